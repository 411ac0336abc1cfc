// Production MIS in the recursive form (misWeightRecursive, fillRecursiveMis, connectionDensities;
// docs/mis.md, "The recursive form") against its two oracles: the ratio walk (misWeight) and the
// definition (misWeightsDefinition).
//
//  * On >= 100,000 (path, strategy) pairs sampled with the real generators and connectStrategy in
//    scenes with mirrors, glass, glossy metal, area/point/spot/directional/environment lights, a
//    pinhole and an orthographic camera, s = 0, s = 1, t = 1 and paths up to 64 vertices: for the
//    balance, power (beta 2, 1.5 and 3) and uniform heuristics, recursive == walk and recursive ==
//    definition, and connectStrategy's weight is the recursive one bit for bit.
//  * 256-vertex paths (sampled in a closed white box; constructed so that density products
//    overflow double): the recursive weights are finite and equal the definition.
//  * The light tree choosing s = 1's lights (MisSettings::lightSampler; docs/mis.md, "Light tree in
//    BDPT"): the same equalities on many-light scenes, a wrong s = 1 pmf caught, and the weights
//    of every strategy of a path summing to 1.
//
// Tolerances (derived, not tuned):
//  * recursive vs walk: both are double arithmetic on the SAME float32 densities (the same
//    Bsdf::pdf, pdfWe, pdfLe calls with the same directions). They differ only in the order of
//    the double operations and in converting a solid-angle density with convertDensity(p, ...)
//    versus p * convertDensity(1, ...). Each of the <= 4 operations per vertex and connection adds
//    a relative error of at most 2^-53 to a sum of positive terms (no cancellation), and
//    misPower raises a relative error e to b e (pow itself: 1 ulp). So
//    |w_rec - w_walk| <= w * max(b, 1) * (8 n + 32) * 2^-52 for an n-vertex path.
//  * recursive vs definition: the float32 budget of support/mis_tolerance.h (the derivation is in
//    tests/unit/test_mis.cpp's header; the recursion evaluates the same float32 densities as the
//    walk, so the walk's bound applies to it unchanged).
#include "bdptref/bdpt.h"
#include "bdptref/scene.h"
#include "bdptref/trace.h"
#include "render/bdpt_vertex.h"
#include "support/mis_tolerance.h"
#include "support/render_util.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <sstream>

using namespace bdptref;
using namespace bdptref::test;

namespace {

struct Heuristic {
    const char* name;
    MisSettings mis;
};

std::vector<Heuristic> heuristics(LightSamplerKind lightSampler = LightSamplerKind::Power) {
    auto make = [lightSampler](const char* name, MisHeuristic h, double beta) {
        MisSettings m;
        m.heuristic = h;
        m.beta = beta;
        m.lightSampler = lightSampler;
        return Heuristic{name, m};
    };
    return {make("balance", MisHeuristic::Balance, 2.0), make("power 2", MisHeuristic::Power, 2.0),
            make("power 1.5", MisHeuristic::Power, 1.5), make("power 3", MisHeuristic::Power, 3.0),
            make("uniform", MisHeuristic::Uniform, 2.0)};
}

std::vector<PathVertex> fullPath(const PathVertex* camera, int t, const PathVertex* light, int s, const PathVertex& sampled) {
    std::vector<PathVertex> x;
    for (int i = 0; i < t; ++i) x.push_back(t == 1 ? sampled : camera[i]);
    for (int j = s - 1; j >= 0; --j) x.push_back(s == 1 ? sampled : light[j]);
    x[size_t(t - 1)].delta = false;  // the connection evaluates the endpoints' non-delta lobes
    if (s > 0) x[size_t(t)].delta = false;
    return x;
}

double walkTolerance(size_t n, double b) { return std::max(b, 1.0) * (8.0 * double(n) + 32.0) * 0x1p-52; }

struct Tally {
    long paths = 0, s0 = 0, s1 = 0, t1 = 0, delta = 0, long64 = 0;
    long endArea = 0, endPoint = 0, endSpot = 0, endDirectional = 0, endEnvironment = 0;
    long walkFailures = 0, definitionFailures = 0, connectionFailures = 0, rangeFailures = 0;
    long treeDiffers = 0;  // tree sweeps: balance weights that the power sampler's definition does not give
    double worstWalk = 0.0, worstDefinition = 0.0;  // |difference| / tolerance
    std::ostringstream first;
    int reported = 0;
    void report(const std::string& what) {
        if (reported++ < 8) first << what << "\n";
    }
};

void countPath(const Scene& scene, const std::vector<PathVertex>& x, int s, Tally& r) {
    const int t = int(x.size()) - s;
    ++r.paths;
    r.s0 += s == 0;
    r.s1 += s == 1;
    r.t1 += t == 1;
    r.long64 += x.size() >= 64;
    bool delta = false;
    for (size_t i = 1; i + 1 < x.size(); ++i) delta = delta || x[i].delta;
    r.delta += delta;
    switch (scene.lights[size_t(x.back().light)].type) {
    case LightType::Area: ++r.endArea; break;
    case LightType::Point: ++r.endPoint; break;
    case LightType::Spot: ++r.endSpot; break;
    case LightType::Directional: ++r.endDirectional; break;
    case LightType::Environment: ++r.endEnvironment; break;
    }
}

// Every strategy connectStrategy evaluates on `samples` pixel samples, under every heuristic, with
// next-event estimation choosing its lights by `lightSampler` (docs/mis.md, "Light tree in BDPT").
void sweep(const Scene& scene, int maxDepth, int minVertices, int samples, uint32_t seed, Tally& r,
           LightSamplerKind lightSampler = LightSamplerKind::Power) {
    const std::vector<Heuristic> hs = heuristics(lightSampler);
    BdptSettings settings;
    settings.maxDepth = maxDepth;  // balance: the weight connectStrategy returns is checked bit for bit
    settings.mis.lightSampler = lightSampler;
    std::vector<PathVertex> camera(size_t(settings.maxCameraVertices())), light(size_t(settings.maxLightVertices()));
    const uint32_t width = uint32_t(scene.camera.width()), pixels = width * uint32_t(scene.camera.height());
    for (int k = 0; k < samples; ++k) {
        const uint32_t pixel = uint32_t(k) * 7919u % pixels;
        const PixelSampler sampler(seed, pixel, uint64_t(k));
        const Vec2 raster = Vec2(float(pixel % width), float(pixel / width)) + sampler.get2D(RngStream::Camera, dim::kFilm);
        const int nc = generateCameraSubpath(scene, sampler, raster, settings, camera.data());
        const int nl = generateLightSubpath(scene, sampler, settings, light.data());
        for (int t = 1; t <= nc; ++t)
            for (int s = 0; s <= lastLightStrategy(nl, t); ++s) {
                if (strategyStatus(s, t, maxDepth, false) != StrategyStatus::Evaluated || s + t < minVertices) continue;
                // The subpaths carry dVCM/dVC for the settings they were generated with (balance).
                fillRecursiveMis(scene, camera.data(), nc, settings.mis);
                fillRecursiveMis(scene, light.data(), nl, settings.mis);
                Connection c;
                PathVertex sampled;
                if (!connectStrategy(scene, light.data(), s, camera.data(), t, sampler, settings, &c, &sampled)) continue;
                const std::vector<PathVertex> x = fullPath(camera.data(), t, light.data(), s, sampled);
                countPath(scene, x, s, r);
                const ConnectionDensities d = connectionDensities(scene, light.data(), s, camera.data(), t, sampled, settings.mis);
                for (const Heuristic& h : hs) {
                    fillRecursiveMis(scene, camera.data(), nc, h.mis);
                    fillRecursiveMis(scene, light.data(), nl, h.mis);
                    const double rec = misWeightRecursive(scene, light.data(), s, camera.data(), t, sampled, d, h.mis);
                    if (h.mis.heuristic == MisHeuristic::Balance && rec != c.weight) ++r.connectionFailures;
                    const double walk = misWeight(scene, light.data(), s, camera.data(), t, sampled, h.mis);
                    const double def = misWeightsDefinition(scene, x, h.mis)[size_t(s)];
                    std::ostringstream what;
                    what.precision(12);
                    what << h.name << " s=" << s << " t=" << t << ": recursive " << rec << " walk " << walk << " definition " << def;
                    if (!(std::isfinite(rec) && rec > 0.0 && rec <= 1.0)) {
                        ++r.rangeFailures;
                        r.report("not in (0, 1]: " + what.str());
                        continue;
                    }
                    const double tolWalk = walk * walkTolerance(x.size(), h.mis.exponent());
                    const double tolDef = def * misRelativeTolerance(x, h.mis.exponent());
                    r.worstWalk = std::max(r.worstWalk, std::abs(rec - walk) / tolWalk);
                    r.worstDefinition = std::max(r.worstDefinition, std::abs(rec - def) / tolDef);
                    if (!(std::abs(rec - walk) <= tolWalk)) {
                        ++r.walkFailures;
                        r.report("recursive != walk: " + what.str());
                    }
                    if (!(std::abs(rec - def) <= tolDef)) {
                        ++r.definitionFailures;
                        r.report("recursive != definition: " + what.str());
                    }
                    // The checks' power: the definition with a wrong s = 1 pmf (the power sampler's
                    // while the tree sampled) must disagree with the tree's weights.
                    if (lightSampler != LightSamplerKind::Power && h.mis.heuristic == MisHeuristic::Balance) {
                        MisSettings wrong = h.mis;
                        wrong.lightSampler = LightSamplerKind::Power;
                        r.treeDiffers += !(std::abs(rec - misWeightsDefinition(scene, x, wrong)[size_t(s)]) <= tolDef);
                    }
                }
            }
    }
}

void requireAllEqual(const Tally& r) {
    INFO(r.first.str());
    INFO(r.paths << " paths; worst |rec - walk| / tolerance " << r.worstWalk << ", worst |rec - def| / tolerance "
                 << r.worstDefinition);
    CHECK(r.rangeFailures == 0);
    CHECK(r.walkFailures == 0);
    CHECK(r.definitionFailures == 0);
    CHECK(r.connectionFailures == 0);
    CHECK(r.worstWalk <= 1.0);  // the same as the failure counts, with the margins in the report
    CHECK(r.worstDefinition <= 1.0);
}

}  // namespace

TEST_CASE("Recursive MIS equals the ratio walk and the definition on 100k sampled paths", "[mis][recursive]") {
    Tally r;
    struct Case {
        const char* scene;
        Rgb environment;
        int maxDepth, minVertices, samples;
    };
    const Case cases[] = {
        {"scenes/mis-zoo.gltf", Rgb(0.3f, 0.35f, 0.4f), 6, 2, 16000},  // delta vertices, every light type
        {"scenes/mis-zoo.gltf", Rgb(0.3f, 0.35f, 0.4f), 16, 2, 1200},  // longer specular chains
        {"scenes/cornell-box.gltf", Rgb(0.f), 5, 2, 3000},             // mm-scale geometry, corners
        {"scenes/furnace-box.gltf", Rgb(0.f), 4, 2, 1200},             // emitters everywhere: s = 0
        {"scenes/white-box.gltf", Rgb(0.f), 62, 56, 120},              // long paths, up to 64 vertices
        {"scenes/gltf-features.gltf", Rgb(0.f), 5, 2, 3000},           // normal map, alpha, emissive texture
    };
    for (const Case& c : cases) sweep(loadTestScene(c.scene, 32, 32, c.environment), c.maxDepth, c.minVertices, c.samples, 20251124u, r);
    // Orthographic camera: t = 1 connects to a film point, x1 has the film's area density.
    sweep(loadTestSceneOrthographic("scenes/mis-zoo.gltf", 32, 32, 1.6f, Rgb(0.3f, 0.35f, 0.4f)), 6, 2, 4000, 20251125u, r);
    requireAllEqual(r);
    INFO("coverage: s=0 " << r.s0 << " s=1 " << r.s1 << " t=1 " << r.t1 << " delta " << r.delta << " area " << r.endArea << " point "
                          << r.endPoint << " spot " << r.endSpot << " directional " << r.endDirectional << " environment "
                          << r.endEnvironment << " >= 64 vertices " << r.long64);
    CHECK(r.paths >= 100000);
    CHECK(r.s0 >= 500);
    CHECK(r.s1 >= 1000);
    CHECK(r.t1 >= 1000);
    CHECK(r.delta >= 1000);
    CHECK(r.endArea >= 1000);
    CHECK(r.endPoint >= 1000);
    CHECK(r.endSpot >= 1000);
    CHECK(r.endDirectional >= 500);
    CHECK(r.endEnvironment >= 500);
    CHECK(r.long64 >= 100);
}

TEST_CASE("Recursive MIS on 256-vertex paths is finite and equals the definition", "[mis][recursive][long]") {
    const Scene scene = loadTestScene("scenes/white-box.gltf", 16, 16);
    Tally r;
    sweep(scene, 254, 256, 4, 7u, r);  // each sample: ~256 strategies x 5 heuristics x an O(n^2) definition
    requireAllEqual(r);
    CHECK(r.paths >= 1);

    // A path constructed so that its density products overflow double: a zig-zag along the edge
    // between the back wall (z = -1) and the floor (y = -1), vertices ~0.009 apart (area densities
    // ~1e3; a product of 250 of them ~1e800), ending on the light patch.
    std::vector<PathVertex> x(256);
    x[0].type = VertexType::Camera;
    x[0].p = Vec3(scene.toWorld(scene.camera.position()));
    x[0].ng = x[0].ns = scene.camera.forward();
    auto surface = [](const Vec3& p, const Vec3& n) {
        PathVertex v;
        v.type = VertexType::Surface;
        v.p = p;
        v.ng = v.ns = n;
        return v;
    };
    x[1] = surface(Vec3(0, 0, -1), Vec3(0, 0, 1));
    for (int i = 2; i < 255; ++i) {
        const float u = -0.9f + 1.8f * float(i) / 255.f;
        x[size_t(i)] = (i % 2) == 1 ? surface(Vec3(u, -0.995f, -1.f), Vec3(0, 0, 1)) : surface(Vec3(u, -1.f, -0.995f), Vec3(0, 1, 0));
    }
    int patch = -1;
    for (size_t l = 0; l < scene.lights.size(); ++l)
        if (scene.lights[l].type == LightType::Area) patch = int(l);
    REQUIRE(patch >= 0);
    const Light& L = scene.lights[size_t(patch)];
    x[255].type = VertexType::Light;
    x[255].light = patch;
    x[255].p = Vec3(scene.toWorld((L.v0 + L.v1 + L.v2) / 3.f));
    x[255].ng = x[255].ns = L.normal;
    for (PathVertex& v : x) v.p = scene.toRender(DVec3(v.p));
    for (size_t i = 1; i + 1 < x.size(); ++i) x[i].wo = glm::normalize(x[i - 1].p - x[i].p);

    const int s = 128, t = 128;
    std::vector<PathVertex> camera(x.begin(), x.begin() + t), light(x.rbegin(), x.rbegin() + s);
    for (size_t j = 1; j < light.size(); ++j) light[j].wo = glm::normalize(light[j - 1].p - light[j].p);
    camera[0].pdfFwd = 1.0;  // the endpoints' densities are set where the subpaths begin
    light[0].pdfFwd = lightOriginDensity(scene, light[0]);
    for (const Heuristic& h : heuristics()) {
        fillSubpathDensities(scene, camera.data(), t, h.mis);
        fillSubpathDensities(scene, light.data(), s, h.mis);
        double naive = 1.0;
        for (int i = 0; i < t; ++i) naive *= camera[size_t(i)].pdfFwd;
        for (int j = 0; j < s; ++j) naive *= light[size_t(j)].pdfFwd;
        CHECK(std::isinf(naive));  // the path really is one whose density products overflow
        const ConnectionDensities d = connectionDensities(scene, light.data(), s, camera.data(), t, PathVertex{}, h.mis);
        const double rec = misWeightRecursive(scene, light.data(), s, camera.data(), t, PathVertex{}, d, h.mis);
        const double def = misWeightsDefinition(scene, x, h.mis)[size_t(s)];
        INFO(h.name << ": recursive " << rec << " definition " << def);
        for (const PathVertex& v : camera) CHECK((std::isfinite(v.dVCM) && std::isfinite(v.dVC)));
        for (const PathVertex& v : light) CHECK((std::isfinite(v.dVCM) && std::isfinite(v.dVC)));
        CHECK(std::isfinite(rec));
        CHECK(def > 0.0);
        CHECK(std::abs(rec - def) <= def * misRelativeTolerance(x, h.mis.exponent()));
    }
}

// ---- The light tree in BDPT (docs/mis.md, "Light tree in BDPT") ----
// Next-event estimation (s = 1) chooses its light with the tree at the shading point; light
// subpaths start with the power sampler. The three forms must agree with the same tolerances as
// above on many-light scenes, delta and infinite lights, s = 0, s = 1, t = 1 and long paths; the
// same sweep with the definition evaluated for the power sampler must disagree (the check's power).

TEST_CASE("Recursive MIS equals the ratio walk and the definition with the light tree", "[mis][recursive][lighttree]") {
    Tally r;
    const LightSamplerKind tree = LightSamplerKind::Tree;
    const Rgb env(0.3f, 0.35f, 0.4f);
    sweep(loadTestScene("scenes/mis-zoo.gltf", 32, 32, env), 6, 2, 8000, 20251201u, r, tree);  // delta, env, every light type
    sweep(loadTestScene("scenes/mis-zoo.gltf", 32, 32, env), 16, 2, 600, 20251202u, r, tree);  // longer specular chains
    sweep(loadTestScene("scenes/many-lights/many-lights.gltf", 32, 32), 5, 2, 3000, 20251203u, r, tree);  // 600 emitters
    sweep(loadTestScene("scenes/many-lights/emissive-texture.gltf", 32, 32), 4, 2, 1500, 20251204u, r, tree);
    sweep(loadTestScene("scenes/white-box.gltf", 32, 32), 62, 56, 60, 20251205u, r, tree);  // long paths
    sweep(loadTestSceneOrthographic("scenes/mis-zoo.gltf", 32, 32, 1.6f, env), 6, 2, 2000, 20251206u, r, tree);
    requireAllEqual(r);
    INFO("coverage: s=0 " << r.s0 << " s=1 " << r.s1 << " t=1 " << r.t1 << " delta " << r.delta << " area " << r.endArea << " point "
                          << r.endPoint << " spot " << r.endSpot << " directional " << r.endDirectional << " environment "
                          << r.endEnvironment << " >= 64 vertices " << r.long64 << "; wrong pmf caught " << r.treeDiffers);
    CHECK(r.paths >= 50000);
    CHECK(r.s0 >= 500);
    CHECK(r.s1 >= 1000);
    CHECK(r.t1 >= 1000);
    CHECK(r.delta >= 500);
    CHECK(r.endArea >= 1000);
    CHECK(r.endPoint >= 500);
    CHECK(r.endSpot >= 500);
    CHECK(r.endDirectional >= 200);
    CHECK(r.endEnvironment >= 200);
    CHECK(r.long64 >= 50);
    CHECK(r.treeDiffers >= 1000);  // a wrong s = 1 pmf is seen on many paths, not a handful
}

namespace {

// The ratio walk's weights of every strategy of the full path x (camera first), on the subpaths
// recursiveMisOfScenePath builds from it (the same densities), for the strategies the definition
// finds possible.
std::vector<double> walkWeightsOfPath(const Scene& scene, const std::vector<PathVertex>& x, const MisSettings& mis,
                                      const std::vector<double>& definition) {
    const int n = int(x.size());
    std::vector<PathVertex> camera(x), light(x.rbegin(), x.rend());
    if (light[0].type == VertexType::Surface && light[0].light >= 0) light[0].type = VertexType::Light;  // an s = 0 path's end
    camera[0].pdfFwd = 1.0;
    light[0].pdfFwd = lightOriginDensity(scene, light[0]);
    fillSubpathDensities(scene, camera.data(), n, mis);
    fillSubpathDensities(scene, light.data(), n, mis);
    std::vector<double> w(size_t(n), 0.0);
    for (int s = 0; s < n; ++s) {
        if (!(definition[size_t(s)] > 0.0)) continue;
        const int t = n - s;
        PathVertex sampled = t == 1 ? camera[0] : light[0];
        if (s == 1 && t >= 2) sampled.pdfFwd = nextEventOriginDensity(scene, mis.lightSampler, camera[size_t(t - 1)], light[0]);
        w[size_t(s)] = misWeight(scene, light.data(), s, camera.data(), t, sampled, mis);
    }
    return w;
}

double sum(const std::vector<double>& v) {
    double out = 0.0;
    for (double x : v) out += x;
    return out;
}

struct SumTally {
    long paths = 0, failures = 0, s0 = 0, s1 = 0;
    std::ostringstream first;
};

// The full path of strategy (s, t) that connectStrategy produced: the sums of the recursive and
// the walk weights of all its strategies are 1, and the recursive weight of (s, t) is the one
// the renderer gave it. Tolerance: each weight carries the relative error walkTolerance(n, b) of
// the double arithmetic (header), and adding n of them at most n 2^-53 more.
void checkPathSums(const Scene& scene, const std::vector<PathVertex>& x, int s, double rendered, const Heuristic& h,
                   SumTally& r) {
    const RecursiveMisPath rec = recursiveMisOfScenePath(scene, x, h.mis);
    const std::vector<double> walk = walkWeightsOfPath(scene, x, h.mis, misWeightsDefinition(scene, x, h.mis));
    const double tolW = walkTolerance(x.size(), h.mis.exponent());
    const double tol = tolW + double(x.size()) * 0x1p-53;
    ++r.paths;
    r.s0 += s == 0;
    r.s1 += s == 1;
    const bool ok = std::abs(sum(rec.weights) - 1.0) <= tol && std::abs(sum(walk) - 1.0) <= tol &&
                    std::abs(rec.weights[size_t(s)] - rendered) <= rendered * tolW;
    if (!ok && r.failures++ < 8)
        r.first << lightSamplerName(h.mis.lightSampler) << " " << h.name << " s=" << s << " n=" << x.size() << ": sum recursive - 1 "
                << sum(rec.weights) - 1.0 << ", sum walk - 1 " << sum(walk) - 1.0 << ", weight " << rendered << " vs "
                << rec.weights[size_t(s)] << "\n";
}

// checkPathSums on every path connectStrategy produces from `samples` pixel samples.
void sumsOfSampledPaths(const Scene& scene, const Heuristic& h, int samples, SumTally& r) {
    BdptSettings settings;
    settings.maxDepth = 6;
    settings.mis = h.mis;
    std::vector<PathVertex> camera(size_t(settings.maxCameraVertices())), light(size_t(settings.maxLightVertices()));
    const uint32_t width = uint32_t(scene.camera.width()), pixels = width * uint32_t(scene.camera.height());
    for (int k = 0; k < samples; ++k) {
        const uint32_t pixel = uint32_t(k) * 7919u % pixels;
        const PixelSampler sampler(20251210u, pixel, uint64_t(k));
        const Vec2 raster = Vec2(float(pixel % width), float(pixel / width)) + sampler.get2D(RngStream::Camera, dim::kFilm);
        const int nc = generateCameraSubpath(scene, sampler, raster, settings, camera.data());
        const int nl = generateLightSubpath(scene, sampler, settings, light.data());
        for (int t = 1; t <= nc; ++t)
            for (int s = 0; s <= lastLightStrategy(nl, t); ++s) {
                if (strategyStatus(s, t, settings.maxDepth, false) != StrategyStatus::Evaluated) continue;
                Connection c;
                PathVertex sampled;
                if (!connectStrategy(scene, light.data(), s, camera.data(), t, sampler, settings, &c, &sampled)) continue;
                checkPathSums(scene, fullPath(camera.data(), t, light.data(), s, sampled), s, c.weight, h, r);
            }
    }
}

}  // namespace

// Every strategy's weight of one full path, as the renderer computes it for that strategy: the
// weights sum to 1. Both samplers: with power this also checks bdptref mis's recursive weights of
// paths that s = 0 found (their last vertex a surface on an area light; recursiveMisOfScenePath).
TEST_CASE("MIS weights with the light tree and with power sum to one over the strategies of a path",
          "[mis][recursive][lighttree]") {
    const Scene scenes[] = {loadTestScene("scenes/mis-zoo.gltf", 32, 32, Rgb(0.3f, 0.35f, 0.4f)),
                            loadTestScene("scenes/many-lights/many-lights.gltf", 32, 32)};
    SumTally r;
    for (const Scene& scene : scenes)
        for (const LightSamplerKind kind : {LightSamplerKind::Power, LightSamplerKind::Tree})
            for (const Heuristic& h : heuristics(kind)) sumsOfSampledPaths(scene, h, 600, r);
    INFO(r.first.str());
    INFO(r.paths << " paths, s=0 " << r.s0 << ", s=1 " << r.s1);
    CHECK(r.failures == 0);
    CHECK(r.paths >= 5000);
    CHECK(r.s0 >= 100);
    CHECK(r.s1 >= 500);
}
