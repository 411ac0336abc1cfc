#include "bdptref/film.h"

#include <algorithm>

namespace bdptref {

Film::Film(int width, int height)
    : width_(width), height_(height), sum_(pixelCount(), DVec3(0.0)), sumSq_(pixelCount(), DVec3(0.0)),
      count_(pixelCount(), 0) {}

void Film::addSample(int x, int y, const Rgb& value) {
    const size_t i = index(x, y);
    ++count_[i];
    if (!isFinite(value)) {
        ++nonFinite_;
        return;
    }
    const DVec3 v(value);
    sum_[i] += v;
    sumSq_[i] += v * v;
}

DVec3 Film::mean(int x, int y) const {
    const size_t i = index(x, y);
    return count_[i] ? sum_[i] / double(count_[i]) : DVec3(0.0);
}

DVec3 Film::varianceOfMean(int x, int y) const {
    const size_t i = index(x, y);
    const double n = double(count_[i]);
    if (n < 2) return DVec3(0.0);
    const DVec3 m = sum_[i] / n;
    // Sample variance s^2 = (sum x^2 - n m^2) / (n - 1); clamp round-off below zero.
    const DVec3 s2 = glm::max(DVec3(0.0), (sumSq_[i] - n * m * m) / (n - 1.0));
    return s2 / n;
}

uint64_t Film::minCount() const { return count_.empty() ? 0 : *std::min_element(count_.begin(), count_.end()); }
uint64_t Film::maxCount() const { return count_.empty() ? 0 : *std::max_element(count_.begin(), count_.end()); }

}  // namespace bdptref
