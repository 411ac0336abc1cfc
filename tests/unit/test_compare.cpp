// `bdptref compare` and the library behind it (include/bdptref/image_compare.h, docs/compare.md):
//  * the distributions it relies on against known values;
//  * correct renders with different seeds are judged consistent, and over 60 independent seed
//    pairs no p-value leans towards 0 (one-sided: the local test is conservative by design), the
//    bias test's are consistent with Uniform(0, 1) (Kolmogorov-Smirnov), and the local test finds
//    a 2 x 2 error of +50% in every pair;
//  * wrong images are flagged: a 1% global scale, a BDPT strategy whose MIS weight is doubled,
//    a light tracer without the cosine at the light (a test-only integrator);
//  * unusable input exits with 2; the heatmap and the JSON have what they promise.
// Every statistical test uses fixed seeds, so it is deterministic; a control (the same setup
// without the error) is always judged consistent, so a failure is attributable to the error.
#include "bdptref/bdpt.h"
#include "bdptref/exr_io.h"
#include "bdptref/image_compare.h"
#include "bdptref/integrator.h"
#include "bdptref/renderer.h"
#include "bdptref/scene.h"
#include "support/render_util.h"
#include "support/uniformity.h"

#include <OpenImageIO/imageio.h>
#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

using namespace bdptref;
using namespace bdptref::test;
namespace fs = std::filesystem;

namespace bdptref::test {
// Smallest q with P(Binomial(m, p) <= q) >= level (tests/support/image_stats.h, declared alone:
// that header's studentTTwoSidedP would make the stats:: calls below ambiguous).
uint64_t binomialQuantile(uint64_t m, double p, double level);
}  // namespace bdptref::test

namespace {

const std::string kCornell = sourcePath("scenes/cornell-box.gltf");
const char* kRgb[3] = {"R", "G", "B"};
const char* kVar[3] = {"variance.R", "variance.G", "variance.B"};

// ---- images -----------------------------------------------------------------------------------

// The layers a renderer writes (docs/compare.md): mean, variance of the mean, count. `scale`
// multiplies the mean (and the variance by scale^2), as a renderer with a global error would.
ExrImage imageOf(const Film& f, double scale = 1.0) {
    ExrImage img;
    img.width = f.width();
    img.height = f.height();
    for (int c = 0; c < 3; ++c) {
        img.channels[kRgb[c]].resize(f.pixelCount());
        img.channels[kVar[c]].resize(f.pixelCount());
    }
    img.channels["count"].resize(f.pixelCount());
    for (int y = 0; y < f.height(); ++y)
        for (int x = 0; x < f.width(); ++x) {
            const size_t i = size_t(y) * size_t(f.width()) + size_t(x);
            const DVec3 m = f.mean(x, y), v = f.varianceOfMean(x, y);
            for (int c = 0; c < 3; ++c) {
                img.channels[kRgb[c]][i] = float(m[c] * scale);
                img.channels[kVar[c]][i] = float(v[c] * scale * scale);
            }
            img.channels["count"][i] = float(f.count(x, y));
        }
    return img;
}

// A synthetic image: every pixel has mean `mean`, variance of the mean `var` and `count` samples.
ExrImage constantImage(int w, int h, float mean, float var, float count, bool withVariance = true) {
    ExrImage img;
    img.width = w;
    img.height = h;
    const size_t n = size_t(w) * size_t(h);
    for (int c = 0; c < 3; ++c) {
        img.channels[kRgb[c]].assign(n, mean);
        if (withVariance) img.channels[kVar[c]].assign(n, var);
    }
    if (withVariance) img.channels["count"].assign(n, count);
    return img;
}

// A synthetic noisy estimate of `truth` (per pixel): mean = truth + N(0, var), as an estimator
// with that variance of the mean would give.
ExrImage noisyImage(const ExrImage& truth, double var, uint32_t seed) {
    ExrImage img = truth;
    std::mt19937 rng(seed);
    std::normal_distribution<double> normal(0.0, 1.0);
    const double sd = std::sqrt(var);
    for (int c = 0; c < 3; ++c)
        for (float& v : img.channels[kRgb[c]]) v = float(double(v) + sd * normal(rng));
    return img;
}

const Scene& cornell16() {
    static const Scene s = loadTestScene("scenes/cornell-box.gltf", 16, 16);
    return s;
}
const Scene& cornell32() {
    static const Scene s = loadTestScene("scenes/cornell-box.gltf", 32, 32);
    return s;
}

std::string cli(const std::string& args, int* rc) {
    std::string out;
    *rc = runCli(args, &out);
    return out;
}

// ---- checks of p-values under H0 ---------------------------------------------------------------

uint64_t countBelow(const std::vector<double>& p, double level) {
    return uint64_t(std::count_if(p.begin(), p.end(), [level](double v) { return v < level; }));
}

// Valid p-values (P(p < x) <= x) do not lean towards 0: D+ below its 1% critical value, and the
// counts below 0.05, 0.01 and 0.001 at most the 99.5% quantile of Binomial(n, level). Conservative
// p-values (leaning towards 1) pass.
void checkNoExcessOfSmallPValues(const char* what, const std::vector<double>& p) {
    INFO(what << " p-values: " << p.size() << ", D+ = " << ksPlus(p) << " (critical " << ksPlusCritical01(p.size())
              << "), below 0.05 / 0.01 / 0.001: " << countBelow(p, 0.05) << " / " << countBelow(p, 0.01) << " / "
              << countBelow(p, 0.001));
    CHECK(ksPlus(p) <= ksPlusCritical01(p.size()));
    for (double level : {0.05, 0.01, 0.001}) CHECK(countBelow(p, level) <= binomialQuantile(p.size(), level, 0.995));
}

std::string listOf(const std::vector<double>& v) {
    std::string s;
    for (double x : v) s += std::to_string(x) + " ";
    return s;
}

// The p-values of compare over pairs of correct renders, and the local test on the same pairs with
// the test's 2 x 2 pixels (7..8, 6..7) made 50% (and 30%) too bright.
struct NullRuns {
    std::vector<double> pGlobal, pLocal, pBias, pMin, pPixel;
    int injectedRejected = 0, injectedFoundThere = 0, smallerInjectedRejected = 0;

    void add(const ExrImage& a, const ExrImage& b) {
        const CompareResult r = compareImages(a, b);
        REQUIRE(r.hasVerdict);
        REQUIRE(r.tested >= 200);
        pGlobal.push_back(r.pGlobal);
        pLocal.push_back(r.pLocal);
        pBias.push_back(r.pBias);
        pMin.push_back(r.pMin);
        for (size_t i = 0; i < r.status.size(); ++i)
            if (r.status[i] == PixelStatus::Tested) pPixel.push_back(double(r.pixelP[i]));
        const CompareResult e = compareImages(injected(a, 1.5), b);
        injectedRejected += e.pLocal < 0.01;
        injectedFoundThere += e.pMinX >= 7 && e.pMinX <= 8 && e.pMinY >= 6 && e.pMinY <= 7;
        smallerInjectedRejected += compareImages(injected(a, 1.3), b).pLocal < 0.01;
    }

    // A local error: the block's means scaled (and their variances by the square, as a renderer
    // with that error would write them).
    static ExrImage injected(ExrImage img, double scale) {
        for (int y = 6; y <= 7; ++y)
            for (int x = 7; x <= 8; ++x)
                for (int c = 0; c < 3; ++c) {
                    const size_t i = size_t(y) * size_t(img.width) + size_t(x);
                    img.channels[kRgb[c]][i] *= float(scale);
                    img.channels[kVar[c]][i] *= float(scale * scale);
                }
        return img;
    }
};

// ---- a deliberately wrong light tracer (test only) --------------------------------------------

// Light tracing (every light-subpath vertex connected to the pinhole) built from the library's
// subpath generation and connection, except that with `dropCosine` it omits |cos| at the light
// vertex: the emitted throughput is not multiplied by the cosine between the light's normal and
// the emitted direction (a classic port bug), and neither is the light seen directly (s = 1).
// With dropCosine = false it computes exactly what the library's light tracer computes.
class LightCosineTracer final : public Integrator {
public:
    LightCosineTracer(int maxDepth, bool dropCosine) : dropCosine_(dropCosine) { settings_.maxDepth = maxDepth; }
    const char* name() const override { return dropCosine_ ? "lt-without-light-cosine" : "lt-test-copy"; }
    bool producesSplats() const override { return true; }

    void samplePixel(const Scene& scene, int, int, const PixelSampler& sampler, SampleOutput& out) const override {
        thread_local std::vector<PathVertex> light, camera;
        light.resize(size_t(settings_.maxLightVertices()));
        camera.assign(1, PathVertex{});
        const int n = generateLightSubpath(scene, sampler, settings_, light.data());
        if (n <= 0) return;
        const bool area = scene.lights[size_t(light[0].light)].type == LightType::Area;
        if (dropCosine_ && area && n >= 2) {
            // generateLightSubpath multiplied the throughput by |cos| at the light: take it out.
            const float cosLight = absDot(light[0].ng, glm::normalize(light[1].p - light[0].p));
            if (!(cosLight > 0.f)) return;
            for (int i = 1; i < n; ++i) light[size_t(i)].beta /= cosLight;
        }
        for (int s = 1; s <= n && s - 1 <= settings_.maxDepth; ++s) {
            Connection c;
            PathVertex sampled;
            if (!connectStrategy(scene, light.data(), s, camera.data(), 1, sampler, settings_, &c, &sampled)) continue;
            Rgb L = c.unweighted;
            if (dropCosine_ && area && s == 1) {
                const float cosLight = absDot(light[0].ng, glm::normalize(sampled.p - light[0].p));
                if (!(cosLight > 0.f)) continue;
                L /= cosLight;
            }
            out.splats.push_back(Splat{c.raster, L});
        }
    }

private:
    BdptSettings settings_;
    bool dropCosine_;
};

Film renderWith(const Scene& scene, const Integrator& integ, int spp, uint32_t seed) {
    RenderOptions ro;
    ro.spp = spp;
    ro.seed = seed;
    Film film(scene.camera.width(), scene.camera.height());
    renderImage(scene, integ, ro, film);
    return film;
}

}  // namespace

// ===============================================================================================
// distributions
// ===============================================================================================

TEST_CASE("compare statistics: incomplete beta, Student t, normal quantile, Sidak, Cauchy combination", "[compare]") {
    using namespace bdptref::stats;
    // I_x(1, 1) = x, I_x(a, 1) = x^a, I_x(1, b) = 1 - (1 - x)^b, I_1/2(a, a) = 1/2.
    CHECK(regularizedIncompleteBeta(1, 1, 0.3) == Approx(0.3).epsilon(1e-12));
    CHECK(regularizedIncompleteBeta(3.5, 1, 0.6) == Approx(std::pow(0.6, 3.5)).epsilon(1e-12));
    CHECK(regularizedIncompleteBeta(1, 2.5, 0.2) == Approx(1 - std::pow(0.8, 2.5)).epsilon(1e-12));
    CHECK(regularizedIncompleteBeta(7.25, 7.25, 0.5) == Approx(0.5).epsilon(1e-12));
    // Student t two-sided critical values (tables): t_{0.975} = 12.7062 (1), 2.22814 (10), 1.98397 (100).
    CHECK(studentTTwoSidedP(12.7062047, 1) == Approx(0.05).epsilon(1e-6));
    CHECK(studentTTwoSidedP(2.22813885, 10) == Approx(0.05).epsilon(1e-6));
    CHECK(studentTTwoSidedP(-1.98397152, 100) == Approx(0.05).epsilon(1e-6));
    CHECK(studentTTwoSidedP(3.16927267, 10) == Approx(0.01).epsilon(1e-6));
    CHECK(studentTTwoSidedP(0, 5) == Approx(1.0));
    // Far tail: 1 dof is Cauchy, P(|T| > t) = 1 - 2 atan(t) / pi.
    CHECK(studentTTwoSidedP(1e6, 1) == Approx(2.0 / (3.14159265358979 * 1e6)).epsilon(1e-6));
    // Many degrees of freedom: the normal.
    CHECK(studentTTwoSidedP(1.959963985, 1e7) == Approx(0.05).epsilon(1e-8));
    CHECK(normalTwoSidedP(1.959963985) == Approx(0.05).epsilon(1e-8));
    CHECK(normalQuantile(0.975) == Approx(1.959963984540054).epsilon(1e-12));
    CHECK(normalQuantile(1e-10) == Approx(-6.361340902404056).epsilon(1e-10));
    CHECK(normalQuantile(0.5) == Approx(0.0).margin(1e-15));
    CHECK(zFromTwoSidedP(0.05) == Approx(1.959963984540054).epsilon(1e-12));
    CHECK(zFromTwoSidedP(normalTwoSidedP(8.5)) == Approx(8.5).epsilon(1e-9));
    // Sidak, without cancellation for tiny p.
    CHECK(sidak(0.01, 1) == Approx(0.01));
    CHECK(sidak(0.05, 2) == Approx(1 - 0.95 * 0.95));
    CHECK(sidak(1e-12, 1000) == Approx(1e-9).epsilon(1e-6));
    // Cauchy combination: exact for identical p-values, and for independent ones (two standard
    // Cauchy variables averaged are standard Cauchy): p = 1/2 - atan(T)/pi.
    const double same[3] = {0.0123, 0.0123, 0.0123};
    CHECK(cauchyCombination(same, 3) == Approx(0.0123).epsilon(1e-9));
    const double two[2] = {0.2, 0.7};
    const double T = 0.5 * (std::tan((0.5 - 0.2) * 3.14159265358979) + std::tan((0.5 - 0.7) * 3.14159265358979));
    CHECK(cauchyCombination(two, 2) == Approx(0.5 - std::atan(T) / 3.14159265358979).epsilon(1e-9));
    const double tiny[2] = {1e-200, 0.5};
    CHECK(cauchyCombination(tiny, 2) == Approx(2e-200).epsilon(1e-6));
}

TEST_CASE("compare statistics: the Kolmogorov-Smirnov helpers of this test file reproduce known values and reject a non-uniform sample", "[compare]") {
    // Kolmogorov's distribution: Q(1.358) = 0.05, Q(1.628) = 0.01 (lambda without the correction:
    // pass n huge).
    CHECK(ksPValue(1.358 / std::sqrt(1e12), size_t(1e12)) == Approx(0.05).epsilon(2e-3));
    CHECK(ksPValue(1.628 / std::sqrt(1e12), size_t(1e12)) == Approx(0.01).epsilon(5e-3));
    std::vector<double> grid, cubes;
    for (int i = 0; i < 30; ++i) {
        grid.push_back((i + 0.5) / 30.0);
        cubes.push_back(std::pow((i + 0.5) / 30.0, 3.0));  // far from uniform
    }
    CHECK(ksStatistic(grid) == Approx(0.5 / 30.0));
    CHECK(ksPValue(ksStatistic(grid), 30) > 0.99);
    CHECK(ksPValue(ksStatistic(cubes), 30) < 0.001);
}

// ===============================================================================================
// metrics and per-pixel rules on synthetic images
// ===============================================================================================

TEST_CASE("compare metrics: MSE, RMSE, relMSE, MAE, max error and its place, mean bias and its CI", "[compare]") {
    // 4x2 images without variances: the bias CI comes from the spread of t - r over the pixels.
    ExrImage ref = constantImage(4, 2, 1.f, 0, 0, false), test = ref;
    const float d[8] = {0.1f, -0.1f, 0.2f, 0.f, 0.f, 0.3f, -0.2f, 0.1f};
    for (int c = 0; c < 3; ++c)
        for (int i = 0; i < 8; ++i) test.channels[kRgb[c]][size_t(i)] = 1.f + d[i] * float(c + 1);
    CompareOptions o;
    o.epsilon = 0.5;
    const CompareResult r = compareImages(test, ref, o);
    CHECK(r.kind == TestKind::None);
    CHECK_FALSE(r.hasVerdict);
    CHECK_FALSE(r.biasFromVariances);
    for (int c = 0; c < 3; ++c) {
        double se = 0, ae = 0, sum = 0, sum2 = 0, mx = 0;
        for (int i = 0; i < 8; ++i) {
            const double di = double(test.channels[kRgb[c]][size_t(i)]) - 1.0;
            se += di * di;
            ae += std::abs(di);
            sum += di;
            sum2 += di * di;
            mx = std::max(mx, std::abs(di));
        }
        const ChannelMetrics& m = r.channel[size_t(c)];
        CHECK(m.mse == Approx(se / 8));
        CHECK(m.rmse == Approx(std::sqrt(se / 8)));
        CHECK(m.relMse == Approx(se / 8 / 1.5));  // r^2 + eps = 1.5
        CHECK(m.mae == Approx(ae / 8));
        CHECK(m.maxAbs == Approx(mx));
        CHECK(m.maxX == 1);  // the 0.3 entry: pixel 5 = (1, 1)
        CHECK(m.maxY == 1);
        CHECK(m.bias == Approx(sum / 8));
        const double sd = std::sqrt((sum2 - sum * sum / 8) / 7);
        CHECK(m.biasHigh - m.bias == Approx(1.959963985 * sd / std::sqrt(8.0)));
        CHECK(m.relativeBias == Approx(sum / 8));
    }
    CHECK(r.overall.maxChannel == 2);
    CHECK(r.overall.mse == Approx((r.channel[0].mse + r.channel[1].mse + r.channel[2].mse) / 3));
}

TEST_CASE("compare per-pixel rules: zero-variance equality, count < 2 excluded, NaN flagged, z-test against the reference", "[compare]") {
    const ExrImage ref = constantImage(8, 8, 0.5f, 1e-4f, 100);
    ExrImage test = noisyImage(ref, 1e-4, 7);
    for (int c = 0; c < 3; ++c) test.channels[kVar[c]].assign(64, 1e-4f);

    SECTION("zero variance in both images: equal passes, different fails") {
        ExrImage t = test, r = ref;
        for (int c = 0; c < 3; ++c) {
            t.channels[kVar[c]][0] = r.channels[kVar[c]][0] = 0.f;
            t.channels[kRgb[c]][0] = r.channels[kRgb[c]][0] = 2.f;
        }
        CompareResult res = compareImages(t, r);
        CHECK(res.equal == 1);
        CHECK(res.consistent);
        t.channels["G"][0] = 2.01f;
        res = compareImages(t, r);
        CHECK(res.unequal == 1);
        CHECK_FALSE(res.consistent);
        CHECK(res.pGlobal == 0.0);
        CHECK(res.flagged >= 1);
        CHECK(res.sentence.find("zero-variance pixels differ") != std::string::npos);
    }
    SECTION("two images rendered with the same seed are reported (their noise is not independent)") {
        ExrImage t = test, r = ref;
        t.attributes["bdptref:seed"] = r.attributes["bdptref:seed"] = "7";
        const CompareResult res = compareImages(t, r);
        REQUIRE(res.warnings.size() == 1);
        CHECK(res.warnings[0].find("both images were rendered with seed 7") != std::string::npos);
        r.attributes["bdptref:seed"] = "8";
        CHECK(compareImages(t, r).warnings.empty());
    }
    SECTION("count < 2 is excluded and counted") {
        ExrImage t = test;
        t.channels["count"][5] = 1.f;
        t.channels["R"][5] = 100.f;  // would be flagged if it were tested
        const CompareResult res = compareImages(t, ref);
        CHECK(res.fewSamples == 1);
        CHECK(res.tested == 63);
        CHECK(res.consistent);
    }
    SECTION("NaN or infinity is a hard failure") {
        ExrImage t = test;
        t.channels["B"][9] = std::numeric_limits<float>::quiet_NaN();
        const CompareResult res = compareImages(t, ref);
        CHECK(res.nonFinite == 1);
        CHECK_FALSE(res.consistent);
        CHECK(res.isFlagged[9] == 1);
    }
    SECTION("a test image without variances is tested against the reference mean and variance") {
        // The reference's noise alone: the test image here is the exact value.
        ExrImage exact = constantImage(8, 8, 0.5f, 0, 0, false);
        const ExrImage noisyRef = noisyImage(ref, 1e-4, 8);
        CompareResult res = compareImages(exact, noisyRef);
        CHECK(res.kind == TestKind::RefVariance);
        CHECK(res.consistent);
        for (float& v : exact.channels["R"]) v = 0.55f;  // 5 sigma in every pixel
        res = compareImages(exact, noisyRef);
        CHECK_FALSE(res.consistent);
        CHECK(res.flagged > 32);
    }
    SECTION("a difference below the precision floor is never significant") {
        ExrImage t = ref, r = ref;
        for (int c = 0; c < 3; ++c) {
            t.channels[kVar[c]].assign(64, 1e-20f);  // essentially exact values...
            r.channels[kVar[c]].assign(64, 1e-20f);
        }
        for (float& v : t.channels["R"]) v *= 1.000004f;  // ...that differ by float rounding
        CHECK(compareImages(t, r).consistent);
        for (float& v : t.channels["R"]) v *= 1.001f;  // a real 0.1% difference
        CHECK_FALSE(compareImages(t, r).consistent);
    }
}

// ===============================================================================================
// renders
// ===============================================================================================

TEST_CASE("compare: two Cornell box renders with different seeds are consistent (CLI exit 0 and library)", "[compare]") {
    const std::string dir = makeTempDir("compare-consistent");
    const std::string common = " --spp 256 --width 32 --height 32 --max-depth 5 -q --no-preview";
    REQUIRE(runCli("render " + kCornell + " -o " + dir + "/a.exr --seed 1" + common) == 0);
    REQUIRE(runCli("render " + kCornell + " -o " + dir + "/b.exr --seed 2" + common) == 0);
    int rc = -1;
    const std::string out = cli("compare " + dir + "/a.exr " + dir + "/b.exr", &rc);
    INFO(out);
    CHECK(rc == 0);
    CHECK(out.find("consistent with the reference (p = ") != std::string::npos);
    CHECK(out.find("INCONSISTENT") == std::string::npos);

    const CompareResult r = compareImages(readImage(dir + "/a.exr"), readImage(dir + "/b.exr"));
    INFO(formatCompareReport(r));
    CHECK(r.kind == TestKind::Welch);
    CHECK(r.hasVerdict);
    CHECK(r.consistent);
    CHECK(r.pGlobal >= 0.01);
    CHECK(r.tested >= 1000);  // nearly every pixel of 1024 is tested
    CHECK(r.unequal == 0);
    CHECK(r.warnings.empty());
}

TEST_CASE("compare: over 60 seed pairs no test leans towards small p-values, the bias test is uniform, and the local test finds a 2x2 error of +50%", "[compare][statistics]") {
    // Under H0 (two independent renders of the same estimator: path tracing up to depth 2 at
    // 128 spp, 16 x 16) no p-value may lean towards 0: that is the promise (false alarms <= alpha).
    // The local test's p-values are not uniform: they lean towards 1 (docs/compare.md,
    // "Calibration": "Why the local test is conservative"; over 300 pairs only 2 below 0.05), so
    // they are checked one-sided, with the tested pixels' own p-values (about 14500: independent
    // samples, tied only weakly through the neighbourhood bound), and for power on an injected
    // local error. The bias test is uniform (300 pairs: KS p = 0.61) and keeps the
    // two-sided check. The uncorrected smallest pixel p-value must fail the one-sided check: it
    // would catch a missing or wrong multiple-testing correction. About 10 s.
    const Scene& scene = cornell16();
    IntegratorSettings is;
    is.maxDepth = 2;
    const auto pt = makePathTracer(is);
    const int pairs = 60;
    NullRuns h0;
    for (uint32_t k = 0; k < uint32_t(pairs); ++k) {
        const Film a = renderWith(scene, *pt, 128, 100 + 2 * k), b = renderWith(scene, *pt, 128, 101 + 2 * k);
        h0.add(imageOf(a), imageOf(b));
    }
    INFO("global p-values: " << listOf(h0.pGlobal));
    INFO("local p-values: " << listOf(h0.pLocal));
    checkNoExcessOfSmallPValues("global", h0.pGlobal);
    checkNoExcessOfSmallPValues("local", h0.pLocal);
    checkNoExcessOfSmallPValues("pixel", h0.pPixel);
    CHECK(ksPValue(ksStatistic(h0.pBias), h0.pBias.size()) >= 0.01);
    CHECK(ksPlus(h0.pMin) > ksPlusCritical01(h0.pMin.size()));
    CHECK(ksPValue(ksStatistic(h0.pMin), h0.pMin.size()) < 0.01);
    // Not vacuous: +50% on the 2 x 2 pixels (7..8, 6..7) of the back wall is about 7.8 standard
    // deviations of t - r per pixel and channel (measured over 300 pairs; +30%: 4.7). Over 300
    // pairs the largest local p-value at +50% was 4e-5: every pair must reject it at 0.01, at that
    // block. At +30% 268 of 300 rejected (Welch's variances without the bound: 291): at least 45 of
    // 60 must (the mean 53.6 less 3.6 binomial standard deviations), so that a local test made much
    // more conservative fails here.
    INFO("injected +50%: " << h0.injectedRejected << " rejected, " << h0.injectedFoundThere
                           << " found there; +30%: " << h0.smallerInjectedRejected << " rejected, of " << pairs);
    CHECK(h0.injectedRejected == pairs);
    CHECK(h0.smallerInjectedRejected >= 45);
    CHECK(h0.injectedFoundThere == pairs);
}

TEST_CASE("compare flags a test image scaled by 1.01", "[compare]") {
    // Needed samples: the bias test sees a relative error delta as Z = delta * sum_T w_T R_T /
    // sqrt(sum_T w_T^2 V_T) over its tiles (R_T the tile's reference sum, V_T the variance of the
    // tile's difference, w_T the weight from the 3 x 3 tiles around it). sqrt(V_T) / R_T falls as
    // 1 / sqrt(spp); for direct lighting in the 32x32 Cornell box (max depth 1) a pilot render gave
    // Z ~ 5.3 for delta = 1% at 256 spp (7 with each tile weighted by its own variance, a weight
    // that biases Z for skewed estimators; docs/compare.md). Detection needs Z > 2.81
    // (p_bias < 1 - 0.99^(1/2)), and Z >= 2.81 + 3.09 = 5.9 makes a miss a 1e-3 event:
    // spp >= 256 * (5.9 / 5.3)^2 = 318. 512 spp is used, and the expected Z is checked below from
    // the images themselves.
    const Scene& scene = cornell32();
    IntegratorSettings is;
    is.maxDepth = 1;
    const auto pt = makePathTracer(is);
    const Film a = renderWith(scene, *pt, 512, 5), b = renderWith(scene, *pt, 512, 6);
    const ExrImage ref = imageOf(b), good = imageOf(a), scaled = imageOf(a, 1.01);

    // Pixels whose estimate has no noise (the emitter seen directly, the unlit ceiling at depth 1)
    // would catch the scale through the exact equality test alone: leave them out to show that the
    // statistics catch it.
    CompareOptions o;
    o.mask.assign(size_t(32 * 32), 1);
    size_t noiseless = 0;
    for (size_t i = 0; i < o.mask.size(); ++i)
        for (int c = 0; c < 3; ++c)
            if (ref.channels.at(kVar[c])[i] == 0.f && o.mask[i]) {
                o.mask[i] = 0;
                ++noiseless;
            }
    INFO("noiseless pixels masked out: " << noiseless);
    // Power check: the expected Z of the bias test for a 1% scale, from the variances, with the
    // test's weights: tile T has R_T (reference sum), V_T (variance of the difference) and m_T
    // pixels, its weight is 1 / sqrt(m_T V~) with V~ the variance per pixel of the 3 x 3 tiles
    // around it, and Z = 0.01 sum_T w_T R_T / sqrt(sum_T w_T^2 V_T).
    const int bt = biasTileSize(32, 32), nt = 32 / bt;
    for (int c = 0; c < 3; ++c) {
        std::vector<double> R(size_t(nt * nt), 0.0), V(R), M(R);
        for (int y = 0; y < 32; ++y)
            for (int x = 0; x < 32; ++x) {
                const size_t i = size_t(y) * 32 + size_t(x), t = size_t((y / bt) * nt + x / bt);
                if (!o.mask[i]) continue;
                R[t] += ref.channels.at(kRgb[c])[i];
                V[t] += ref.channels.at(kVar[c])[i] + scaled.channels.at(kVar[c])[i];
                M[t] += 1;
            }
        double num = 0, den = 0;
        for (int ty = 0; ty < nt; ++ty)
            for (int tx = 0; tx < nt; ++tx) {
                const size_t t = size_t(ty * nt + tx);
                if (!(V[t] > 0)) continue;
                double sv = 0, sm = 0;
                for (int uy = std::max(0, ty - 1); uy <= std::min(nt - 1, ty + 1); ++uy)
                    for (int ux = std::max(0, tx - 1); ux <= std::min(nt - 1, tx + 1); ++ux) {
                        sv += V[size_t(uy * nt + ux)];
                        sm += M[size_t(uy * nt + ux)];
                    }
                const double w = 1.0 / std::sqrt(sv / sm * M[t]);
                num += w * R[t];
                den += w * w * V[t];
            }
        INFO("channel " << kRgb[c] << ": expected bias-test Z for a 1% error " << 0.01 * num / std::sqrt(den));
        REQUIRE(0.01 * num / std::sqrt(den) >= 5.9);
    }

    const CompareResult control = compareImages(good, ref, o);
    INFO(formatCompareReport(control));
    CHECK(control.consistent);
    const CompareResult r = compareImages(scaled, ref, o);
    INFO(formatCompareReport(r));
    CHECK(r.hasVerdict);
    CHECK_FALSE(r.consistent);
    CHECK(r.unequal == 0);
    CHECK(r.pGlobal < 0.01);
    CHECK(r.pBias < 0.005);
    for (int c = 0; c < 3; ++c) {
        CHECK(r.biasZ[size_t(c)] > 2.81);
        // The bias it estimates is the 1% it was given, within 4 of its standard deviations.
        CHECK(std::abs(r.weightedRelativeBias[size_t(c)] - 0.01) < 4 * r.weightedRelativeBiasSigma[size_t(c)] + 0.001);
    }

    // The command line on the whole image: exit 1 (here the noiseless pixels also differ).
    const std::string dir = makeTempDir("compare-scaled");
    writeImageChannels(dir + "/ref.exr", ref);
    writeImageChannels(dir + "/good.exr", good);
    writeImageChannels(dir + "/scaled.exr", scaled);
    int rc = -1;
    std::string out = cli("compare " + dir + "/good.exr " + dir + "/ref.exr", &rc);
    INFO(out);
    CHECK(rc == 0);
    out = cli("compare " + dir + "/scaled.exr " + dir + "/ref.exr", &rc);
    INFO(out);
    CHECK(rc == 1);
    CHECK(out.find("INCONSISTENT with the reference (p = ") != std::string::npos);
}

TEST_CASE("compare flags a BDPT render with the MIS weight of one strategy doubled", "[compare]") {
    // Doubling strategy (s=1, t=3)'s MIS weight (next-event estimation at the second bounce) adds
    // its weighted contribution once more: about 3.5% of the image's mean, more in the indirectly
    // lit pixels. The edit is made on the image (its weighted layer added to R, G, B); the
    // renderer is untouched.
    const std::string dir = makeTempDir("compare-mis");
    const std::string common = " --integrator bdpt --strategies --spp 64 --width 32 --height 32 --max-depth 3 -q --no-preview";
    REQUIRE(runCli("render " + kCornell + " -o " + dir + "/t.exr --seed 3" + common) == 0);
    REQUIRE(runCli("render " + kCornell + " -o " + dir + "/r.exr --seed 4" + common) == 0);
    ExrImage wrong = readImage(dir + "/t.exr");
    for (int c = 0; c < 3; ++c) {
        const std::vector<float>& layer = wrong.channels.at(std::string("s1t3.weighted.") + kRgb[c]);
        std::vector<float>& beauty = wrong.channels.at(kRgb[c]);
        for (size_t i = 0; i < beauty.size(); ++i) beauty[i] += layer[i];
    }
    writeImageChannels(dir + "/wrong.exr", wrong);
    int rc = -1;
    std::string out = cli("compare " + dir + "/t.exr " + dir + "/r.exr", &rc);
    INFO(out);
    CHECK(rc == 0);  // control: the unedited render
    out = cli("compare " + dir + "/wrong.exr " + dir + "/r.exr", &rc);
    INFO(out);
    CHECK(rc == 1);
    CHECK(out.find("INCONSISTENT") != std::string::npos);
    // Narrowing it down: the per-strategy layers of two correct renders agree, and the layer of
    // the strategy whose weight doubled does not.
    out = cli("compare " + dir + "/t.exr " + dir + "/r.exr --layer s1t3.weighted", &rc);
    INFO(out);
    CHECK(rc == 0);
    for (int c = 0; c < 3; ++c)
        for (float& v : wrong.channels.at(std::string("s1t3.weighted.") + kRgb[c])) v *= 2.f;
    writeImageChannels(dir + "/wrong.exr", wrong);
    out = cli("compare " + dir + "/wrong.exr " + dir + "/r.exr --layer s1t3.weighted", &rc);
    INFO(out);
    CHECK(rc == 1);
}

TEST_CASE("compare flags a light tracer that drops the cosine at the light vertex", "[compare]") {
    const Scene& scene = cornell32();
    IntegratorSettings is;
    is.maxDepth = 3;
    const auto lt = makeLightTracer(is);
    const LightCosineTracer copy(3, false), wrong(3, true);
    const ExrImage ref = imageOf(renderWith(scene, *lt, 64, 21));
    const ExrImage control = imageOf(renderWith(scene, copy, 64, 22));
    const ExrImage bad = imageOf(renderWith(scene, wrong, 64, 22));

    const std::string dir = makeTempDir("compare-cosine");
    writeImageChannels(dir + "/ref.exr", ref);
    writeImageChannels(dir + "/control.exr", control);
    writeImageChannels(dir + "/bad.exr", bad);
    int rc = -1;
    std::string out = cli("compare " + dir + "/control.exr " + dir + "/ref.exr", &rc);
    INFO(out);
    CHECK(rc == 0);  // the test integrator with the cosine is a correct light tracer
    out = cli("compare " + dir + "/bad.exr " + dir + "/ref.exr --json", &rc);
    INFO(out);
    CHECK(rc == 1);
    const auto j = nlohmann::json::parse(out);
    CHECK(j["verdict"] == "inconsistent");
    CHECK(j["pixels"]["flagged"].get<int>() > 0);
}

// ===============================================================================================
// input handling, PFM, heatmap, JSON
// ===============================================================================================

TEST_CASE("compare: unusable input exits with 2 and names the problem", "[compare][errors]") {
    const std::string dir = makeTempDir("compare-bad");
    writeImageChannels(dir + "/a.exr", constantImage(8, 8, 0.5f, 1e-4f, 64));
    writeImageChannels(dir + "/small.exr", constantImage(4, 8, 0.5f, 1e-4f, 64));
    writeImageChannels(dir + "/plain.exr", constantImage(8, 8, 0.5f, 0, 0, false));
    ExrImage noRgb;
    noRgb.width = noRgb.height = 8;
    noRgb.channels["Y"].assign(64, 1.f);
    writeImageChannels(dir + "/y.exr", noRgb);
    writeImageChannels(dir + "/mask4.exr", constantImage(4, 4, 1.f, 0, 0, false));
    {
        std::ofstream f(dir + "/junk.exr");
        f << "this is not an image";
    }
    struct Case {
        std::string args, expect;
    };
    const std::string a = dir + "/a.exr";
    const Case cases[] = {
        {"compare " + dir + "/small.exr " + a, "differ in size"},
        {"compare " + dir + "/missing.exr " + a, "missing.exr"},
        {"compare " + dir + "/y.exr " + a, "no R, G, B"},
        {"compare " + dir + "/junk.exr " + a, "junk.exr"},
        {"compare " + a + " " + a + " --region 4,4,8,8", "--region"},
        {"compare " + a + " " + a + " --region 1,2,3", "--region"},
        {"compare " + a + " " + a + " --layer s1t2.weighted", "no layer 's1t2.weighted'"},
        {"compare " + a + " " + a + " --mask " + dir + "/mask4.exr", "mask"},
        {"compare " + a + " " + a + " --alpha 1.5", "--alpha"},
        {"compare " + a + " " + a + " --epsilon 0", "--epsilon"},
        {"compare " + dir + "/plain.exr " + dir + "/plain.exr", "cannot be told apart from its Monte Carlo noise"},
        {"compare " + dir + "/plain.exr " + a, "N >= 2 independent renders"},
        {"compare " + a, "reference"},
    };
    for (const Case& c : cases) {
        int rc = -1;
        const std::string out = cli(c.args, &rc);
        INFO(c.args << "\n" << out);
        CHECK(rc == 2);
        CHECK(out.find(c.expect) != std::string::npos);
        CHECK(out.find("Segmentation") == std::string::npos);
    }
}

TEST_CASE("compare --heatmap writes a PNG of the region with a legend bar and labels", "[compare]") {
    // 24 x 16 synthetic images; the test is 0.1 too bright in x 4..7, y 2..5 (7 sigma).
    const std::string dir = makeTempDir("compare-heatmap");
    const int w = 24, h = 16;
    const ExrImage truth = constantImage(w, h, 1.f, 1e-4f, 100);
    ExrImage ref = noisyImage(truth, 1e-4, 11), test = noisyImage(truth, 1e-4, 12);
    for (int y = 2; y < 6; ++y)
        for (int x = 4; x < 8; ++x)
            for (int c = 0; c < 3; ++c) test.channels[kRgb[c]][size_t(y * w + x)] += 0.1f;
    writeImageChannels(dir + "/ref.exr", ref);
    writeImageChannels(dir + "/test.exr", test);
    int rc = -1;
    const std::string out = cli("compare " + dir + "/test.exr " + dir + "/ref.exr --heatmap " + dir + "/heat.png", &rc);
    INFO(out);
    CHECK(rc == 1);
    CHECK(out.find("worst region x 4..7, y 2..5") != std::string::npos);
    REQUIRE(fs::exists(dir + "/heat.png"));

    auto in = OIIO::ImageInput::open(dir + "/heat.png");
    REQUIRE(in);
    const OIIO::ImageSpec spec = in->spec();
    std::vector<uint8_t> px(size_t(spec.width) * size_t(spec.height) * 3);
    REQUIRE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, px.data()));
    in->close();
    const HeatmapLayout L = heatmapLayout(w, h);
    CHECK(spec.width == L.width);
    CHECK(spec.height == L.height);
    CHECK(L.scale * w <= L.width);
    CHECK(L.imageHeight == h * L.scale);
    CHECK(L.height > L.imageHeight);  // the legend is below the map
    auto at = [&](int x, int y) { return &px[(size_t(y) * size_t(spec.width) + size_t(x)) * 3]; };
    // The shifted block is red (test brighter), the rest close to neutral grey.
    const uint8_t* hot = at(int((5.5) * L.scale), int(3.5 * L.scale));
    CHECK(int(hot[0]) > int(hot[2]) + 80);
    const uint8_t* calm = at(int(16.5 * L.scale), int(12.5 * L.scale));
    CHECK(std::abs(int(calm[0]) - int(calm[2])) < 120);
    // The bar runs from blue (test darker) to red (test brighter).
    const int by = (L.barY0 + L.barY1) / 2;
    const uint8_t* left = at(L.barX0, by);
    const uint8_t* right = at(L.barX1 - 1, by);
    CHECK(int(left[2]) > int(left[0]) + 80);
    CHECK(int(right[0]) > int(right[2]) + 80);
    // Labels: light text pixels below the bar, under its left end, middle and right end.
    auto textNear = [&](int cx) {
        int n = 0;
        for (int y = L.barY1 + 3; y < L.height; ++y)
            for (int x = std::max(0, cx - 16); x < std::min(L.width, cx + 16); ++x) n += at(x, y)[0] > 200 && at(x, y)[2] > 200;
        return n;
    };
    CHECK(textNear(L.barX0) > 10);
    CHECK(textNear((L.barX0 + L.barX1) / 2) > 10);
    CHECK(textNear(L.barX1) > 10);
    // No temporary file is left behind.
    for (const auto& e : fs::directory_iterator(dir)) CHECK(e.path().filename().string().find(".tmp") == std::string::npos);

    // Without variances (library only: the command refuses such a test image) the map shows the
    // relative error.
    const CompareResult plain = compareImages(constantImage(w, h, 1.05f, 0, 0, false), constantImage(w, h, 1.f, 0, 0, false));
    CHECK_FALSE(plain.hasVerdict);
    writeHeatmapPng(dir + "/rel.png", plain);
    CHECK(fs::exists(dir + "/rel.png"));
}

TEST_CASE("compare --json prints every result as parseable JSON", "[compare]") {
    const std::string dir = makeTempDir("compare-json");
    const int w = 16, h = 16;
    const ExrImage truth = constantImage(w, h, 0.5f, 4e-4f, 64);
    const ExrImage ref = noisyImage(truth, 4e-4, 21), test = noisyImage(truth, 4e-4, 22);
    writeImageChannels(dir + "/ref.exr", ref);
    writeImageChannels(dir + "/test.exr", test);
    int rc = -1;
    const std::string out = cli("compare " + dir + "/test.exr " + dir + "/ref.exr --json --region 2,3,10,12 --epsilon 0.02", &rc);
    INFO(out);
    CHECK(rc == 0);
    const auto j = nlohmann::json::parse(out);
    for (const char* key : {"test", "reference", "width", "height", "region", "method", "alpha", "epsilon", "metrics",
                            "biasCISource", "pixels", "tests", "verdict", "consistent", "exitCode", "sentence",
                            "flaggedPixels", "worstPixels", "warnings"})
        CHECK(j.contains(key));
    CHECK(j["method"] == "welch");
    CHECK(j["verdict"] == "consistent");
    CHECK(j["exitCode"] == 0);
    CHECK(j["epsilon"] == 0.02);
    CHECK(j["region"]["width"] == 10);
    CHECK(j["pixels"]["compared"] == 120);
    CHECK(j["pixels"]["tested"] == 120);
    CHECK(j["biasCISource"] == "per-pixel variances");
    for (const char* t : {"pMin", "pLocal", "biasZ", "pBias", "pGlobal", "zThreshold"}) CHECK(j["tests"].contains(t));
    CHECK(j["tests"]["pGlobal"].get<double>() >= 0.01);
    CHECK(j["tests"]["pGlobal"].get<double>() <= 1.0);
    // The metrics are those of the region, computed here independently.
    for (int c = 0; c < 3; ++c) {
        double se = 0, rel = 0, bias = 0, var = 0;
        for (int y = 3; y < 15; ++y)
            for (int x = 2; x < 12; ++x) {
                const size_t i = size_t(y * w + x);
                const double t = test.channels.at(kRgb[c])[i], r = ref.channels.at(kRgb[c])[i];
                se += (t - r) * (t - r);
                rel += (t - r) * (t - r) / (r * r + 0.02);
                bias += t - r;
                var += double(test.channels.at(kVar[c])[i]) + double(ref.channels.at(kVar[c])[i]);
            }
        const auto& m = j["metrics"][kRgb[c]];
        CHECK(m["mse"].get<double>() == Approx(se / 120));
        CHECK(m["relMse"].get<double>() == Approx(rel / 120));
        CHECK(m["bias"].get<double>() == Approx(bias / 120));
        CHECK(m["biasCI95"][1].get<double>() - m["bias"].get<double>() == Approx(1.959963985 * std::sqrt(var) / 120));
    }
    CHECK(j["metrics"]["overall"].contains("rmse"));
    CHECK(j["sentence"].get<std::string>().rfind("consistent with the reference (p = ", 0) == 0);
}
