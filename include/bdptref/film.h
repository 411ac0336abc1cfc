// The film: per pixel, double-precision sums of sample values and of their squares and the
// number of samples, so the mean and the variance of the mean are exact functions of the samples
// (docs/contracts.md, contract 4). Samples are added in a fixed order (pixel by pixel, pass by pass), never
// with atomics, so the result does not depend on the number of threads.
#pragma once

#include "bdptref/math.h"
#include "bdptref/sample_range.h"

#include <cstdint>
#include <string>
#include <vector>

namespace bdptref {

// Per-pass layers: `layerCount` per-pixel RGB quantities. A pass adds, for every layer and pixel,
// the sum of what that pass put there (all of its contributions, splats included), so each layer
// keeps per-pixel sums and sums of squares over passes: its mean and the variance of that mean
// are exact functions of the passes, like the film's (docs/exr.md, "Layers"). Used by the
// per-(s,t) strategy layers and the per-depth layers.
class PassLayers {
public:
    PassLayers() = default;
    PassLayers(int width, int height, int layerCount);
    bool enabled() const { return layerCount_ > 0; }
    int layerCount() const { return layerCount_; }
    size_t pixels() const { return pixels_; }
    // Adds one pass: `values` holds layerCount() * pixels() values, layer-major (layer * pixels() + pixel).
    void addPass(const std::vector<Rgb>& values);
    DVec3 mean(int layer, int x, int y) const;
    DVec3 varianceOfMean(int layer, int x, int y) const;
    uint64_t passes() const { return passes_; }
    // Layer values that were not finite (counted as zero, like Film::nonFiniteSamples()).
    uint64_t nonFiniteValues() const { return nonFinite_; }

    // Exact state, for checkpoints and merge (src/film/film_exact.cpp, film_merge.cpp): the
    // per-layer sums (layer-major, layerCount() * pixels() each) and the number of passes.
    std::vector<DVec3>& sums() { return sum_; }
    std::vector<DVec3>& sumSquares() { return sumSq_; }
    const std::vector<DVec3>& sums() const { return sum_; }
    const std::vector<DVec3>& sumSquares() const { return sumSq_; }
    void setPasses(uint64_t n) { passes_ = n; }
    void setNonFiniteValues(uint64_t n) { nonFinite_ = n; }
    // Adds another layer set of the same size and layer count (merge). Throws std::invalid_argument otherwise.
    void accumulate(const PassLayers& other);

private:
    size_t at(int layer, int x, int y) const { return size_t(layer) * pixels_ + size_t(y) * size_t(width_) + size_t(x); }
    int width_ = 0, layerCount_ = 0;
    size_t pixels_ = 0;
    uint64_t passes_ = 0;
    uint64_t nonFinite_ = 0;
    std::vector<DVec3> sum_, sumSq_;
};

// Per-(s,t) layers: for every strategy of depth 0..maxDepth, the weighted and the unweighted
// contribution, each a PassLayers (so every layer has a variance too). Strategy (s, t) of depth
// d = s + t - 2 (t >= 1) has index d(d+3)/2 + s.
class StrategyLayers {
public:
    StrategyLayers() = default;
    StrategyLayers(int width, int height, int maxDepth);
    bool enabled() const { return maxDepth_ >= 0; }
    int maxDepth() const { return maxDepth_; }
    static int index(int s, int t) { const int d = s + t - 2; return d * (d + 3) / 2 + s; }
    int layerCount() const { return layerCountFor(maxDepth_); }
    static int layerCountFor(int maxDepth) { return maxDepth < 0 ? 0 : index(maxDepth + 1, 1) + 1; }
    // Adds one pass: `weighted`/`unweighted` hold layerCount() * pixels values (layer-major).
    void addPass(const std::vector<Rgb>& weighted, const std::vector<Rgb>& unweighted);
    DVec3 mean(int s, int t, bool weighted, int x, int y) const { return of(weighted).mean(index(s, t), x, y); }
    DVec3 varianceOfMean(int s, int t, bool weighted, int x, int y) const {
        return of(weighted).varianceOfMean(index(s, t), x, y);
    }
    uint64_t passes() const { return weighted_.passes(); }
    // Layer values that were not finite (counted as zero, like Film::nonFiniteSamples()).
    uint64_t nonFiniteValues() const { return weighted_.nonFiniteValues() + unweighted_.nonFiniteValues(); }
    const PassLayers& of(bool weighted) const { return weighted ? weighted_ : unweighted_; }
    PassLayers& of(bool weighted) { return weighted ? weighted_ : unweighted_; }

    // Exact state, for checkpoints and merge (src/film/film_exact.cpp, film_merge.cpp).
    std::vector<DVec3>& sums(bool weighted) { return of(weighted).sums(); }
    std::vector<DVec3>& sumSquares(bool weighted) { return of(weighted).sumSquares(); }
    const std::vector<DVec3>& sums(bool weighted) const { return of(weighted).sums(); }
    const std::vector<DVec3>& sumSquares(bool weighted) const { return of(weighted).sumSquares(); }
    void setPasses(uint64_t n) {
        weighted_.setPasses(n);
        unweighted_.setPasses(n);
    }
    void setNonFiniteValues(uint64_t n) {  // the total of both sets (one header attribute)
        weighted_.setNonFiniteValues(n);
        unweighted_.setNonFiniteValues(0);
    }
    // Adds another layer set of the same size and depth (merge).
    void accumulate(const StrategyLayers& other);

private:
    int maxDepth_ = -1;
    PassLayers weighted_, unweighted_;
};

// Per-depth layers (`render --depth-layers`): layer d holds the contributions of paths with d
// scattering bounces, d = s + t - 2 for BDPT strategy (s, t), the bounce count for the path
// tracer (an emitter seen directly: depth 0). The layers of depths 0..maxDepth sum to the beauty.
class DepthLayers : public PassLayers {
public:
    DepthLayers() = default;
    DepthLayers(int width, int height, int maxDepth) : PassLayers(width, height, maxDepth < 0 ? 0 : maxDepth + 1) {}
    int maxDepth() const { return layerCount() - 1; }  // -1: none
};

// Which part of the full image a film holds: the pixels [x0, x0 + width) x [y0, y0 + height) of a
// fullWidth x fullHeight image. A crop render's film holds only the crop window (its memory is
// that of the window, not of the full image); an EXR stores it as the data window inside the
// display window (docs/camera.md, "Crop windows").
struct FilmWindow {
    int fullWidth = 0, fullHeight = 0;
    int x0 = 0, y0 = 0, width = 0, height = 0;
    static FilmWindow full(int w, int h) { return {w, h, 0, 0, w, h}; }
    bool isFull() const { return x0 == 0 && y0 == 0 && width == fullWidth && height == fullHeight; }
    bool operator==(const FilmWindow& o) const {
        return fullWidth == o.fullWidth && fullHeight == o.fullHeight && x0 == o.x0 && y0 == o.y0 && width == o.width &&
               height == o.height;
    }
    bool operator!=(const FilmWindow& o) const { return !(*this == o); }
    // "WxH+X+Y of FWxFH", for messages.
    std::string text() const;
};

class Film {
public:
    Film() = default;
    Film(int width, int height);  // the full image
    explicit Film(const FilmWindow& window);

    // The film's own pixels: (x, y) below are film coordinates, 0 <= x < width(); the full-image
    // pixel is (x + window().x0, y + window().y0).
    int width() const { return window_.width; }
    int height() const { return window_.height; }
    const FilmWindow& window() const { return window_; }
    size_t pixelCount() const { return size_t(width()) * size_t(height()); }
    // Bytes a film of `pixels` pixels with strategy layers of `strategyMaxDepth` and depth layers
    // of `depthMaxDepth` (-1: none) holds.
    static double bytesFor(double pixels, int strategyMaxDepth, int depthMaxDepth = -1);

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
    // the light image normalised by the number of light paths (docs/contracts.md, contract 4).
    void addLight(int x, int y, const Rgb& value);
    DVec3 lightMean(int x, int y) const;
    StrategyLayers& strategies() { return strategies_; }
    const StrategyLayers& strategies() const { return strategies_; }
    void enableStrategies(int maxDepth) { strategies_ = StrategyLayers(width(), height(), maxDepth); }
    DepthLayers& depths() { return depths_; }
    const DepthLayers& depths() const { return depths_; }
    void enableDepthLayers(int maxDepth) { depths_ = DepthLayers(width(), height(), maxDepth); }
    // Non-finite values of the strategy and depth layers together.
    uint64_t nonFiniteLayerValues() const { return strategies_.nonFiniteValues() + depths_.nonFiniteValues(); }
    uint64_t minCount() const;
    uint64_t maxCount() const;

    // The pixel-sample indices whose passes the film holds (renderImage appends at samples().endIndex()).
    const SampleRanges& samples() const { return samples_; }
    SampleRanges& samples() { return samples_; }

    // Exact accumulator state, for checkpoints (film_exr_exact.cpp) and merge (film_merge.cpp).
    struct Accumulators {
        std::vector<DVec3>& sum;
        std::vector<DVec3>& sumSquares;
        std::vector<uint64_t>& count;
        std::vector<DVec3>& lightSum;
        uint64_t& nonFinite;
    };
    Accumulators accumulators() { return {sum_, sumSq_, count_, lightSum_, nonFinite_}; }
    DVec3 lightSum(int x, int y) const { return lightSum_[index(x, y)]; }

    // Adds the accumulators of `other` (same window and layers) and its sample ranges,
    // which must not overlap this film's. Throws std::invalid_argument otherwise.
    void accumulate(const Film& other);

private:
    size_t index(int x, int y) const { return size_t(y) * size_t(window_.width) + size_t(x); }
    FilmWindow window_;
    std::vector<DVec3> sum_, sumSq_;
    std::vector<uint64_t> count_;
    std::vector<DVec3> lightSum_;
    uint64_t nonFinite_ = 0;
    StrategyLayers strategies_;
    DepthLayers depths_;
    SampleRanges samples_;
};

// How converged a film is, from its own variance estimates (pixels with a positive mean):
// per pixel r = sqrt(mean over R,G,B of variance of the mean) / (mean over R,G,B of the mean).
struct FilmErrorSummary {
    double medianRelativeStandardError = 0;  // median of r over the pixels
    double p95RelativeStandardError = 0;     // its 95th percentile
    double imageRelativeStandardError = 0;   // of the image average: sqrt(sum v) / sum m (pixels independent)
    uint64_t pixels = 0;                     // pixels with a positive mean
};
FilmErrorSummary summarizeError(const Film& film);

}  // namespace bdptref
