// The path tracer's strategy layers (render --integrator path --strategies; docs/path-tracer.md,
// "Strategy layers"): its emission found by BSDF sampling is BDPT's strategy s = 0, t = depth + 2,
// and its next-event estimation s = 1, t = depth + 1. What is proven:
//  - weighted, the two add up to the depth layer in every pixel (float rounding of one sum);
//  - unweighted, each is an estimator of the whole depth layer on its own (on the Cornell box's
//    area light both sample every path): its image mean agrees with an independent render's depth
//    layer within k = 5 standard errors (the two films' per-pixel variances, pixels independent
//    in a path tracer), and 5 standard errors are below 25% of the layer, so an error of that
//    size is seen (emitter hits at depths 1 and 2, next events at 1 to 4); the MIS weights are
//    < 1 (the weighted layers hold less than the unweighted ones, the emitter hits less than
//    half) and 1 at depth 0 (the light seen directly: one strategy);
//  - under a point light (a delta light) no emitter is hit, and every next event is unweighted:
//    its weighted and unweighted layers are equal bit for bit.
// The wavefront mode writes the same layers bit for bit (test_wavefront.cpp: every estimator with
// strategy layers).
#include "support/estimators.h"
#include "support/render_util.h"

#include <catch2/catch.hpp>

#include <cmath>

using namespace bdptref;
using namespace bdptref::test;

namespace {

constexpr double kSigmas = 5.0;
constexpr double kDetectableBias = 0.25;

// An image mean of a layer and the variance of that mean (pixels independent).
struct ImageMean {
    DVec3 mean{0.0}, variance{0.0};
};

template <class MeanOf, class VarianceOf>
ImageMean imageMean(const Film& f, MeanOf&& meanOf, VarianceOf&& varianceOf) {
    ImageMean m;
    const double n = double(f.pixelCount());
    for (int y = 0; y < f.height(); ++y)
        for (int x = 0; x < f.width(); ++x) {
            m.mean += meanOf(x, y) / n;
            m.variance += varianceOf(x, y) / (n * n);
        }
    return m;
}

ImageMean strategyMean(const Film& f, int s, int t, bool weighted) {
    return imageMean(
        f, [&](int x, int y) { return f.strategies().mean(s, t, weighted, x, y); },
        [&](int x, int y) { return f.strategies().varianceOfMean(s, t, weighted, x, y); });
}

ImageMean depthMean(const Film& f, int d) {
    return imageMean(
        f, [&](int x, int y) { return f.depths().mean(d, x, y); }, [&](int x, int y) { return f.depths().varianceOfMean(d, x, y); });
}

EstimatorSetup pathSetup(uint32_t seed, int spp, int maxDepth) {
    EstimatorSetup s;
    s.integrator = "path";
    s.seed = seed;
    s.spp = spp;
    s.maxDepth = maxDepth;
    s.layers = true;
    s.depthLayers = true;
    return s;
}

}  // namespace

TEST_CASE("Path tracer strategy layers: weighted they add up to the depth layer, unweighted each estimates it alone",
          "[path][strategies][agreement]") {
    const Scene scene = loadTestScene("scenes/cornell-box.gltf", 24, 24);
    constexpr int kMaxDepth = 4;
    const Film a = renderEstimator(scene, pathSetup(11, 512, kMaxDepth));
    const Film b = renderEstimator(scene, pathSetup(12, 512, kMaxDepth));
    REQUIRE(a.strategies().enabled());
    CHECK(a.nonFiniteSamples() == 0);

    // Weighted: emission found + next event = the depth layer, pixel by pixel; depth 0 has one
    // strategy (the camera ray finds the light), whose weight is 1.
    double worst = 0;
    for (int d = 0; d <= kMaxDepth; ++d)
        for (int y = 0; y < a.height(); ++y)
            for (int x = 0; x < a.width(); ++x) {
                const DVec3 sum = a.strategies().mean(0, d + 2, true, x, y) + (d > 0 ? a.strategies().mean(1, d + 1, true, x, y) : DVec3(0.0));
                const DVec3 layer = a.depths().mean(d, x, y);
                for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(sum[c] - layer[c]) / std::max(1e-9, layer[c]));
                if (d == 0) CHECK(a.strategies().mean(0, 2, true, x, y) == a.strategies().mean(0, 2, false, x, y));
            }
    CHECK(worst < 1e-5);

    // Unweighted: each strategy against the other render's depth layer. The emitter hits find the
    // light by BSDF sampling alone: at 512 spp only depths 1 and 2 have the power asked for.
    for (int d = 1; d <= kMaxDepth; ++d)
        for (int s : {0, 1}) {
            if (s == 0 && d > 2) continue;
            const ImageMean u = strategyMean(a, s, d + 2 - s, false), ref = depthMean(b, d);
            for (int c = 0; c < 3; ++c) {
                INFO("depth " << d << ", s = " << s << ", channel " << c << ": " << u.mean[c] << " +- " << std::sqrt(u.variance[c])
                              << " against " << ref.mean[c] << " +- " << std::sqrt(ref.variance[c]));
                const double sigma = std::sqrt(u.variance[c] + ref.variance[c]);
                CHECK(std::abs(u.mean[c] - ref.mean[c]) <= kSigmas * sigma);
                CHECK(kSigmas * sigma < kDetectableBias * ref.mean[c]);  // not vacuous
            }
            // The MIS weights are below 1 where both strategies sample the path (the power
            // heuristic gives the small light's next events most of it).
            CHECK(strategyMean(a, s, d + 2 - s, true).mean.y < (s == 0 ? 0.5 : 1.0) * u.mean.y);
        }
}

TEST_CASE("Path tracer strategy layers under a point light: no emitter hits, next events unweighted", "[path][strategies][punctual]") {
    const Scene scene = loadTestScene("scenes/sphere-point-light.gltf", 16, 16);
    constexpr int kMaxDepth = 3;
    const Film f = renderEstimator(scene, pathSetup(5, 16, kMaxDepth));
    for (int d = 1; d <= kMaxDepth; ++d) {
        INFO("depth " << d);
        CHECK(strategyMean(f, 1, d + 1, false).mean.y > 0.0);
        CHECK(strategyMean(f, 0, d + 2, false).mean == DVec3(0.0));
        CHECK(strategyMean(f, 0, d + 2, true).mean == DVec3(0.0));
        bool same = true;
        for (int y = 0; y < f.height(); ++y)
            for (int x = 0; x < f.width(); ++x)
                same = same && f.strategies().mean(1, d + 1, true, x, y) == f.strategies().mean(1, d + 1, false, x, y) &&
                       f.strategies().varianceOfMean(1, d + 1, true, x, y) == f.strategies().varianceOfMean(1, d + 1, false, x, y);
        CHECK(same);
    }
}
