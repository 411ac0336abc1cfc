#include "bdptref/film.h"

#include <algorithm>
#include <stdexcept>

namespace bdptref {

std::string FilmWindow::text() const {
    return std::to_string(width) + "x" + std::to_string(height) + "+" + std::to_string(x0) + "+" + std::to_string(y0) +
           " of " + std::to_string(fullWidth) + "x" + std::to_string(fullHeight);
}

Film::Film(int width, int height) : Film(FilmWindow::full(width, height)) {}

Film::Film(const FilmWindow& window)
    : window_(window), sum_(pixelCount(), DVec3(0.0)), sumSq_(pixelCount(), DVec3(0.0)), count_(pixelCount(), 0),
      lightSum_(pixelCount(), DVec3(0.0)) {}

double Film::bytesFor(double pixels, int strategyMaxDepth) {
    // sum, sum of squares, light sum (3 DVec3) and the count; each strategy layer: 4 DVec3.
    const double perPixel = 3.0 * sizeof(DVec3) + sizeof(uint64_t) +
                            double(StrategyLayers::layerCountFor(strategyMaxDepth)) * 4.0 * sizeof(DVec3);
    return pixels * perPixel;
}

void Film::addLight(int x, int y, const Rgb& value) {
    if (isFinite(value)) lightSum_[index(x, y)] += DVec3(value);
}

DVec3 Film::lightMean(int x, int y) const {
    const size_t i = index(x, y);
    return count_[i] ? lightSum_[i] / double(count_[i]) : DVec3(0.0);
}

StrategyLayers::StrategyLayers(int width, int height, int maxDepth)
    : width_(width), height_(height), maxDepth_(maxDepth), pixels_(size_t(width) * size_t(height)) {
    const size_t n = size_t(layerCount()) * pixels_;
    sumW_.assign(n, DVec3(0.0));
    sumSqW_.assign(n, DVec3(0.0));
    sumU_.assign(n, DVec3(0.0));
    sumSqU_.assign(n, DVec3(0.0));
}

void StrategyLayers::addPass(const std::vector<Rgb>& weighted, const std::vector<Rgb>& unweighted) {
    for (size_t i = 0; i < sumW_.size(); ++i) {
        const bool wOk = isFinite(weighted[i]), uOk = isFinite(unweighted[i]);
        nonFinite_ += uint64_t(!wOk) + uint64_t(!uOk);  // counted, never dropped silently
        const DVec3 w = wOk ? DVec3(weighted[i]) : DVec3(0.0);
        const DVec3 u = uOk ? DVec3(unweighted[i]) : DVec3(0.0);
        sumW_[i] += w;
        sumSqW_[i] += w * w;
        sumU_[i] += u;
        sumSqU_[i] += u * u;
    }
    ++passes_;
}

DVec3 StrategyLayers::mean(int s, int t, bool weighted, int x, int y) const {
    if (passes_ == 0) return DVec3(0.0);
    return (weighted ? sumW_ : sumU_)[at(index(s, t), x, y)] / double(passes_);
}

DVec3 StrategyLayers::varianceOfMean(int s, int t, bool weighted, int x, int y) const {
    const double n = double(passes_);
    if (n < 2) return DVec3(0.0);
    const size_t i = at(index(s, t), x, y);
    const DVec3 m = (weighted ? sumW_ : sumU_)[i] / n;
    const DVec3 s2 = glm::max(DVec3(0.0), ((weighted ? sumSqW_ : sumSqU_)[i] - n * m * m) / (n - 1.0));
    return s2 / n;
}

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

void StrategyLayers::accumulate(const StrategyLayers& other) {
    if (other.maxDepth_ != maxDepth_ || other.pixels_ != pixels_)
        throw std::invalid_argument("strategy layers differ in depth or size");
    for (size_t i = 0; i < sumW_.size(); ++i) {
        sumW_[i] += other.sumW_[i];
        sumSqW_[i] += other.sumSqW_[i];
        sumU_[i] += other.sumU_[i];
        sumSqU_[i] += other.sumSqU_[i];
    }
    passes_ += other.passes_;
    nonFinite_ += other.nonFinite_;
}

void Film::accumulate(const Film& other) {
    if (other.window_ != window_)
        throw std::invalid_argument("films differ in window: " + other.window_.text() + " vs " + window_.text());
    SampleRanges joined = samples_;
    for (const SampleRange& r : other.samples_.ranges())
        if (!joined.add(r)) throw std::invalid_argument("films hold overlapping sample ranges");
    strategies_.accumulate(other.strategies_);
    for (size_t i = 0; i < sum_.size(); ++i) {
        sum_[i] += other.sum_[i];
        sumSq_[i] += other.sumSq_[i];
        count_[i] += other.count_[i];
        lightSum_[i] += other.lightSum_[i];
    }
    nonFinite_ += other.nonFinite_;
    samples_ = joined;
}

uint64_t Film::minCount() const { return count_.empty() ? 0 : *std::min_element(count_.begin(), count_.end()); }
uint64_t Film::maxCount() const { return count_.empty() ? 0 : *std::max_element(count_.begin(), count_.end()); }

}  // namespace bdptref
