// Per-depth layers (`render --depth-layers`, DepthLayers in film.h, docs/exr.md "Channels"):
//  * PassLayers keeps per-pixel sums and squares of per-pass values: mean and variance of the
//    mean are those of the passes (checked against values worked out here);
//  * the depth layers add up to the beauty in every pixel and every pass, for PT, LT, BDPT
//    balance and power, with and without a crop window (float rounding: the layers and the beauty
//    are sums of the same contributions grouped differently);
//  * every depth 0..maxDepth receives something on the Cornell box, and nothing lands beyond it;
//  * the wavefront mode gives the same layers bit for bit (small pool and queues, so that pool
//    passes and early flushes happen), and the bit-identity check sees a one-value difference;
//    so do 1 and 2 threads.
#include "support/estimators.h"
#include "support/render_util.h"

#include "bdptref/renderer.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <memory>
#include <vector>

using namespace bdptref;
using namespace bdptref::test;

namespace {

// |sum_d layer_d - beauty| <= kSumTolerance * (|beauty| + sum_d |layer_d|) per channel: float
// sums of at most a few hundred terms (u = 6e-8 each), far below a missing or doubled term.
constexpr double kSumTolerance = 1e-5;

// Checks, after every pass of a render into `film`, that the pass's depth layers add up to the
// pass's beauty sample in every pixel the pass rendered. Returns the pixels x passes checked.
struct PassSumChecker {
    const Film& film;
    std::vector<DVec3> lastSum, lastLayers;
    uint64_t checked = 0, failed = 0;
    explicit PassSumChecker(const Film& f) : film(f), lastSum(f.pixelCount(), DVec3(0.0)), lastLayers(f.depths().sums().size(), DVec3(0.0)) {}
    void afterPass() {
        const size_t n = film.pixelCount();
        const std::vector<DVec3>& layers = film.depths().sums();
        for (int y = 0; y < film.height(); ++y)
            for (int x = 0; x < film.width(); ++x) {
                const size_t p = size_t(y) * size_t(film.width()) + size_t(x);
                const DVec3 beauty = film.sum(x, y) - lastSum[p];
                lastSum[p] = film.sum(x, y);
                DVec3 total(0.0), magnitude = glm::abs(beauty);
                for (int d = 0; d < film.depths().layerCount(); ++d) {
                    const size_t i = size_t(d) * n + p;
                    const DVec3 v = layers[i] - lastLayers[i];
                    lastLayers[i] = layers[i];
                    total += v;
                    magnitude += glm::abs(v);
                }
                if (film.count(x, y) == 0) continue;  // outside a crop window
                ++checked;
                for (int c = 0; c < 3; ++c)
                    if (!(std::abs(total[c] - beauty[c]) <= kSumTolerance * magnitude[c] + 1e-30)) {
                        if (failed++ < 5)
                            UNSCOPED_INFO("pixel " << x << "," << y << " channel " << c << ": layers " << total[c] << ", beauty "
                                                   << beauty[c]);
                    }
            }
    }
};

// Total luminance of depth layer d (over pixels and passes).
double layerTotal(const Film& f, int d) {
    double t = 0;
    for (size_t p = 0; p < f.pixelCount(); ++p) t += f.depths().sums()[size_t(d) * f.pixelCount() + p].y;
    return t;
}

}  // namespace

TEST_CASE("PassLayers: the mean and the variance of the mean are over passes, non-finite values count as zero",
          "[film][depthlayers]") {
    PassLayers L(2, 1, 2);  // 2 pixels, 2 layers
    REQUIRE(L.sums().size() == 4);
    // Layer 0 of pixel 1 receives 1, 2, 6 over three passes; layer 1 of pixel 0 a NaN in pass 2.
    const float nan = std::nanf("");
    L.addPass({Rgb(0.f), Rgb(1.f), Rgb(3.f), Rgb(0.f)});
    L.addPass({Rgb(0.f), Rgb(2.f), Rgb(nan), Rgb(0.f)});
    L.addPass({Rgb(0.f), Rgb(6.f), Rgb(3.f), Rgb(0.f)});
    CHECK(L.passes() == 3);
    CHECK(L.nonFiniteValues() == 1);
    CHECK(L.mean(0, 1, 0).x == 3.0);
    // s^2 = ((1-3)^2 + (2-3)^2 + (6-3)^2) / 2 = 7, variance of the mean 7/3.
    CHECK(L.varianceOfMean(0, 1, 0).y == Approx(7.0 / 3.0).epsilon(1e-14));
    CHECK(L.mean(1, 0, 0).z == 2.0);  // 3, 0 (the NaN), 3
    CHECK(L.varianceOfMean(1, 0, 0).z == Approx(1.0).epsilon(1e-14));  // s^2 = 3, / 3
    CHECK(L.mean(0, 0, 0) == DVec3(0.0));
    CHECK_THROWS_AS(L.addPass({Rgb(0.f)}), std::invalid_argument);
    // Merge: the sums, the passes and the non-finite count add; a different layer count is refused.
    PassLayers M = L;
    M.accumulate(L);
    CHECK(M.passes() == 6);
    CHECK(M.nonFiniteValues() == 2);
    CHECK(M.mean(0, 1, 0).x == 3.0);
    CHECK_THROWS_AS(M.accumulate(PassLayers(2, 1, 3)), std::invalid_argument);
    // DepthLayers: maxDepth + 1 layers; -1 is none.
    CHECK(DepthLayers(4, 4, 5).layerCount() == 6);
    CHECK(DepthLayers(4, 4, 5).maxDepth() == 5);
    CHECK_FALSE(DepthLayers(4, 4, -1).enabled());
    CHECK(Film::bytesFor(100.0, -1, 3) - Film::bytesFor(100.0, -1) == 100.0 * 4 * 2 * sizeof(DVec3));
}

TEST_CASE("Depth layers add up to the beauty in every pixel and pass, for PT LT BDPT-balance and BDPT-power",
          "[film][depthlayers]") {
    const Scene scene = loadTestScene("scenes/cornell-box.gltf", 16, 16);
    for (EstimatorSetup s : everyEstimator()) {
        s.spp = 6;
        s.maxDepth = 5;
        s.seed = 7;
        s.depthLayers = true;
        s.layers = s.integrator != "path";  // strategy layers alongside: both are filled
        DYNAMIC_SECTION(estimatorName(s)) {
            std::unique_ptr<PassSumChecker> checker;
            const Film film = renderEstimator(scene, s, [&](const Film& f, int) {
                if (!checker) checker = std::make_unique<PassSumChecker>(f);
                checker->afterPass();
            });
            REQUIRE(checker);
            CHECK(checker->failed == 0);
            CHECK(checker->checked == film.pixelCount() * uint64_t(s.spp));
            CHECK(film.depths().passes() == uint64_t(s.spp));
            CHECK(film.nonFiniteLayerValues() == 0);
            // Not vacuous: every depth 0..5 received light (the light seen directly, direct
            // lighting, ... five bounces), so a contribution filed under the wrong depth would
            // change two layers, which the agreement test (tests/scenes/test_depth_agreement.cpp) sees.
            for (int d = 0; d <= s.maxDepth; ++d) {
                INFO("depth " << d);
                CHECK(layerTotal(film, d) > 0.0);
            }
            // With strategy layers: depth d is the sum of the weighted layers of the strategies of depth d.
            if (s.layers) {
                double worst = 0;
                for (int d = 0; d <= s.maxDepth; ++d)
                    for (int y = 0; y < film.height(); ++y)
                        for (int x = 0; x < film.width(); ++x) {
                            DVec3 sum(0.0);
                            for (int sl = 0; sl <= d + 1; ++sl) sum += film.strategies().mean(sl, d + 2 - sl, true, x, y);
                            const DVec3 depth = film.depths().mean(d, x, y);
                            for (int c = 0; c < 3; ++c)
                                worst = std::max(worst, std::abs(sum[c] - depth[c]) / std::max(1e-30, std::abs(depth[c])));
                        }
                CHECK(worst <= kSumTolerance);
            }
        }
    }
}

TEST_CASE("Depth layers of a crop render add up to the beauty inside the window (splats outside it dropped)",
          "[film][depthlayers][crop]") {
    Scene scene = loadTestScene("scenes/cornell-box.gltf", 16, 16);
    scene.camera = scene.camera.withCrop(3, 2, 12, 9);
    for (const char* integrator : {"lt", "bdpt"}) {
        DYNAMIC_SECTION(integrator) {
            IntegratorSettings is;
            is.maxDepth = 4;
            is.recordDepths = true;
            const auto integ = makeIntegrator(integrator, is);
            Film film(FilmWindow{16, 16, 2, 1, 12, 10});  // more than the crop: a border of unrendered pixels
            film.enableDepthLayers(is.maxDepth);
            PassSumChecker checker(film);
            RenderOptions ro;
            ro.spp = 4;
            ro.seed = 3;
            renderImage(scene, *integ, ro, film, nullptr, [&](const RenderProgress&) { checker.afterPass(); });
            CHECK(checker.failed == 0);
            CHECK(checker.checked == 9u * 7u * 4u);
            // Nothing lands outside the crop, in the beauty or in any layer.
            for (int d = 0; d <= is.maxDepth; ++d)
                for (int y = 0; y < film.height(); ++y)
                    for (int x = 0; x < film.width(); ++x)
                        if (film.count(x, y) == 0) CHECK(film.depths().mean(d, x, y) == DVec3(0.0));
        }
    }
}

TEST_CASE("A film whose depth layers are shallower than the integrator's depth is refused, not overrun", "[film][depthlayers]") {
    const Scene scene = loadTestScene("scenes/cornell-box.gltf", 8, 8);
    IntegratorSettings is;
    is.maxDepth = 4;
    is.recordDepths = true;
    Film film(8, 8);
    film.enableDepthLayers(2);
    RenderOptions ro;
    ro.spp = 2;
    CHECK_THROWS_AS(renderImage(scene, *makePathTracer(is), ro, film), std::invalid_argument);
}

TEST_CASE("Wavefront mode: depth layers bit-identical to the megakernel for PT LT BDPT-balance and BDPT-power",
          "[wavefront][depthlayers]") {
    const Scene scene = loadTestScene("scenes/cornell-box.gltf", 16, 16);
    EstimatorSetup base;
    base.spp = 2;
    base.maxDepth = 6;
    base.seed = 9;
    // Small pool and queues: several pool passes per pass, shadow and connection queues flushed early.
    base.wavefrontOptions.poolSize = 96;
    base.wavefrontOptions.shadowQueueCapacity = 40;
    base.wavefrontOptions.connectionQueueCapacity = 200;
    checkWavefrontIdenticalEveryEstimator(scene, base);  // depth layers on for every estimator

    // The comparison sees a single differing value of one depth layer.
    EstimatorSetup s = base;
    s.integrator = "path";
    s.depthLayers = true;
    const Film a = renderEstimator(scene, s);
    Film b = a;
    CHECK(filmDifference(a, b, s.maxDepth).total() == 0);
    double& v = b.depths().sums()[3 * b.pixelCount() + 17].y;
    // One ulp up; a zero becomes a normal number (denormals compare equal to 0 where they are flushed).
    v = v == 0.0 ? 1e-300 : std::nextafter(v, 1e300);
    CHECK(filmDifference(a, b, s.maxDepth).layers == 1);
    Film c = a;
    double& w = c.depths().sumSquares()[5 * c.pixelCount() + 2].x;
    w = w == 0.0 ? 1e-300 : std::nextafter(w, 1e300);
    CHECK(filmDifference(a, c, s.maxDepth).layers == 1);
}

TEST_CASE("Depth layers do not depend on the number of threads", "[film][depthlayers]") {
    const Scene scene = loadTestScene("scenes/cornell-box.gltf", 16, 16);
    for (EstimatorSetup s : everyEstimator()) {
        s.spp = 2;
        s.maxDepth = 4;
        s.depthLayers = true;
        DYNAMIC_SECTION(estimatorName(s)) {
            s.threads = 1;
            s.tileSize = 4;  // 16 tiles: two threads take them in varying order
            const Film one = renderEstimator(scene, s);
            s.threads = 2;
            const Film two = renderEstimator(scene, s);
            CHECK(filmDifference(one, two, s.maxDepth).total() == 0);
        }
    }
}
