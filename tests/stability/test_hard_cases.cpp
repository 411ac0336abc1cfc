// Numerical stability on hard cases (issue 8; the table of cases and outcomes is in
// docs/hard-cases.md). Every case is rendered by every estimator of kEstimators, and:
//  * no layer holds a NaN or Inf: beauty mean and variance, the light (splat) image, and for the
//    estimators with (s,t) layers every weighted and unweighted layer and its variance; the film
//    counted no non-finite sample or layer value (they would be zeroed, so a count > 0 means an
//    estimator produced NaN/Inf somewhere);
//  * MIS weights are finite and in [0, 1]: every weighted layer is at most its unweighted layer in
//    every pixel (both are sums of non-negative contributions c and w c);
//  * where an estimator can converge on the scene, it agrees with the reference: per pixel
//    (tests/support/image_stats.h: Welch's t per pixel at alpha = 0.01, pass when the rejected
//    pixels are within the 1 - 1e-4 binomial quantile; channels need 50 effective samples to be
//    t-tested and at least a quarter of the pixels must be, so the comparison is not vacuous) and by the image mean (k = 5 standard errors of the
//    difference, from the spread of the per-pass image means of the same runs; 5 sigma must be
//    below 10% of the mean, else the test is too weak to mean anything);
//  * a closed form, when the scene has one, is matched by the image mean at k = 5 standard errors
//    (and 5 sigma below 25% of the value: a depth cut at 64 instead of 256 is 48% off);
//  * an estimator that cannot sample any light-carrying path of the scene gives exactly 0.
// Renders use different seeds per estimator, so compared images are independent.
#include "stability/hard_case_scenes.h"
#include "support/image_stats.h"
#include "support/pass_statistics.h"

#include "bdptref/bdpt.h"
#include "bdptref/integrator.h"
#include "bdptref/renderer.h"
#include "bdptref/wavefront.h"
#include "render/bdpt_vertex.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <string>

using namespace bdptref;
using namespace bdptref::test;

namespace {

constexpr double kSigmas = 5.0;
constexpr int kMaxLayerDepth = 8;  // (s,t) layers are recorded up to this max depth
// The hard cases make heavy-tailed pixel estimates (a grazing light, a narrow spot seen by light
// tracing): with 10 effective samples the sample mean of such a pixel is still skewed low and its
// variance underestimated, and Welch's t rejects correct pairs. Per pixel, only channels with at
// least 50 effective samples in both images are t-tested (image_stats.h explains n_eff); the
// image-mean comparison covers every pixel.
constexpr double kHardCaseMinEffectiveSamples = 50.0;

struct Estimator {
    std::string name;
    bool hasStrategies = false;
    // Set for a schedule that must reproduce another estimator's film bit for bit (the wavefront
    // mode): it is rendered with that estimator's seed and compared exactly, not statistically.
    std::string bitIdenticalTo;
    std::function<void(const Scene&, const IntegratorSettings&, const RenderOptions&, Film&,
                       const std::function<void(const RenderProgress&)>&)>
        render;
};

Estimator megakernel(const std::string& name, const std::string& integrator, MisHeuristic heuristic = MisHeuristic::Balance) {
    Estimator e;
    e.name = name;
    e.hasStrategies = integrator != "path";
    e.render = [integrator, heuristic](const Scene& s, IntegratorSettings is, const RenderOptions& ro, Film& film,
                                       const std::function<void(const RenderProgress&)>& progress) {
        is.mis.heuristic = heuristic;
        renderImage(s, *makeIntegrator(integrator, is), ro, film, nullptr, progress);
    };
    return e;
}

// The GPU-style wavefront schedule (docs/wavefront.md) of a megakernel estimator: the same image
// bit for bit, so one render per case compared exactly with the megakernel's is the whole check.
Estimator wavefront(const std::string& name, const std::string& integrator, const std::string& sameAs) {
    Estimator e;
    e.name = name;
    e.hasStrategies = integrator != "path";
    e.bitIdenticalTo = sameAs;
    e.render = [integrator](const Scene& s, const IntegratorSettings& is, RenderOptions ro, Film& film,
                            const std::function<void(const RenderProgress&)>& progress) {
        WavefrontScheduler scheduler(integrator, is, WavefrontOptions{});
        ro.scheduler = &scheduler;
        renderImage(s, *makeIntegrator(integrator, is), ro, film, nullptr, progress);
    };
    return e;
}

// Every estimator of the product; a new rendering mode is one more line here.
const std::vector<Estimator>& estimators() {
    static const std::vector<Estimator> list = {
        megakernel("path", "path"),
        megakernel("lt", "lt"),
        megakernel("bdpt-balance", "bdpt", MisHeuristic::Balance),
        megakernel("bdpt-power", "bdpt", MisHeuristic::Power),
        wavefront("bdpt-balance-wavefront", "bdpt", "bdpt-balance"),
    };
    return list;
}

const Estimator& estimatorNamed(const std::string& name) {
    const auto e = std::find_if(estimators().begin(), estimators().end(), [&](const Estimator& x) { return x.name == name; });
    REQUIRE(e != estimators().end());
    return *e;
}

struct Rendered {
    Film film;
    PassImageMean imageMean;
};

Rendered renderWith(const Estimator& e, const Scene& scene, int maxDepth, int spp, uint32_t seed) {
    IntegratorSettings is;
    is.maxDepth = maxDepth;
    is.recordStrategies = e.hasStrategies && maxDepth <= kMaxLayerDepth;
    RenderOptions ro;
    ro.spp = spp;
    ro.seed = seed;
    ro.tileSize = 8;
    Rendered r{Film(scene.camera.width(), scene.camera.height()), {}};
    if (is.recordStrategies) r.film.enableStrategies(maxDepth);
    e.render(scene, is, ro, r.film, [&](const RenderProgress&) { r.imageMean.afterPass(r.film); });
    REQUIRE(r.imageMean.passes() == ro.spp);
    return r;
}

// Counts the pixels where two films differ at all: sums, sums of squares, counts, the light image
// and every (s,t) layer (0 = bit-identical).
int differingPixels(const Film& a, const Film& b) {
    int differ = 0;
    const StrategyLayers &La = a.strategies(), &Lb = b.strategies();
    for (int y = 0; y < a.height(); ++y)
        for (int x = 0; x < a.width(); ++x) {
            bool d = a.sum(x, y) != b.sum(x, y) || a.sumSquares(x, y) != b.sumSquares(x, y) || a.count(x, y) != b.count(x, y) ||
                     a.lightSum(x, y) != b.lightSum(x, y) || La.enabled() != Lb.enabled();
            if (La.enabled() && Lb.enabled())
                for (int dep = 0; dep <= La.maxDepth(); ++dep)
                    for (int s = 0; s <= dep + 1; ++s)
                        for (bool w : {true, false})
                            d = d || La.mean(s, dep + 2 - s, w, x, y) != Lb.mean(s, dep + 2 - s, w, x, y) ||
                                La.varianceOfMean(s, dep + 2 - s, w, x, y) != Lb.varianceOfMean(s, dep + 2 - s, w, x, y);
            differ += d;
        }
    return differ;
}

bool finite(const DVec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

void checkFiniteLayers(const Film& f) {
    CHECK(f.nonFiniteSamples() == 0);
    const StrategyLayers& L = f.strategies();
    CHECK(L.nonFiniteValues() == 0);
    int bad = 0, weightAboveOne = 0;
    for (int y = 0; y < f.height(); ++y)
        for (int x = 0; x < f.width(); ++x) {
            bad += !finite(f.mean(x, y)) + !finite(f.varianceOfMean(x, y)) + !finite(f.lightMean(x, y));
            if (!L.enabled()) continue;
            for (int d = 0; d <= L.maxDepth(); ++d)
                for (int s = 0; s <= d + 1; ++s) {
                    const int t = d + 2 - s;
                    for (bool w : {true, false})
                        bad += !finite(L.mean(s, t, w, x, y)) + !finite(L.varianceOfMean(s, t, w, x, y));
                    const DVec3 mw = L.mean(s, t, true, x, y), mu = L.mean(s, t, false, x, y);
                    for (int c = 0; c < 3; ++c)
                        weightAboveOne += mw[c] < 0.0 || mw[c] > mu[c] * (1.0 + 1e-5) + 1e-30;
                }
        }
    CHECK(bad == 0);
    CHECK(weightAboveOne == 0);
}

void checkImageMeansAgree(const std::string& label, const PassImageMean& a, const PassImageMean& ref) {
    for (int c = 0; c < 3; ++c) {
        const double diff = a.mean()[c] - ref.mean()[c];
        const double se = std::sqrt(a.standardError()[c] * a.standardError()[c] + ref.standardError()[c] * ref.standardError()[c]);
        INFO(label << " channel " << c << ": image mean " << a.mean()[c] << " vs reference " << ref.mean()[c] << ", difference "
                   << diff << " = " << diff / se << " sigma");
        CHECK(std::abs(diff) <= kSigmas * se);
        CHECK(kSigmas * se <= 0.10 * ref.mean()[c]);  // not vacuous
    }
}

void checkAgreement(const std::string& label, const Rendered& r, const Rendered& ref, const std::string& refName) {
    const ImageComparison cmp =
        compareImages(momentsOf(r.film), momentsOf(ref.film), kPixelAlpha, label, refName + " (reference)", kHardCaseMinEffectiveSamples);
    INFO(label << " against " << refName << "\n" << cmp.report);
    CHECK(cmp.passed());
    CHECK(cmp.tested * 4 >= cmp.pixels);
    checkImageMeansAgree(label, r.imageMean, ref.imageMean);
}

void runHardCase(const std::string& name) {
    const std::vector<HardCase> all = hardCases();
    const auto it = std::find_if(all.begin(), all.end(), [&](const HardCase& c) { return c.name == name; });
    REQUIRE(it != all.end());
    const HardCase& hc = *it;
    const Scene scene = hc.build(hc.size, hc.size);
    std::map<std::string, Rendered> renders;
    std::map<std::string, uint32_t> seeds;
    uint32_t seed = 1000;
    for (const Estimator& e : estimators()) {
        INFO("case '" << hc.name << "', estimator " << e.name);
        seed += 17;
        seeds[e.name] = seed;
        if (!e.bitIdenticalTo.empty()) {
            REQUIRE(renders.count(e.bitIdenticalTo) == 1);
            const Rendered r = renderWith(e, scene, hc.maxDepth, hc.spp, seeds.at(e.bitIdenticalTo));
            CHECK(differingPixels(r.film, renders.at(e.bitIdenticalTo).film) == 0);
            continue;
        }
        Rendered r = renderWith(e, scene, hc.maxDepth, hc.spp, seed);
        checkFiniteLayers(r.film);
        if (std::count(hc.exactlyBlack.begin(), hc.exactlyBlack.end(), e.name)) {
            int nonzero = 0;
            for (int y = 0; y < hc.size; ++y)
                for (int x = 0; x < hc.size; ++x) nonzero += r.film.sum(x, y) != DVec3(0.0);
            CHECK(nonzero == 0);
        }
        if (hc.analyticPixel) {
            const double expected = *hc.analyticPixel;
            for (int c = 0; c < 3; ++c) {
                const double m = r.imageMean.mean()[c], se = r.imageMean.standardError()[c];
                INFO("image mean " << m << " +- " << se << ", expected " << expected);
                CHECK(std::abs(m - expected) <= kSigmas * se);
                // Not vacuous: a depth cut at 64 instead of 256 would give 48% less.
                CHECK(kSigmas * se <= 0.25 * expected);
            }
        }
        renders.emplace(e.name, std::move(r));
    }
    INFO("case '" << hc.name << "'");
    if (!hc.converging.empty()) {
        const Rendered* ref = nullptr;
        Rendered separate;
        if (hc.referenceBuild || hc.referenceSpp > 0) {
            const Scene refScene = hc.referenceBuild ? hc.referenceBuild(hc.size, hc.size) : hc.build(hc.size, hc.size);
            separate = renderWith(estimatorNamed(hc.reference), refScene, hc.maxDepth, hc.referenceSpp > 0 ? hc.referenceSpp : hc.spp, 7);
            checkFiniteLayers(separate.film);
            ref = &separate;
        } else {
            REQUIRE(renders.count(hc.reference) == 1);
            ref = &renders.at(hc.reference);
        }
        for (const std::string& n : hc.converging)
            if (renders.count(n)) checkAgreement(n, renders.at(n), *ref, hc.reference);  // else not in this build's list
    }
    // Direct lighting only (max depth 1): fresh renders of the estimator and the reference, both
    // at the reference's sample count (direct lighting is cheap; the emitter's pixel-coverage noise
    // sets the image mean's error).
    if (!hc.convergingDirectLighting.empty()) {
        const int spp = hc.referenceSpp > 0 ? hc.referenceSpp : hc.spp;
        const Rendered ref = renderWith(estimatorNamed(hc.reference), scene, 1, spp, 8);
        for (const std::string& n : hc.convergingDirectLighting) {
            const Rendered r = renderWith(estimatorNamed(n), scene, 1, spp, seeds.at(n) + 1);
            checkFiniteLayers(r.film);
            checkAgreement(n + " (direct lighting)", r, ref, hc.reference + " (direct lighting)");
        }
    }
}

}  // namespace

// [!mayfail]: open findings (docs/hard-cases.md, "Open findings"): the assertions run and report,
// but do not fail the suite until the cause is fixed.
TEST_CASE("Hard case: grazing view and light", "[stability]") { runHardCase("grazing view and light"); }
TEST_CASE("Hard case: tiny bright area light", "[stability]") { runHardCase("tiny bright area light"); }
TEST_CASE("Hard case: GGX roughness 1e-4 next to a delta mirror", "[stability]") {
    runHardCase("GGX roughness 1e-4 next to a delta mirror");
}
TEST_CASE("Hard case: coincident and touching geometry", "[stability]") { runHardCase("coincident and touching geometry"); }
TEST_CASE("Hard case: scene translated by 1e5", "[stability]") { runHardCase("scene translated by 1e5"); }
TEST_CASE("Hard case: closed box of albedo 0.99 at max depth 256", "[stability]") {
    runHardCase("closed box of albedo 0.99 at max depth 256");
}
TEST_CASE("Hard case: point light seen only through a glass sphere", "[stability]") {
    runHardCase("point light seen only through a glass sphere");
}
TEST_CASE("Hard case: narrow spot light", "[stability]") { runHardCase("narrow spot light"); }
TEST_CASE("Hard case: directional light", "[stability]") { runHardCase("directional light"); }
TEST_CASE("Hard case: back-facing emitters", "[stability]") { runHardCase("back-facing emitters"); }
TEST_CASE("Hard case: degenerate and zero-area triangles among the lights", "[stability]") {
    runHardCase("degenerate and zero-area triangles among the lights");
}

TEST_CASE("Hard case: grazing sun on rough glass", "[stability][!mayfail]") { runHardCase("grazing sun on rough glass"); }
TEST_CASE("Hard case: near-delta rough glass roughness 1e-3", "[stability]") {
    runHardCase("near-delta rough glass roughness 1e-3");
}

TEST_CASE("Hard case: sheen under clearcoat on coincident and touching geometry", "[stability][nan-safe]") {
    runHardCase(kLayeredCoincidentCase);
}

// Exactly coincident path vertices on layered (sheen under clearcoat) surfaces, built from sampled
// subpaths of the layered case's scene (a render produces them only by chance, where surfaces
// coincide and the ray offset is small). Per pixel sample:
//  * a light subpath whose surface vertex is placed on the camera subpath's first surface vertex
//    (the connection between them has length 0), and
//  * the camera subpath with that vertex repeated (a re-hit at distance 0).
// Their densities and recursive MIS quantities must be finite; every connection of length 0 must
// contribute nothing (the exact value: such paths have measure zero, docs/mis.md); every other
// strategy must be finite with a weight in [0, 1], the same from the megakernel's connectStrategy
// and the wavefront's evaluateConnection / traceShadowRay / finishConnection; the test oracles
// (ratio walk, definition) must give finite weights in [0, 1]. Before the fix the NaN direction
// between the two vertices indexed the sheen albedo table at int(NaN) and crashed.
TEST_CASE("Hard case: exactly coincident path vertices on layered surfaces", "[stability][nan-safe]") {
    const std::vector<HardCase> all = hardCases();
    const auto hc = std::find_if(all.begin(), all.end(), [](const HardCase& c) { return c.name == kLayeredCoincidentCase; });
    REQUIRE(hc != all.end());
    const int size = 8;
    const Scene scene = hc->build(size, size);
    BdptSettings settings;
    settings.maxDepth = 5;
    auto finiteVertex = [](const PathVertex& v) {
        return std::isfinite(v.pdfFwd) && std::isfinite(v.pdfRev) && std::isfinite(v.dVCM) && std::isfinite(v.dVC);
    };
    auto weightOk = [](double w) { return std::isfinite(w) && w >= 0.0 && w <= 1.0 + 1e-9; };
    int samples = 0, coincident = 0, contributing = 0, badVertices = 0, badStrategies = 0, modeMismatch = 0, badOracle = 0;
    for (uint32_t i = 0; i < uint32_t(size * size); ++i) {
        const PixelSampler sampler(29, i, 0);
        std::vector<PathVertex> cam(size_t(settings.maxCameraVertices())), light(size_t(settings.maxLightVertices()));
        const Vec2 raster(float(i % size) + 0.5f, float(i / size) + 0.5f);
        const int nc = generateCameraSubpath(scene, sampler, raster, settings, cam.data());
        const int nl = generateLightSubpath(scene, sampler, settings, light.data());
        if (nc < 2 || nl < 1 || cam[1].type != VertexType::Surface) continue;
        ++samples;
        std::vector<PathVertex> lp = {light[0], cam[1]};
        lp[1].wo = directionTo(lp[1], lp[0]);
        lp[1].beta = light[0].beta;
        lp[1].delta = false;
        fillSubpathDensities(scene, lp.data(), int(lp.size()), settings.mis);
        std::vector<PathVertex> cp(cam.begin(), cam.begin() + nc);
        cp.insert(cp.begin() + 2, cp[1]);
        cp[2].wo = nc >= 3 ? cam[2].wo : cam[1].wo;  // arrived along the ray that left cam[1]
        cp[1].delta = false;
        fillSubpathDensities(scene, cp.data(), int(cp.size()), settings.mis);
        for (const PathVertex& v : lp) badVertices += !finiteVertex(v);
        for (const PathVertex& v : cp) badVertices += !finiteVertex(v);

        for (int t = 1; t <= int(cp.size()); ++t)
            for (int s = 0; s <= lastLightStrategy(int(lp.size()), t); ++s) {
                if (strategyStatus(s, t, settings.maxDepth, false) != StrategyStatus::Evaluated) continue;
                Connection mk;
                const bool okMk = connectStrategy(scene, lp.data(), s, cp.data(), t, sampler, settings, &mk);
                PendingConnection pending;
                bool okWf = evaluateConnection(scene, lp.data(), s, cp.data(), t, sampler, &pending, settings.mis.lightSampler);
                if (okWf && pending.needsShadowRay) okWf = traceShadowRay(scene, pending.shadow);
                Connection wf;
                if (okWf) finishConnection(scene, lp.data(), s, cp.data(), t, pending, settings, &wf);
                modeMismatch += okMk != okWf || (okMk && (mk.unweighted != wf.unweighted || mk.weight != wf.weight));
                const bool zeroLength = s >= 2 && t >= 2 && lp[size_t(s - 1)].p == cp[size_t(t - 1)].p;
                if (zeroLength) {
                    ++coincident;
                    CHECK_FALSE(okMk);
                    continue;
                }
                if (!okMk) continue;
                ++contributing;
                badStrategies += !isFinite(mk.unweighted) || !weightOk(mk.weight);
                // The oracles on the full path (camera vertices first).
                std::vector<PathVertex> x(cp.begin(), cp.begin() + t);
                for (int k = s - 1; k >= 0; --k) x.push_back(lp[size_t(k)]);
                if (s == 1 || t == 1) {  // the fresh endpoint of the strategy
                    PathVertex sampled;
                    connectStrategy(scene, lp.data(), s, cp.data(), t, sampler, settings, &mk, &sampled);
                    if (s == 1) x.back() = sampled;
                    else x.front() = sampled;
                    badOracle += !weightOk(misWeight(scene, lp.data(), s, cp.data(), t, sampled, settings.mis));
                } else {
                    badOracle += !weightOk(misWeight(scene, lp.data(), s, cp.data(), t, PathVertex{}, settings.mis));
                }
                for (double w : misWeightsDefinition(scene, x, settings.mis)) badOracle += !weightOk(w);
            }
    }
    INFO(samples << " samples, " << coincident << " connections of length 0, " << contributing << " contributing");
    CHECK(samples >= size * size / 2);
    CHECK(coincident >= samples);  // (s, t) = (2, 2) and (2, 3) at least once per sample
    CHECK(contributing > 0);
    CHECK(badVertices == 0);
    CHECK(badStrategies == 0);
    CHECK(modeMismatch == 0);
    CHECK(badOracle == 0);
}

TEST_CASE("Hard cases: zero-area triangles never become lights", "[stability]") {
    for (const HardCase& hc : hardCases()) {
        if (hc.name != "degenerate and zero-area triangles among the lights") continue;
        const Scene s = hc.build(hc.size, hc.size);
        // The two ceiling-light triangles and the sliver; the three zero-area ones are skipped.
        CHECK(s.lights.size() == 3);
        for (const Light& l : s.lights) {
            CHECK(l.area > 0.f);
            CHECK(std::isfinite(l.power));
        }
    }
}
