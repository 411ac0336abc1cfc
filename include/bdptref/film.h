// The film: per pixel, double-precision sums of sample values and of their squares and the
// number of samples, so the mean and the variance of the mean are exact functions of the samples
// (DESIGN contract 4). Samples are added in a fixed order (pixel by pixel, pass by pass), never
// with atomics, so the result does not depend on the number of threads.
#pragma once

#include "bdptref/math.h"

#include <cstdint>
#include <vector>

namespace bdptref {

// Per-(s,t) layers: for every strategy of depth 0..maxDepth, the weighted and the unweighted
// contribution, each with per-pixel sums and sums of squares over passes (so every layer has a
// variance too). Strategy (s, t) of depth d = s + t - 2 (t >= 1) has index d(d+3)/2 + s.
class StrategyLayers {
public:
    StrategyLayers() = default;
    StrategyLayers(int width, int height, int maxDepth);
    bool enabled() const { return maxDepth_ >= 0; }
    int maxDepth() const { return maxDepth_; }
    static int index(int s, int t) { const int d = s + t - 2; return d * (d + 3) / 2 + s; }
    int layerCount() const { return maxDepth_ < 0 ? 0 : index(maxDepth_ + 1, 1) + 1; }
    // Adds one pass: `weighted`/`unweighted` hold layerCount() * pixels values (layer-major).
    void addPass(const std::vector<Rgb>& weighted, const std::vector<Rgb>& unweighted);
    DVec3 mean(int s, int t, bool weighted, int x, int y) const;
    DVec3 varianceOfMean(int s, int t, bool weighted, int x, int y) const;
    uint64_t passes() const { return passes_; }
    // Layer values that were not finite (counted as zero, like Film::nonFiniteSamples()).
    uint64_t nonFiniteValues() const { return nonFinite_; }

private:
    size_t at(int layer, int x, int y) const { return size_t(layer) * pixels_ + size_t(y) * size_t(width_) + size_t(x); }
    int width_ = 0, height_ = 0, maxDepth_ = -1;
    size_t pixels_ = 0;
    uint64_t passes_ = 0;
    uint64_t nonFinite_ = 0;
    std::vector<DVec3> sumW_, sumSqW_, sumU_, sumSqU_;
};

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

    // The light-tracing (splat) part of the image: per pass, the sum of the splats that landed in
    // the pixel (already included in the samples added with addSample). Its mean over passes is
    // the light image normalised by the number of light paths (DESIGN contract 4).
    void addLight(int x, int y, const Rgb& value);
    DVec3 lightMean(int x, int y) const;
    StrategyLayers& strategies() { return strategies_; }
    const StrategyLayers& strategies() const { return strategies_; }
    void enableStrategies(int maxDepth) { strategies_ = StrategyLayers(width_, height_, maxDepth); }
    uint64_t minCount() const;
    uint64_t maxCount() const;

private:
    size_t index(int x, int y) const { return size_t(y) * size_t(width_) + size_t(x); }
    int width_ = 0, height_ = 0;
    std::vector<DVec3> sum_, sumSq_;
    std::vector<uint64_t> count_;
    std::vector<DVec3> lightSum_;
    uint64_t nonFinite_ = 0;
    StrategyLayers strategies_;
};

}  // namespace bdptref
