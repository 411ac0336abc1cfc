// The mean over all pixels of a render, with its standard error from the per-pass image means.
// Pixels of one pass are not independent when light paths splat into several of them (LT, BDPT),
// but the passes are independent and identically distributed (each is a pure function of the seed
// and its index), so the spread of the per-pass image means gives the exact standard error.
#pragma once

#include "bdptref/film.h"
#include "bdptref/math.h"

namespace bdptref::test {

class PassImageMean {
public:
    // Call after every completed pass with the film (e.g. from renderImage's progress callback).
    void afterPass(const Film& f) {
        DVec3 total(0.0);
        for (int y = 0; y < f.height(); ++y)
            for (int x = 0; x < f.width(); ++x) total += f.sum(x, y);
        const DVec3 v = (total - previous_) / double(f.pixelCount());
        previous_ = total;
        sum_ += v;
        sumSq_ += v * v;
        ++n_;
    }
    int passes() const { return n_; }
    DVec3 mean() const { return sum_ / double(n_); }
    DVec3 standardError() const {
        const DVec3 m = mean();
        return glm::sqrt(glm::max(DVec3(0.0), (sumSq_ - double(n_) * m * m) / (double(n_) - 1.0)) / double(n_));
    }

private:
    DVec3 previous_{0.0}, sum_{0.0}, sumSq_{0.0};
    int n_ = 0;
};

}  // namespace bdptref::test
