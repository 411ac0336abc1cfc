// Cross-checks of the bidirectional path tracer (docs/contracts.md, "How tests are
// written": known answers first, cross-checks next).
//
// The per-pixel comparisons use tests/support/image_stats.h: Welch's t-test in every pixel and
// channel (alpha = 0.01 per pixel, Bonferroni over the three channels), and the comparison passes
// when the number of rejected pixels is at most the 1 - 1e-4 quantile of Binomial(m, 0.01), m the
// number of pixels tested. Every compared pair of images comes from renders with DIFFERENT seeds,
// so the two estimates of a pixel are independent, as the t-test requires.
//
// Why these comparisons can fail (their power), measured on these very renders: each agreement
// test also scales one image of each pair by 1 + delta (mean and standard error alike) and
// checks that the comparison then FAILS. A uniform 5% error in one estimator is caught by the
// Cornell comparisons (kDetectableBias; measured over several seed sets: 34-72 rejected pixels
// against a bound of 16, where the correct renders reject 0-8), and a local error where it is
// several standard errors of the pixel difference in a group of pixels (per-pixel standard
// errors are 2-4% of the value here). For example, while this test was written it caught connection shadow rays that found
// their own target occluded when the target lay on the floor or the green wall (coordinates near
// 0, where the target's offset was far below the float precision of a long ray): BDPT 1-2% low
// over the image, up to 20% in some pixels, 25-47 rejected pixels against a bound of 16. Bugs
// of the kinds BDPT ports have produce errors far above that, in many pixels:
//  * a missing cosine (at a light vertex, at the camera, in G) changes every affected
//    contribution by a factor cos, typically 0.3-0.9, i.e. 10-70% in most pixels;
//  * a doubled (or halved) MIS weight for one strategy adds (removes) that strategy's weighted
//    share, which is tens of percent of direct lighting in the Cornell box for s = 0, 1 and t = 1;
//  * a wrong splat normalisation (by the number of pixels of a crop, of a tile, of the passes)
//    scales the light-tracing image by a factor of 2 or more against PT, which has no splats;
//  * a wrong camera importance We (a missing 1/cos^4, a wrong image-plane area) distorts LT and
//    the t = 1 strategies by many percent towards the image corners or globally.
// PT, LT and BDPT share no estimator code beyond the BSDF, the light sampling and the camera: an
// error in one of them shows up as a disagreement with the others. The analytic checks below
// pin the absolute level for scenes with closed forms.
#include "support/chi2.h"
#include "support/estimators.h"
#include "support/image_stats.h"
#include "support/pass_statistics.h"
#include "support/render_util.h"

#include "bdptref/bdpt.h"
#include "bdptref/integrator.h"
#include "bdptref/renderer.h"

#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

using namespace bdptref;
using namespace bdptref::test;

namespace {

constexpr double kPiD = 3.14159265358979323846;

// --- rendering helpers -----------------------------------------------------------------------

// The renders here use 8-pixel tiles: 24 x 24 gives 9 equal tiles, 16 x 16 gives 4 (both threads stay busy).
struct Setup : EstimatorSetup {
    Setup() { tileSize = 8; }
};

// Mean over passes of a per-pass quantity, with its standard error: the passes of a render are
// independent and identically distributed (each is a pure function of the seed and its index).
struct PassStatistic {
    DVec3 sum{0.0}, sumSq{0.0};
    int n = 0;
    void add(const DVec3& v) {
        sum += v;
        sumSq += v * v;
        ++n;
    }
    DVec3 mean() const { return sum / double(n); }
    DVec3 standardError() const {
        const DVec3 m = mean();
        return glm::sqrt(glm::max(DVec3(0.0), (sumSq - double(n) * m * m) / (double(n) - 1.0)) / double(n));
    }
};

// The mean over all pixels of a render, with its standard error computed from the per-pass image
// means. Pixels of one pass are NOT independent when light paths splat into several of them, so
// the per-pixel samples cannot be pooled as independent (pooledMean() in render_util would
// underestimate the error of LT and BDPT); the passes are independent and identically
// distributed, so the spread of the per-pass image means gives the exact standard error.
struct PassPooled {
    DVec3 mean{0.0}, standardError{0.0};
    int passes = 0;
};

PassPooled renderPassPooled(const Scene& scene, const Setup& s) {
    PassImageMean stat;
    const Film film = renderEstimator(scene, s, [&](const Film& f, int) { stat.afterPass(f); });
    CHECK(film.nonFiniteSamples() == 0);
    PassPooled r;
    r.passes = stat.passes();
    r.mean = stat.mean();
    r.standardError = stat.standardError();
    return r;
}

// One strategy layer as an image of moments.
MomentImage layerMoments(const Film& film, int s, int t, bool weighted) {
    const StrategyLayers& L = film.strategies();
    return momentsFrom(film.width(), film.height(), [&](int x, int y) {
        PixelMoments m;
        m.mean = L.mean(s, t, weighted, x, y);
        m.varianceOfMean = L.varianceOfMean(s, t, weighted, x, y);
        m.count = L.passes();
        return m;
    });
}

// Uniform relative error that every Cornell-box comparison must detect (see the file comment).
constexpr double kDetectableBias = 0.05;
// Relative error of one unweighted strategy layer that the image-mean comparison must see.
constexpr double kLayerDetectableBias = 0.25;
// Uniform relative error that the crop comparison (144 pixels) must detect.
constexpr double kCropDetectableBias = 0.10;
constexpr double kSigmas = 5.0;

}  // namespace

// ---- the statistics themselves ----------------------------------------------------------------

TEST_CASE("Image statistics: Student t p-values and binomial quantiles and the Welch comparison", "[stats]") {
    // Closed forms of the two-sided Student t tail: nu = 1 (Cauchy) and nu = 2.
    for (double t : {0.0, 0.3, 1.0, 2.5, 12.706204736, 100.0}) {
        CHECK(studentTTwoSidedP(t, 1.0) == Approx(1.0 - 2.0 / kPiD * std::atan(t)).epsilon(1e-10).margin(1e-14));
        CHECK(studentTTwoSidedP(-t, 2.0) == Approx(1.0 - t / std::sqrt(2.0 + t * t)).epsilon(1e-10).margin(1e-14));
        // Large nu: the normal tail erfc(t / sqrt 2).
        CHECK(studentTTwoSidedP(t, 1e8) == Approx(std::erfc(t / std::sqrt(2.0))).epsilon(1e-6).margin(1e-14));
    }
    // Tabulated quantiles: t_{0.975, 10} = 2.228138852, t_{0.995, 5} = 4.032142984.
    CHECK(studentTTwoSidedP(2.228138852, 10.0) == Approx(0.05).epsilon(1e-8));
    CHECK(studentTTwoSidedP(4.032142984, 5.0) == Approx(0.01).epsilon(1e-8));
    // I_x(a, 1) = x^a, I_x(1, b) = 1 - (1 - x)^b.
    CHECK(regularizedBeta(3.7, 1.0, 0.42) == Approx(std::pow(0.42, 3.7)).epsilon(1e-12));
    CHECK(regularizedBeta(1.0, 5.3, 0.91) == Approx(1.0 - std::pow(0.09, 5.3)).epsilon(1e-12));

    // Binomial: exact quantiles (computed with rational arithmetic): for m = 576, 1000 and 4096
    // at p = 0.01, the smallest q with P(X <= q) >= 1 - 1e-4 is 16, 24 and 67.
    CHECK(binomialQuantile(576, 0.01, kBinomialLevel) == 16);
    CHECK(binomialQuantile(1000, 0.01, kBinomialLevel) == 24);
    CHECK(binomialQuantile(4096, 0.01, kBinomialLevel) == 67);
    CHECK(binomialCdf(5, 576, 0.01) == Approx(0.4843205728534686).epsilon(1e-10));
    CHECK(binomialCdf(0, 1, 0.25) == Approx(0.75));

    // Welch comparison of synthetic images: per pixel and channel, 64 normal samples of sd 0.5
    // and mean 1 (+ bias), from a counter-based generator (Box-Muller).
    auto synth = [](uint64_t seed, double bias, int w, int h) {
        return momentsFrom(w, h, [&](int x, int y) {
            TestRng rng(seed, uint64_t(y * w + x));
            PixelMoments m;
            const int n = 64;
            for (int c = 0; c < 3; ++c) {
                double s = 0, s2 = 0;
                for (int i = 0; i < n; ++i) {
                    const double u1 = 1.0 - rng.uniformDouble(), u2 = rng.uniformDouble();
                    const double v = 1.0 + bias + 0.5 * std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kPiD * u2);
                    s += v;
                    s2 += v * v;
                }
                m.mean[c] = s / n;
                m.varianceOfMean[c] = (s2 - s * s / n) / (n - 1) / n;
            }
            m.count = n;
            return m;
        });
    };
    const ImageComparison same = compareImages(synth(1, 0.0, 64, 64), synth(2, 0.0, 64, 64));
    INFO(same.report);
    CHECK(same.tested == 4096);
    CHECK(same.passed());
    CHECK(same.rejected >= 10);  // about 0.01 * 4096 = 41 expected: the level is not far too strict
    // A bias of 0.1 (1.6 standard errors of the difference) is detected.
    const ImageComparison biased = compareImages(synth(1, 0.0, 64, 64), synth(2, 0.1, 64, 64));
    INFO(biased.report);
    CHECK_FALSE(biased.passed());
    // Zero-variance channels are compared for exact equality.
    MomentImage z1 = momentsFrom(2, 1, [](int, int) { return PixelMoments{DVec3(1.0), DVec3(0.0), 8}; });
    MomentImage z2 = z1;
    CHECK(compareImages(z1, z2).passed());
    CHECK(compareImages(z1, z2).exactOnly == 2);
    z2.pixels[1].mean.y = 1.0 + 1e-12;
    CHECK(compareImages(z1, z2).exactMismatches == 1);
    CHECK_FALSE(compareImages(z1, z2).passed());

    // Effective samples: 4 hits of 25 among 100 samples (mean 1, s^2 = (4 * 625 - 100) / 99).
    CHECK(effectiveSamples(1.0, 2400.0 / 99.0 / 100.0, 100) == Approx(4.0).epsilon(1e-12));
    CHECK(effectiveSamples(3.0, 0.0, 50) == Approx(50.0));  // a constant: every sample counts
    CHECK(effectiveSamples(0.0, 0.0, 50) == 0.0);
    // Rare events are not t-tested: no hit at all in one image, 4 hits in the other.
    const MomentImage none = momentsFrom(1, 1, [](int, int) { return PixelMoments{DVec3(0.0), DVec3(0.0), 100}; });
    const MomentImage rare =
        momentsFrom(1, 1, [](int, int) { return PixelMoments{DVec3(1.0), DVec3(2400.0 / 99.0 / 100.0), 100}; });
    const ImageComparison r = compareImages(none, rare);
    CHECK(r.lowEffective == 1);
    CHECK(r.tested == 0);
    CHECK(r.passed());
    // Blocks: means average, variances of the mean add with weight 1 / block^4.
    const MomentImage quad = momentsFrom(2, 2, [](int x, int y) {
        return PixelMoments{DVec3(double(1 + x + 2 * y)), DVec3(double(4 * (1 + x + 2 * y))), 7};
    });
    const MomentImage merged = mergeBlocks(quad, 2);
    REQUIRE(merged.width == 1);
    CHECK(merged.at(0, 0).mean.x == Approx(2.5));
    CHECK(merged.at(0, 0).varianceOfMean.x == Approx(40.0 / 16.0));
    CHECK(merged.at(0, 0).count == 7);
}

// ---- (a), (b): PT, LT and BDPT agree per pixel --------------------------------------------------

namespace {
void checkEstimatorsAgree(const Scene& scene, const std::array<int, 4>& spp) {
    std::vector<Setup> setups(4);
    setups[0].integrator = "path";
    setups[1].integrator = "lt";
    setups[2].heuristic = MisHeuristic::Balance;
    setups[3].heuristic = MisHeuristic::Power;
    std::vector<std::pair<std::string, MomentImage>> images;
    for (size_t i = 0; i < setups.size(); ++i) {
        setups[i].spp = spp[i];
        setups[i].seed = uint32_t(1000 + 17 * i);  // independent renders
        const Film f = renderEstimator(scene, setups[i]);
        CHECK(f.nonFiniteSamples() == 0);
        images.emplace_back(estimatorName(setups[i]), momentsOf(f));
    }
    checkPairwiseAgreement(images, kDetectableBias);
}
void checkEstimatorsAgree(const std::string& sceneFile, const std::array<int, 4>& spp) {
    checkEstimatorsAgree(loadTestScene(sceneFile, 24, 24), spp);
}
}  // namespace

TEST_CASE("PT LT BDPT-balance and BDPT-power agree per pixel on the Cornell box", "[bdpt][agreement]") {
    checkEstimatorsAgree("scenes/cornell-box.gltf", {1024, 1024, 512, 512});
}

// Normal map, MASK and BLEND, COLOR_0 and an emissive texture with a black texel together. Before
// next-event estimation was decoupled from the light subpath (lastLightStrategy), BDPT was ~10%
// dark here: light subpaths starting on the black texel took s = 1 away from the camera subpath.
TEST_CASE("PT LT BDPT-balance and BDPT-power agree per pixel on the glTF features scene (normal map, MASK and BLEND, emissive texture, COLOR_0)",
          "[bdpt][agreement][gltf-features]") {
    checkEstimatorsAgree("scenes/gltf-features.gltf", {1024, 1024, 512, 512});
}

TEST_CASE("PT LT BDPT-balance and BDPT-power agree per pixel on the Cornell box with a small light",
          "[bdpt][agreement]") {
    checkEstimatorsAgree("scenes/cornell-small-light.gltf", {1024, 1024, 512, 512});
}

TEST_CASE("PT LT BDPT-balance and BDPT-power agree per pixel through an orthographic camera", "[bdpt][agreement][camera]") {
    // The film (half-height 290 mm) covers the box; t = 1 connects to the film point a vertex
    // projects onto (docs/camera.md, "Orthographic cameras"). LT gets 4x the samples: through this
    // film its per-pixel standard error is about twice BDPT's, and at 1024 spp a 5% bias in LT
    // was not detectable (the power check of checkPairwiseAgreement failed, the agreement held).
    checkEstimatorsAgree(loadTestSceneOrthographic("scenes/cornell-box.gltf", 24, 24, 290.f), {1024, 4096, 512, 512});
}

// ---- (c), (d): strategy layers ----------------------------------------------------------------
//
// Every strategy (s, t) that can sample all the paths of n vertices carrying light is, UNWEIGHTED,
// an unbiased estimator of the same image: the light transported along paths of exactly n
// vertices. So, per path length n, the unweighted layers are compared pairwise. Each comparison
// pairs a layer of render A with a layer of render B (different seeds): independent samples.
//
// Two views of the same renders:
//  * the image mean of every layer, its standard error from the per-pass image means (the passes
//    are independent), compared at k = 5 sigma; the test also requires 5 sigma of the difference
//    to be below 25% of the layer's value (kLayerDetectableBias) so that it cannot become
//    vacuous (measured: 2-3% for the s >= 1 layers of the Cornell box, 15% for its s = 0 layers,
//    which hit the 130 x 105 light by BSDF sampling alone);
//  * per pixel (image_stats.h), which localises an error. A layer in the rare-event regime per
//    pixel (the Cornell box's unweighted s = 0: median 2 effective samples per pixel at 512 spp,
//    where the t-test does not apply, see image_stats.h) is compared per block of 4 x 4 pixels
//    instead (mergeBlocks: exact for a layer whose pixels are independent within a pass, as for
//    every t >= 2 strategy, and conservative for a single t = 1 layer, whose pixels are
//    negatively correlated: one light path splats at most once into it), with ~16 times the
//    effective samples.
//
// Strategies with an interior connection (s >= 2 and t >= 2) have INFINITE variance in a scene
// with concave edges: near an edge both connected vertices can approach each other on the two
// faces, and G = cos cos / d^2 is unbounded (x at distance a from the edge gives E[G^2] ~ 1/a^2,
// not integrable over a pixel that sees the edge). Their sample means are then skewed low
// (measured: the unweighted (2,2) layer of the Cornell box is 2-10 standard errors below the
// other n = 4 layers exactly in the pixels that see the box's and the blocks' concave edges, and
// its standard error jumps by a factor 3 from seed to seed), and no mean-and-variance test
// applies. So the Cornell box compares the n = 4 layers without (2,2); the interior connections
// are compared inside the sphere around the point light, where two points of the sphere always
// have G = 1 / (4 R^2): bounded. The environment-lit sphere exercises the infinite light in
// every strategy (s = 0 escaping, s = 1 next-event, t = 1 light paths from the environment).

namespace {

struct LayerScene {
    std::string file;
    Rgb env{0.f};
    int resolution = 24;
    int spp = 512;
    int maxDepth = 5;
    std::vector<int> lengths;  // path lengths n (vertices) to compare
    // Block size for the per-pixel comparison of a layer in the rare-event regime (1: per pixel).
    std::function<int(int s, int t)> block = [](int, int) { return 1; };
};

bool interiorConnection(int s, int t) { return s >= 2 && t >= 2; }

// Renders the scene twice (seeds 2001, 2002) with strategy layers and compares the unweighted
// layers of each length pairwise. `skip(s, t)` leaves a strategy out. Returns render A.
Film checkUnweightedLayersAgree(const LayerScene& ls, const std::function<bool(int, int)>& skip) {
    const Scene scene = loadTestScene(ls.file, ls.resolution, ls.resolution, ls.env);
    Setup s;
    s.layers = true;
    s.maxDepth = ls.maxDepth;
    s.spp = ls.spp;
    // Per-pass image means of the unweighted layers of the lengths under test.
    using Key = std::pair<int, int>;
    using Totals = std::map<Key, PassStatistic>;
    auto recordTotals = [&](Totals& totals, std::map<Key, DVec3>& previous) {
        return [&](const Film& f, int passesDone) {
            const StrategyLayers& L = f.strategies();
            for (int n : ls.lengths)
                for (int sl = 0; sl < n; ++sl) {
                    DVec3 total(0.0);
                    for (int y = 0; y < f.height(); ++y)
                        for (int x = 0; x < f.width(); ++x) total += L.mean(sl, n - sl, false, x, y);
                    total *= double(passesDone);  // the layer's sum over passes and pixels
                    DVec3& prev = previous[{sl, n - sl}];
                    totals[{sl, n - sl}].add((total - prev) / double(f.pixelCount()));
                    prev = total;
                }
        };
    };
    Totals totalsA, totalsB;
    std::map<Key, DVec3> prevA, prevB;
    s.seed = 2001;
    Film a = renderEstimator(scene, s, recordTotals(totalsA, prevA));
    s.seed = 2002;
    const Film b = renderEstimator(scene, s, recordTotals(totalsB, prevB));
    REQUIRE(a.strategies().enabled());
    REQUIRE(a.strategies().maxDepth() == ls.maxDepth);
    CHECK(a.nonFiniteSamples() == 0);
    CHECK(b.nonFiniteSamples() == 0);

    for (int n : ls.lengths) {
        std::vector<int> strategies;
        for (int sl = 0; sl < n; ++sl)
            if (!skip(sl, n - sl)) strategies.push_back(sl);
        REQUIRE(strategies.size() >= 2);
        for (size_t i = 0; i < strategies.size(); ++i)
            for (size_t j = i + 1; j < strategies.size(); ++j) {
                const int s1 = strategies[i], s2 = strategies[j];
                const std::string la = "A(s=" + std::to_string(s1) + ",t=" + std::to_string(n - s1) + ")";
                const std::string lb = "B(s=" + std::to_string(s2) + ",t=" + std::to_string(n - s2) + ")";
                INFO(ls.file << ": " << la << " vs " << lb);
                // Image means.
                const PassStatistic& ta = totalsA[{s1, n - s1}];
                const PassStatistic& tb = totalsB[{s2, n - s2}];
                for (int c = 0; c < 3; ++c) {
                    const double sigma = std::sqrt(sqr(ta.standardError()[c]) + sqr(tb.standardError()[c]));
                    INFO("image mean of channel " << c << ": " << ta.mean()[c] << " +- " << ta.standardError()[c]
                                                  << " vs " << tb.mean()[c] << " +- " << tb.standardError()[c]);
                    CHECK(std::abs(ta.mean()[c] - tb.mean()[c]) <= kSigmas * sigma);
                    CHECK(ta.mean()[c] > 0.0);
                    CHECK(kSigmas * sigma < kLayerDetectableBias * tb.mean()[c]);
                }
                // Per pixel (or per block for a layer in the rare-event regime, see above).
                const int block = std::max(ls.block(s1, n - s1), ls.block(s2, n - s2));
                const MomentImage ia = mergeBlocks(layerMoments(a, s1, n - s1, false), block);
                const MomentImage ib = mergeBlocks(layerMoments(b, s2, n - s2, false), block);
                const ImageComparison c = compareImages(ia, ib, kPixelAlpha, la, lb);
                INFO("blocks of " << block << " x " << block << " pixels: " << c.report);
                CHECK(c.passed());
                // Not vacuous: (almost) every pixel is compared, by the t-test or for exact
                // equality (the Cornell box's ceiling receives no light along paths of 3 vertices;
                // blocks: the top row, ceiling and light edge, has few effective samples).
                CHECK(c.tested + c.exactOnly >= c.pixels * 4 / 5);
            }
    }
    return a;
}

}  // namespace

TEST_CASE("Unweighted strategy layers of equal path length agree in the Cornell box and weighted layers sum to the image",
          "[bdpt][strategies]") {
    // The diffuse Cornell box: every surface Lambertian, the light an area light that can be
    // hit, every surface vertex connectible to the pinhole. Lengths n = 3 (direct lighting) and
    // n = 4, all s = 0..n-1 except the interior connection (2,2) (see above).
    LayerScene ls;
    ls.file = "scenes/cornell-box.gltf";
    ls.lengths = {3, 4};
    ls.block = [](int s, int) { return s == 0 ? 4 : 1; };
    const Film a = checkUnweightedLayersAgree(ls, interiorConnection);

    // (d) The weighted layers sum to the image, per pixel.
    {
        // The image's sample of a pass is the float sum of the pixel's camera-side contributions
        // and of the splats landing there; the layers accumulate the same float terms (the
        // weighted contribution is computed once), grouped by strategy. The two differ only by
        // the rounding of float sums of k non-negative terms, at most (k - 1) 2^-24 of their
        // total: below 2e-6 for the k < 30 terms of a pass at depth 5 (measured: 4e-8). A
        // contribution missing from the layers, recorded at another pixel than the image's, or
        // with another weight changes the sum by the whole contribution.
        const StrategyLayers& L = a.strategies();
        double worst = 0.0;
        int bad = 0;
        for (int y = 0; y < a.height(); ++y)
            for (int x = 0; x < a.width(); ++x) {
                DVec3 total(0.0), magnitude(0.0);
                for (int d = 0; d <= L.maxDepth(); ++d)
                    for (int sl = 0; sl <= d + 1; ++sl) {
                        const DVec3 m = L.mean(sl, d + 2 - sl, true, x, y);
                        total += m;
                        magnitude += glm::abs(m);
                    }
                const DVec3 image = a.mean(x, y);
                for (int c = 0; c < 3; ++c) {
                    const double err = std::abs(total[c] - image[c]);
                    const double tol = 1e-5 * std::max(magnitude[c], std::abs(image[c])) + 1e-12;
                    worst = std::max(worst, err / tol);
                    if (err > tol) {
                        if (bad < 5) UNSCOPED_INFO("pixel (" << x << "," << y << ") channel " << c << ": layers sum to "
                                                           << total[c] << ", image " << image[c]);
                        ++bad;
                    }
                }
            }
        INFO("worst error / tolerance: " << worst);
        CHECK(bad == 0);
        CHECK(a.nonFiniteSamples() == 0);
    }
}

TEST_CASE("Unweighted strategy layers agree inside the sphere around a point light (interior connections)",
          "[bdpt][strategies]") {
    // Point light: s = 0 cannot sample any path (the light cannot be hit), every s >= 1 can.
    // n = 4 and 5 include the interior connections (2,2), (2,3) and (3,2), whose G is bounded on
    // a sphere.
    LayerScene ls;
    ls.file = "scenes/sphere-point-light.gltf";
    ls.resolution = 16;
    ls.spp = 256;
    ls.maxDepth = 3;
    ls.lengths = {3, 4, 5};
    checkUnweightedLayersAgree(ls, [](int s, int) { return s == 0; });
}

TEST_CASE("Unweighted strategy layers agree on the sphere under a constant environment (infinite light)",
          "[bdpt][strategies]") {
    // Paths of 3 vertices: s = 0 escapes to the environment after one bounce, s = 1 samples the
    // environment, s = 2 (t = 1) starts light paths from the environment's disk. Few of those
    // reach the cap of the sphere the camera sees (median ~5 effective samples per pixel at 512
    // spp): the t = 1 layer is compared per block of 4 x 4 pixels.
    LayerScene ls;
    ls.file = "scenes/env-sphere.glb";
    ls.env = Rgb(0.8f, 1.0f, 1.3f);
    ls.resolution = 16;
    ls.spp = 512;
    ls.maxDepth = 1;
    ls.lengths = {3};
    ls.block = [](int, int t) { return t == 1 ? 4 : 1; };
    checkUnweightedLayersAgree(ls, [](int, int) { return false; });
}

// ---- (e): analytic scenes with BDPT and LT ------------------------------------------------------
//
// The checks of test_analytic_pt.cpp for BDPT (balance and power) and light tracing: the image
// mean within k = 5 standard errors of the exact value, the standard error computed from the
// per-pass image means (PassPooled: splats make the pixels of a pass dependent) and required to be
// below 0.3% of the value for BDPT, so that a 1.5% error cannot hide in the tolerance.
//
// Light tracing gets a looser sigma bound, 1% (k stays 5): in these scenes a light vertex
// contributes only if it lies in the camera's view (5-10% of the surfaces: the camera sees part
// of one wall of the furnace, ~8% of the sphere around the point light, and the environment's
// light paths mostly miss the visible cap of the sphere). Measured: LT reaches a standard error
// of 0.4-0.8% with 0.26-1 million light paths where BDPT reaches 0.1-0.2% with 16-32 thousand
// samples, so 0.3% would take LT 5-15 s per configuration. LT's absolute level is checked
// more tightly by the per-pixel comparison with PT above (a uniform 5% error fails it); here the
// depth bookkeeping of LT is what matters, and neighbouring depths differ by 12% or more at the
// depths tested for LT (furnace depth 5 vs 64 differ by only 1.6% and is left to BDPT).

namespace {
constexpr double kMaxRelativeSigma = 0.003;
constexpr double kMaxRelativeSigmaLt = 0.01;

struct AnalyticEstimator {
    Setup setup;
    int resolution;
    double maxRelativeSigma;
};

// BDPT at 16 x 16 pixels, LT at 32 x 32 (the standard error depends on the number of light
// paths, and larger passes keep both threads busy); spp measured to meet the sigma bounds with
// margin.
std::vector<AnalyticEstimator> analyticEstimators(int bdptSpp, int ltSpp) {
    std::vector<AnalyticEstimator> v(3);
    v[0].setup.heuristic = MisHeuristic::Balance;
    v[1].setup.heuristic = MisHeuristic::Power;
    v[2].setup.integrator = "lt";
    v[0].setup.spp = v[1].setup.spp = bdptSpp;
    v[2].setup.spp = ltSpp;
    v[0].resolution = v[1].resolution = 16;
    v[2].resolution = 32;
    v[0].maxRelativeSigma = v[1].maxRelativeSigma = kMaxRelativeSigma;
    v[2].maxRelativeSigma = kMaxRelativeSigmaLt;
    return v;
}

bool isLt(const AnalyticEstimator& e) { return e.setup.integrator == "lt"; }

void checkMean(const PassPooled& m, const DVec3& exact, double maxRelativeSigma) {
    for (int c = 0; c < 3; ++c) {
        INFO("channel " << c << ": estimate " << m.mean[c] << " +- " << m.standardError[c] << ", exact " << exact[c]
                        << " (" << m.passes << " passes)");
        CHECK(std::abs(m.mean[c] - exact[c]) <= kSigmas * m.standardError[c] + 1e-6 * exact[c]);
        CHECK(m.standardError[c] < maxRelativeSigma * exact[c]);
    }
}
}  // namespace

TEST_CASE("BDPT and LT: closed emitting box gives Le (1 - rho^(N+1)) / (1 - rho)", "[bdpt][analytic]") {
    Scene scene = loadTestScene("scenes/furnace-box.gltf", 16, 16);
    const double rho = 0.5, Le = 1.0;
    for (const AnalyticEstimator& e : analyticEstimators(64, 320)) {
        for (int depth : {0, 1, 2, 5, 64}) {
            if (isLt(e) && depth == 5) continue;  // see above
            DYNAMIC_SECTION(estimatorName(e.setup) << ", max depth " << depth) {
                Setup s = e.setup;
                scene.camera = scene.camera.withResolution(e.resolution, e.resolution);
                s.maxDepth = depth;
                s.seed = uint32_t(300 + depth);
                const PassPooled m = renderPassPooled(scene, s);
                // (BDPT at depth 0 is strategy (0,2) alone, deterministic: sigma = 0, exact.)
                checkMean(m, DVec3(Le * (1.0 - std::pow(rho, depth + 1)) / (1.0 - rho)), e.maxRelativeSigma);
            }
        }
    }
}

TEST_CASE("BDPT and LT: point light inside a diffuse sphere", "[bdpt][analytic]") {
    // The interval argument of test_analytic_pt.cpp: the depth-N radiance of the inscribed
    // polyhedron lies in [h_min, 1/h_min^2] times the sphere's value.
    Scene scene = loadTestScene("scenes/sphere-point-light.gltf", 16, 16);
    double hMin = 1.0;
    for (const glm::uvec3& t : scene.mesh.indices) {
        const DVec3 a(scene.mesh.positions[t.x]), b(scene.mesh.positions[t.y]), c(scene.mesh.positions[t.z]);
        hMin = std::min(hMin, std::abs(glm::dot(glm::normalize(glm::cross(b - a, c - a)), a)));
    }
    REQUIRE(hMin > 0.999);
    const double rho = 0.5, I = 1.0, R = 1.0;
    for (const AnalyticEstimator& e : analyticEstimators(64, 256)) {
        for (int depth : {1, 3, 64}) {
            if (isLt(e) && depth == 3) continue;  // time: LT's depth 1 and 64 suffice here
            DYNAMIC_SECTION(estimatorName(e.setup) << ", max depth " << depth) {
                Setup s = e.setup;
                scene.camera = scene.camera.withResolution(e.resolution, e.resolution);
                s.maxDepth = depth;
                s.seed = uint32_t(400 + depth);
                const PassPooled m = renderPassPooled(scene, s);
                const double sphere = rho * I / (kPiD * R * R) * (1.0 - std::pow(rho, depth)) / (1.0 - rho);
                const double lo = sphere * hMin, hi = sphere / (hMin * hMin);
                for (int c = 0; c < 3; ++c) {
                    INFO("channel " << c << ": " << m.mean[c] << " +- " << m.standardError[c] << ", interval [" << lo
                                    << ", " << hi << "] (" << m.passes << " passes)");
                    CHECK(m.mean[c] >= lo - kSigmas * m.standardError[c]);
                    CHECK(m.mean[c] <= hi + kSigmas * m.standardError[c]);
                    CHECK(m.standardError[c] < e.maxRelativeSigma * sphere);
                }
            }
        }
    }
}

TEST_CASE("BDPT and LT: convex Lambertian object under a constant environment gives rho * L_env",
          "[bdpt][analytic]") {
    const Rgb env(0.8f, 1.0f, 1.3f);
    Scene scene = loadTestScene("scenes/env-sphere.glb", 16, 16, env);
    const double rho = 0.5;
    for (const AnalyticEstimator& e : analyticEstimators(128, 1024)) {
        for (int depth : {1, 64}) {
            DYNAMIC_SECTION(estimatorName(e.setup) << ", max depth " << depth) {
                Setup s = e.setup;
                scene.camera = scene.camera.withResolution(e.resolution, e.resolution);
                s.maxDepth = depth;
                s.seed = uint32_t(500 + depth);
                const PassPooled m = renderPassPooled(scene, s);
                checkMean(m, rho * DVec3(env), e.maxRelativeSigma);
            }
        }
    }
}

// ---- (f): crop windows ----------------------------------------------------------------------------

TEST_CASE("A crop window renders the same expected image as that region of the full render", "[bdpt][crop]") {
    // Light-tracing normalisation must not depend on the crop: a crop render traces one light
    // path per cropped pixel and pass, and its camera importance is defined over the crop's share
    // of the image plane (camera.h), so that its splats and its t = 1 MIS densities match its
    // camera samples. The errors this catches are large: normalising the splats by the full
    // image's pixel count scales the crop's light image by 144 / 576, and mixing crop and full
    // image-plane areas between the splat and the t = 1 MIS density biases BDPT by the t = 1
    // strategies' weighted share (tens of percent). The crop receives 4 times the passes of the
    // full render, so that both estimate the region from about the same number of light paths;
    // the comparison must detect a uniform 10% error (kCropDetectableBias).
    Scene scene = loadTestScene("scenes/cornell-box.gltf", 24, 24);
    const Camera full = scene.camera;
    const PixelRect crop{5, 7, 17, 19};
    for (const char* integ : {"bdpt", "lt"}) {
        DYNAMIC_SECTION(integ) {
            Setup s;
            s.integrator = integ;
            s.spp = std::string(integ) == "lt" ? 1024 : 256;
            s.seed = 61;
            scene.camera = full;
            const Film whole = renderEstimator(scene, s);
            scene.camera = full.withCrop(crop.x0, crop.y0, crop.x1, crop.y1);
            s.seed = 62;
            s.spp *= 4;
            s.tileSize = 6;  // the 12 x 12 window in 4 equal tiles
            const Film part = renderEstimator(scene, s);
            scene.camera = full;
            CHECK(whole.nonFiniteSamples() == 0);
            CHECK(part.nonFiniteSamples() == 0);
            // The crop render samples its window only, and its light image stays inside it.
            uint64_t outside = 0;
            double lightOutside = 0.0, lightInside = 0.0;
            for (int y = 0; y < part.height(); ++y)
                for (int x = 0; x < part.width(); ++x) {
                    const bool in = x >= crop.x0 && x < crop.x1 && y >= crop.y0 && y < crop.y1;
                    if (in) {
                        CHECK(part.count(x, y) == uint64_t(s.spp));
                        lightInside += part.lightMean(x, y).x;
                    } else {
                        outside += part.count(x, y);
                        lightOutside += part.lightMean(x, y).x;
                    }
                }
            CHECK(outside == 0);
            CHECK(lightOutside == 0.0);
            CHECK(lightInside > 0.0);
            const ImageComparison c = compareFilmRegions(part, crop, whole, crop, kPixelAlpha,
                                                         std::string(integ) + " crop", std::string(integ) + " full");
            INFO(c.report);
            CHECK(c.passed());
            CHECK(c.tested >= c.pixels * 9 / 10);
            const ImageComparison up = compareImages(scaledMoments(momentsOf(part, crop), 1.0 + kCropDetectableBias),
                                                     momentsOf(whole, crop), kPixelAlpha, "crop (scaled)", "full");
            const ImageComparison down = compareImages(momentsOf(part, crop), scaledMoments(momentsOf(whole, crop), 1.0 + kCropDetectableBias),
                                                       kPixelAlpha, "crop", "full (scaled)");
            INFO(up.report);
            INFO(down.report);
            CHECK_FALSE(up.passed());
            CHECK_FALSE(down.passed());
        }
    }
}

// ---- (g): determinism with splats and layers --------------------------------------------------------

TEST_CASE("BDPT and LT films, light images and strategy layers are bit-identical on 1 and 2 threads",
          "[bdpt][determinism]") {
    const Scene scene = loadTestScene("scenes/cornell-box.gltf", 24, 24);
    for (const char* integ : {"bdpt", "lt"}) {
        DYNAMIC_SECTION(integ) {
            Setup s;
            s.integrator = integ;
            s.layers = std::string(integ) == "bdpt";
            s.spp = 4;
            s.seed = 77;
            s.tileSize = 8;  // 9 tiles, so that the two threads really split the work
            s.threads = 1;
            const Film a = renderEstimator(scene, s);
            s.threads = 2;
            const Film b = renderEstimator(scene, s);
            bool identical = true;
            double lightTotal = 0.0;
            for (int y = 0; y < a.height(); ++y)
                for (int x = 0; x < a.width(); ++x) {
                    identical = identical && a.sum(x, y) == b.sum(x, y) && a.sumSquares(x, y) == b.sumSquares(x, y) &&
                                a.count(x, y) == b.count(x, y) && a.lightMean(x, y) == b.lightMean(x, y);
                    lightTotal += a.lightMean(x, y).x;
                }
            CHECK(identical);
            CHECK(lightTotal > 0.0);  // splats happened: the comparison covers them
            if (s.layers) {
                const StrategyLayers& la = a.strategies();
                const StrategyLayers& lb = b.strategies();
                REQUIRE(la.maxDepth() == lb.maxDepth());
                bool layersIdentical = la.passes() == lb.passes();
                double splatLayerTotal = 0.0;
                for (int d = 0; d <= la.maxDepth(); ++d)
                    for (int sl = 0; sl <= d + 1; ++sl)
                        for (bool w : {false, true})
                            for (int y = 0; y < a.height(); ++y)
                                for (int x = 0; x < a.width(); ++x) {
                                    const int t = d + 2 - sl;
                                    layersIdentical = layersIdentical && la.mean(sl, t, w, x, y) == lb.mean(sl, t, w, x, y) &&
                                                      la.varianceOfMean(sl, t, w, x, y) == lb.varianceOfMean(sl, t, w, x, y);
                                    if (t == 1) splatLayerTotal += la.mean(sl, t, w, x, y).x;
                                }
                CHECK(layersIdentical);
                CHECK(splatLayerTotal > 0.0);  // the t = 1 (splat) layers are covered too
            }
        }
    }
}
