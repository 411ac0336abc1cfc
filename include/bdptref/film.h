// The film: per pixel, double-precision sums of sample values and of their squares and the
// number of samples, so the mean and the variance of the mean are exact functions of the samples
// (DESIGN contract 4). Samples are added in a fixed order (pixel by pixel, pass by pass), never
// with atomics, so the result does not depend on the number of threads.
#pragma once

#include "bdptref/math.h"

#include <cstdint>
#include <vector>

namespace bdptref {

class Film {
public:
    Film() = default;
    Film(int width, int height);

    int width() const { return width_; }
    int height() const { return height_; }
    size_t pixelCount() const { return size_t(width_) * size_t(height_); }

    // Adds one sample to pixel (x, y). A non-finite sample is counted as a sample of value zero
    // and recorded in nonFiniteSamples() so it is never lost silently.
    void addSample(int x, int y, const Rgb& value);

    DVec3 sum(int x, int y) const { return sum_[index(x, y)]; }
    DVec3 sumSquares(int x, int y) const { return sumSq_[index(x, y)]; }
    uint64_t count(int x, int y) const { return count_[index(x, y)]; }
    DVec3 mean(int x, int y) const;
    // Unbiased estimate of the variance of the pixel mean: s^2 / n (0 for n < 2).
    DVec3 varianceOfMean(int x, int y) const;
    uint64_t nonFiniteSamples() const { return nonFinite_; }
    uint64_t minCount() const;
    uint64_t maxCount() const;

private:
    size_t index(int x, int y) const { return size_t(y) * size_t(width_) + size_t(x); }
    int width_ = 0, height_ = 0;
    std::vector<DVec3> sum_, sumSq_;
    std::vector<uint64_t> count_;
    uint64_t nonFinite_ = 0;
};

}  // namespace bdptref
