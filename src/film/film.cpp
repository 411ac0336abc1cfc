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

double Film::bytesFor(double pixels, int strategyMaxDepth, int depthMaxDepth) {
    // sum, sum of squares, light sum (3 DVec3) and the count; each strategy layer: 4 DVec3 (sum
    // and squares, weighted and unweighted); each depth layer: 2 DVec3 (sum and squares).
    const double perPixel = 3.0 * sizeof(DVec3) + sizeof(uint64_t) +
                            double(StrategyLayers::layerCountFor(strategyMaxDepth)) * 4.0 * sizeof(DVec3) +
                            double(depthMaxDepth < 0 ? 0 : depthMaxDepth + 1) * 2.0 * sizeof(DVec3);
    return pixels * perPixel;
}

void Film::addLight(int x, int y, const Rgb& value) {
    if (isFinite(value)) lightSum_[index(x, y)] += DVec3(value);
}

DVec3 Film::lightMean(int x, int y) const {
    const size_t i = index(x, y);
    return count_[i] ? lightSum_[i] / double(count_[i]) : DVec3(0.0);
}

PassLayers::PassLayers(int width, int height, int layerCount)
    : width_(width), layerCount_(std::max(0, layerCount)), pixels_(size_t(width) * size_t(height)) {
    sum_.assign(size_t(layerCount_) * pixels_, DVec3(0.0));
    sumSq_.assign(sum_.size(), DVec3(0.0));
}

void PassLayers::addPass(const std::vector<Rgb>& values) {
    if (values.size() != sum_.size()) throw std::invalid_argument("PassLayers::addPass: wrong number of values");
    for (size_t i = 0; i < sum_.size(); ++i) {
        const bool ok = isFinite(values[i]);
        nonFinite_ += uint64_t(!ok);  // counted, never dropped silently
        const DVec3 v = ok ? DVec3(values[i]) : DVec3(0.0);
        sum_[i] += v;
        sumSq_[i] += v * v;
    }
    ++passes_;
}

DVec3 PassLayers::mean(int layer, int x, int y) const {
    if (passes_ == 0) return DVec3(0.0);
    return sum_[at(layer, x, y)] / double(passes_);
}

DVec3 PassLayers::varianceOfMean(int layer, int x, int y) const {
    const double n = double(passes_);
    if (n < 2) return DVec3(0.0);
    const size_t i = at(layer, x, y);
    const DVec3 m = sum_[i] / n;
    const DVec3 s2 = glm::max(DVec3(0.0), (sumSq_[i] - n * m * m) / (n - 1.0));
    return s2 / n;
}

void PassLayers::accumulate(const PassLayers& other) {
    if (other.layerCount_ != layerCount_ || other.pixels_ != pixels_)
        throw std::invalid_argument("layers differ in count or size");
    for (size_t i = 0; i < sum_.size(); ++i) {
        sum_[i] += other.sum_[i];
        sumSq_[i] += other.sumSq_[i];
    }
    passes_ += other.passes_;
    nonFinite_ += other.nonFinite_;
}

StrategyLayers::StrategyLayers(int width, int height, int maxDepth)
    : maxDepth_(maxDepth), weighted_(width, height, layerCountFor(maxDepth)), unweighted_(width, height, layerCountFor(maxDepth)) {}

void StrategyLayers::addPass(const std::vector<Rgb>& weighted, const std::vector<Rgb>& unweighted) {
    weighted_.addPass(weighted);
    unweighted_.addPass(unweighted);
}

void StrategyLayers::accumulate(const StrategyLayers& other) {
    if (other.maxDepth_ != maxDepth_) throw std::invalid_argument("strategy layers differ in depth");
    weighted_.accumulate(other.weighted_);
    unweighted_.accumulate(other.unweighted_);
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

void Film::accumulate(const Film& other) {
    if (other.window_ != window_)
        throw std::invalid_argument("films differ in window: " + other.window_.text() + " vs " + window_.text());
    SampleRanges joined = samples_;
    for (const SampleRange& r : other.samples_.ranges())
        if (!joined.add(r)) throw std::invalid_argument("films hold overlapping sample ranges");
    // Checked before anything is added, so a refused film leaves this one unchanged.
    if (other.strategies_.maxDepth() != strategies_.maxDepth() || other.depths_.maxDepth() != depths_.maxDepth())
        throw std::invalid_argument("films differ in their strategy or depth layers");
    strategies_.accumulate(other.strategies_);
    depths_.accumulate(other.depths_);
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
