// MIS weights (docs/contracts.md, contract 3, docs/mis.md): the definition implementation
// (misWeightsDefinition, every strategy's density built from the vertices) against the production
// ratio walk (misWeight, and Connection::weight from connectStrategy).
//
//  * On >= 100,000 full paths drawn from shipped scenes with the real subpath generators and
//    connectStrategy: the definition's weights of all strategies sum to 1 (1e-9) for the balance,
//    power (beta 2) and uniform heuristics, and the production weight of the strategy that made
//    the path equals the definition's weight for that strategy within the float32 error bound
//    below. The paths cover delta reflection and refraction, glossy and diffuse vertices, area,
//    point, spot, directional and environment lights, s = 0, s = 1, t = 1, and up to 64 vertices.
//    Run twice: with the subpaths' densities re-evaluated from the vertex positions (the ratio walk
//    itself) and with the densities stored by the generators.
//  * A 256-vertex path (sampled in a closed box of albedo 0.999, and one constructed so that its
//    density products overflow double) has finite weights summing to 1 and a finite contribution.
//  * Paths whose weights are worked out on paper (docs/mis.md, "Worked examples").
//
// Tolerance of the production/definition comparison (derived, not tuned): positions, directions
// and every density routine (Bsdf::pdf, Camera::pdfWe, pdfLe, pdfLi) are float32, and the two
// implementations evaluate them with differently rounded directions (float vs double
// normalisation). A density factor for an edge (a, b) then carries a relative error of at most
// 2^-24 (32 + 4/|cos_a| + 4/|cos_b|): a few ulps for the evaluation (the GGX lobe of roughness
// >= 0.35 amplifies a direction ulp by at most ~16), and 2 ulps of a direction component changing
// a cosine by 2^-23 absolutely at each end. A weight w_s = 1 / sum_j (p_j/p_s)^b has relative error
// at most b * max_j |d log(p_j/p_s)|, and each edge enters p_j/p_s at most twice (forward and
// reverse density), so |w_prod - w_def| <= w_def * max(b, 1) * sum_edges 2 * eps_edge.
#include "bdptref/bdpt.h"
#include "bdptref/bsdf.h"
#include "bdptref/scene.h"
#include "render/bdpt_vertex.h"
#include "support/render_util.h"

#include "support/mis_tolerance.h"

#include <catch2/catch.hpp>

#include <array>
#include <chrono>
#include <cmath>
#include <sstream>

using namespace bdptref;
using namespace bdptref::test;

namespace {

constexpr double kSumTolerance = 1e-9;
const MisHeuristic kHeuristics[3] = {MisHeuristic::Balance, MisHeuristic::Power, MisHeuristic::Uniform};
const char* const kHeuristicNames[3] = {"balance", "power", "uniform"};

MisSettings misSettings(MisHeuristic h) {
    MisSettings m;
    m.heuristic = h;
    m.beta = 2.0;
    return m;
}

// The full path of strategy (s, t), camera first: camera[0..t-1] then light[s-1..0], with the
// fresh endpoint of s == 1 (light sample) or t == 1 (camera). The connection endpoints x_{t-1} and
// x_t are evaluated through their non-delta lobes by the connection, so in the full path they are
// not delta vertices whatever their subpath did next (docs/mis.md, "Delta vertices").
std::vector<PathVertex> fullPath(const PathVertex* camera, int t, const PathVertex* light, int s, const PathVertex& sampled) {
    std::vector<PathVertex> x;
    x.reserve(size_t(s + t));
    for (int i = 0; i < t; ++i) x.push_back(t == 1 ? sampled : camera[i]);
    for (int j = s - 1; j >= 0; --j) x.push_back(s == 1 ? sampled : light[j]);
    x[size_t(t - 1)].delta = false;
    if (s > 0) x[size_t(t)].delta = false;
    return x;
}


// Replaces the densities stored in a subpath while it was sampled by the same densities evaluated
// from its vertex positions (render/bdpt_vertex.h); delta-sampled densities stay 0.
void densitiesFromPositions(const Scene& scene, PathVertex* path, int n, bool lightPath) {
    for (int i = 0; i < n; ++i) {
        PathVertex& v = path[i];
        if (i == 0)
            v.pdfFwd = lightPath ? lightOriginDensity(scene, v) : 1.0;
        else if (i == 1 && lightPath)
            v.pdfFwd = pdfLightToVertex(scene, path[0], v);
        else if (path[i - 1].delta)
            v.pdfFwd = 0.0;
        else
            v.pdfFwd = vertexPdf(scene, path[i - 1], i >= 2 ? &path[i - 2] : nullptr, v);
        if (i + 2 < n) v.pdfRev = path[i + 1].delta ? 0.0 : vertexPdf(scene, path[i + 1], &path[i + 2], v);
    }
    fillRecursiveMis(scene, path, n, MisSettings{});  // the recursive quantities of these densities (balance)
}

struct Coverage {
    long paths = 0, specular = 0, reflection = 0, refraction = 0, glossy = 0, s0 = 0, s1 = 0, t1 = 0, long64 = 0;
    long endArea = 0, endPoint = 0, endSpot = 0, endDirectional = 0, endEnvironment = 0;
    size_t maxVertices = 0;
};

struct Comparison {
    long sumFailures = 0, rangeFailures = 0, weightFailures = 0, connectionFailures = 0, invalidButUsed = 0;
    double worstSumError = 0.0, worstRatio = 0.0;  // ratio: |w_prod - w_def| / tolerance
    std::ostringstream firstFailures;
    int reported = 0;
    void report(const std::string& what) {
        if (reported++ < 8) firstFailures << what << "\n";
    }
};

std::string describe(const std::vector<PathVertex>& x, int s, const std::vector<double>& w, double prod, const char* h) {
    std::ostringstream o;
    o.precision(10);
    o << h << " s=" << s << " t=" << int(x.size()) - s << " n=" << x.size() << " production " << prod << " definition "
      << w[size_t(s)] << "; vertices:";
    for (const PathVertex& v : x)
        o << " [" << (v.type == VertexType::Camera ? "C" : v.type == VertexType::Light ? "L" : "S") << (v.delta ? " delta" : "")
          << (v.infinite ? " inf" : "") << " light " << v.light << " mat " << v.material << "]";
    o << "; definition weights:";
    for (double d : w) o << " " << d;
    return o.str();
}

void account(const Scene& scene, const std::vector<PathVertex>& x, int s, Coverage& cov) {
    const int n = int(x.size()), t = n - s;
    ++cov.paths;
    cov.maxVertices = std::max(cov.maxVertices, x.size());
    if (n >= 64) ++cov.long64;
    if (s == 0) ++cov.s0;
    if (s == 1) ++cov.s1;
    if (t == 1) ++cov.t1;
    bool specular = false, reflection = false, refraction = false, glossy = false;
    for (int i = 1; i + 1 < n; ++i) {
        const PathVertex& v = x[size_t(i)];
        const Material& m = scene.materials[v.material];
        if (v.delta) {
            specular = true;
            const DVec3 a = glm::normalize(DVec3(x[size_t(i - 1)].p) - DVec3(v.p));
            const DVec3 b = x[size_t(i + 1)].infinite ? DVec3(x[size_t(i + 1)].ng) : glm::normalize(DVec3(x[size_t(i + 1)].p) - DVec3(v.p));
            (glm::dot(a, DVec3(v.ng)) * glm::dot(b, DVec3(v.ng)) < 0.0 ? refraction : reflection) = true;
        } else if (m.roughness > 0.f && m.metallic > 0.f) {
            glossy = true;
        }
    }
    cov.specular += specular;
    cov.reflection += reflection;
    cov.refraction += refraction;
    cov.glossy += glossy;
    switch (scene.lights[size_t(x.back().light)].type) {
    case LightType::Area: ++cov.endArea; break;
    case LightType::Point: ++cov.endPoint; break;
    case LightType::Spot: ++cov.endSpot; break;
    case LightType::Directional: ++cov.endDirectional; break;
    case LightType::Environment: ++cov.endEnvironment; break;
    }
}

// Compares the definition with the production walk on every connection of `samples` pixel samples.
// storedDensities = false: the subpaths' pdfFwd/pdfRev are re-evaluated from the vertex positions
// before connecting (so the comparison tests the ratio walk itself); true: as sampled.
void sweep(const Scene& scene, int maxDepth, int minVertices, int samples, uint32_t seed, bool storedDensities, Coverage& cov,
           Comparison& cmp) {
    BdptSettings settings;
    settings.maxDepth = maxDepth;
    settings.mis = misSettings(MisHeuristic::Balance);
    std::vector<PathVertex> camera(size_t(settings.maxCameraVertices())), light(size_t(settings.maxLightVertices()));
    const uint32_t width = uint32_t(scene.camera.width()), pixels = width * uint32_t(scene.camera.height());
    for (int k = 0; k < samples; ++k) {
        const uint32_t pixel = uint32_t(k) * 7919u % pixels;
        const PixelSampler sampler(seed, pixel, uint64_t(k));
        const Vec2 raster = Vec2(float(pixel % width), float(pixel / width)) + sampler.get2D(RngStream::Camera, dim::kFilm);
        const int nc = generateCameraSubpath(scene, sampler, raster, settings, camera.data());
        const int nl = generateLightSubpath(scene, sampler, settings, light.data());
        if (!storedDensities) {
            densitiesFromPositions(scene, camera.data(), nc, false);
            densitiesFromPositions(scene, light.data(), nl, true);
        }
        for (int t = 1; t <= nc; ++t)
            for (int s = 0; s <= nl; ++s) {
                const int depth = s + t - 2;
                if (depth < 0 || depth > maxDepth || (s == 1 && t == 1)) continue;  // as the BDPT integrator
                if (s + t < minVertices) continue;
                Connection c;
                PathVertex sampled;
                if (!connectStrategy(scene, light.data(), s, camera.data(), t, sampler, settings, &c, &sampled)) continue;
                const std::vector<PathVertex> x = fullPath(camera.data(), t, light.data(), s, sampled);
                account(scene, x, s, cov);
                for (int h = 0; h < 3; ++h) {
                    const MisSettings mis = misSettings(kHeuristics[h]);
                    const std::vector<double> w = misWeightsDefinition(scene, x, mis);
                    double sum = 0.0;
                    bool inRange = w.size() == x.size();
                    for (double v : w) {
                        sum += v;
                        inRange = inRange && std::isfinite(v) && v >= 0.0 && v <= 1.0;
                    }
                    const double prod = misWeight(scene, light.data(), s, camera.data(), t, sampled, mis);
                    if (!inRange) {
                        ++cmp.rangeFailures;
                        cmp.report("weights not finite in [0,1]: " + describe(x, s, w, prod, kHeuristicNames[h]));
                        continue;
                    }
                    cmp.worstSumError = std::max(cmp.worstSumError, std::abs(sum - 1.0));
                    if (!(std::abs(sum - 1.0) <= kSumTolerance)) {
                        ++cmp.sumFailures;
                        cmp.report("weights do not sum to 1: " + describe(x, s, w, prod, kHeuristicNames[h]));
                    }
                    if (!(w[size_t(s)] > 0.0)) {
                        ++cmp.invalidButUsed;
                        cmp.report("strategy used but invalid by the definition: " + describe(x, s, w, prod, kHeuristicNames[h]));
                        continue;
                    }
                    const double tol = w[size_t(s)] * test::misRelativeTolerance(x, mis.exponent());
                    const double err = std::abs(prod - w[size_t(s)]);
                    cmp.worstRatio = std::max(cmp.worstRatio, err / tol);
                    if (!(err <= tol)) {
                        ++cmp.weightFailures;
                        cmp.report("production != definition (tolerance " + std::to_string(tol) + "): " +
                                   describe(x, s, w, prod, kHeuristicNames[h]));
                    }
                    // connectStrategy's weight is the recursive form (tests/unit/test_mis_recursive.cpp
                    // compares it with this walk and the definition).
                    if (h == 0 && c.weight != misWeightRecursive(scene, light.data(), s, camera.data(), t, sampled,
                                                                 connectionDensities(scene, light.data(), s, camera.data(), t, sampled, mis),
                                                                 mis))
                        ++cmp.connectionFailures;
                }
            }
    }
}

struct SweepCase {
    const char* scene;
    Rgb environment;
    int maxDepth, minVertices, samples;
};

const SweepCase kSweeps[] = {
    {"scenes/mis-zoo.gltf", Rgb(0.3f, 0.35f, 0.4f), 6, 2, 20000},  // delta vertices, every light type
    {"scenes/mis-zoo.gltf", Rgb(0.3f, 0.35f, 0.4f), 16, 2, 1500},  // longer specular chains
    {"scenes/cornell-box.gltf", Rgb(0.f), 5, 2, 4000},             // mm-scale geometry, corners
    {"scenes/furnace-box.gltf", Rgb(0.f), 4, 2, 1500},             // emitters everywhere: s = 0
    {"scenes/white-box.gltf", Rgb(0.f), 62, 56, 160},              // long paths, up to 64 vertices
    {"scenes/gltf-features.gltf", Rgb(0.f), 5, 2, 4000},           // normal map, alpha, emissive texture
};

std::string runSweeps(bool storedDensities, Coverage& cov, Comparison& cmp) {
    std::ostringstream log;
    for (const SweepCase& c : kSweeps) {
        const auto start = std::chrono::steady_clock::now();
        const long before = cov.paths;
        const Scene scene = loadTestScene(c.scene, 32, 32, c.environment);
        sweep(scene, c.maxDepth, c.minVertices, c.samples, 20250401u, storedDensities, cov, cmp);
        log << c.scene << " max depth " << c.maxDepth << ": " << cov.paths - before << " paths, "
            << std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() << " s\n";
    }
    return log.str();
}

// ----- hand-built scenes for the worked examples

// A 4x4 Lambertian floor (albedo 0.5) at z = 0 facing +z, optional extra triangles, camera looking
// down from (0, 0, 1) with a 90 degree field of view (image-plane area A = 4 at distance 1).
struct HandScene {
    Scene scene;
    HandScene() {
        Material floor;
        floor.name = "floor";
        floor.baseColor = Rgb(0.5f);
        floor.metallic = 0.f;
        floor.roughness = 1.f;
        floor.specular = 0.f;
        scene.materials.push_back(floor);
        quad({Vec3(-2, -2, 0), Vec3(2, -2, 0), Vec3(2, 2, 0), Vec3(-2, 2, 0)}, 0);
        scene.camera = Camera::lookAt(Vec3(0, 0, 1), Vec3(0, 0, 0), Vec3(0, 1, 0), 0.5f * kPi, 8, 8);
    }
    void triangle(const Vec3& a, const Vec3& b, const Vec3& c, uint32_t material) {
        const Vec3 n = glm::normalize(glm::cross(b - a, c - a));
        const uint32_t base = uint32_t(scene.mesh.positions.size());
        for (const Vec3& p : {a, b, c}) {
            scene.mesh.positions.push_back(p);
            scene.mesh.normals.push_back(n);
            scene.mesh.vertexHasNormal.push_back(1);
        }
        scene.mesh.indices.push_back(glm::uvec3(base, base + 1, base + 2));
        scene.mesh.triangleMaterial.push_back(material);
    }
    void quad(const std::array<Vec3, 4>& p, uint32_t material) {
        triangle(p[0], p[1], p[2], material);
        triangle(p[0], p[2], p[3], material);
    }
    uint32_t addMaterial(const Material& m) {
        scene.materials.push_back(m);
        return uint32_t(scene.materials.size() - 1);
    }
};

// The hand-made vertices below are in world coordinates (as on paper); toRenderSpace moves a path
// into the scene's camera-centred render space (Scene::worldOrigin) before it is evaluated.
PathVertex cameraVertex(const Scene& scene) {
    PathVertex v;
    v.type = VertexType::Camera;
    v.p = Vec3(scene.toWorld(scene.camera.position()));
    v.ng = v.ns = scene.camera.forward();
    v.pdfFwd = 1.0;
    return v;
}

PathVertex surfaceVertex(const Vec3& p, const Vec3& n, uint32_t material, bool delta = false) {
    PathVertex v;
    v.type = VertexType::Surface;
    v.p = p;
    v.ng = v.ns = n;
    v.material = material;
    v.delta = delta;
    return v;
}

PathVertex lightVertex(int light, const Vec3& p, const Vec3& n, bool infinite = false) {
    PathVertex v;
    v.type = VertexType::Light;
    v.light = light;
    v.p = p;
    v.ng = v.ns = n;
    v.infinite = infinite;
    return v;
}

std::vector<PathVertex> toRenderSpace(const Scene& scene, std::vector<PathVertex> worldPath) {
    for (PathVertex& v : worldPath) v.p = scene.toRender(DVec3(v.p));
    return worldPath;
}

// Expected weights p_s^b / sum p_j^b from densities worked out on paper (0 = invalid strategy).
std::vector<double> expectedWeights(const std::vector<double>& p, double b) {
    std::vector<double> w(p.size(), 0.0);
    double sum = 0.0;
    for (size_t i = 0; i < p.size(); ++i)
        if (p[i] > 0.0) sum += b == 0.0 ? 1.0 : std::pow(p[i], b);
    for (size_t i = 0; i < p.size(); ++i)
        if (p[i] > 0.0) w[i] = (b == 0.0 ? 1.0 : std::pow(p[i], b)) / sum;
    return w;
}

void checkWorkedExample(const Scene& scene, const std::vector<PathVertex>& x, const std::vector<double>& p, double tolerance) {
    for (int h = 0; h < 3; ++h) {
        const MisSettings mis = misSettings(kHeuristics[h]);
        const std::vector<double> expected = expectedWeights(p, mis.exponent());
        const std::vector<double> w = misWeightsDefinition(scene, x, mis);
        REQUIRE(w.size() == expected.size());
        for (size_t s = 0; s < w.size(); ++s) {
            INFO(kHeuristicNames[h] << " s = " << s);
            CHECK(w[s] == Approx(expected[s]).epsilon(tolerance).margin(1e-15));
        }
    }
}

}  // namespace

TEST_CASE("MIS: definition weights sum to 1 and the production ratio walk reproduces them on 100k sampled paths",
          "[mis]") {
    // The subpaths' densities are re-evaluated from their vertex positions, so this tests the
    // ratio walk (remap0, delta vertices, delta and infinite lights, exponents) against the
    // definition; the test case below uses the densities stored while sampling.
    const auto start = std::chrono::steady_clock::now();
    Coverage cov;
    Comparison cmp;
    const std::string perScene = runSweeps(false, cov, cmp);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    INFO(cmp.firstFailures.str());
    INFO(perScene << "paths " << cov.paths << " in " << seconds << " s; worst |sum - 1| " << cmp.worstSumError
                  << "; worst |w_prod - w_def| / tolerance " << cmp.worstRatio);
    CHECK(cmp.rangeFailures == 0);
    CHECK(cmp.sumFailures == 0);
    CHECK(cmp.invalidButUsed == 0);
    CHECK(cmp.weightFailures == 0);
    CHECK(cmp.connectionFailures == 0);

    // The paths exercise what they must (not vacuous).
    INFO("coverage: specular " << cov.specular << " (reflection " << cov.reflection << ", refraction " << cov.refraction
                               << "), glossy " << cov.glossy << ", s=0 " << cov.s0 << ", s=1 " << cov.s1 << ", t=1 " << cov.t1
                               << ", ends on area " << cov.endArea << " point " << cov.endPoint << " spot " << cov.endSpot
                               << " directional " << cov.endDirectional << " environment " << cov.endEnvironment << ", >= 64 vertices "
                               << cov.long64 << ", longest " << cov.maxVertices);
    CHECK(cov.paths >= 100000);
    CHECK(cov.reflection >= 1000);
    CHECK(cov.refraction >= 1000);
    CHECK(cov.glossy >= 1000);
    CHECK(cov.s0 >= 500);
    CHECK(cov.s1 >= 1000);
    CHECK(cov.t1 >= 1000);
    CHECK(cov.endArea >= 1000);
    CHECK(cov.endPoint >= 1000);
    CHECK(cov.endSpot >= 1000);
    CHECK(cov.endDirectional >= 500);
    CHECK(cov.endEnvironment >= 500);
    CHECK(cov.long64 >= 500);
    CHECK(cov.maxVertices == 64);
}

TEST_CASE("MIS: production weights of sampled subpaths (densities stored while sampling) equal the definition", "[mis]") {
    // The same paths with the pdfFwd/pdfRev the generators stored. They must be the densities of
    // the directions between the stored vertices (docs/mis.md, "Densities are functions of the
    // vertex positions"): densities of the sampled directions, which leave from offset ray origins,
    // differ from those the connections recompute, and the weights of a path's strategies then
    // no longer sum to 1.
    Coverage cov;
    Comparison cmp;
    runSweeps(true, cov, cmp);
    INFO(cmp.firstFailures.str());
    INFO("paths " << cov.paths << "; worst |w_prod - w_def| / tolerance " << cmp.worstRatio);
    CHECK(cmp.rangeFailures == 0);
    CHECK(cmp.sumFailures == 0);
    CHECK(cmp.invalidButUsed == 0);
    CHECK(cmp.weightFailures == 0);
    CHECK(cmp.connectionFailures == 0);
}

TEST_CASE("MIS: weights sum to 1 and production equals definition on paths through an orthographic camera", "[mis][camera]") {
    // t = 1 connects to the film point a vertex projects onto, and the camera samples x1 with
    // area density |cos| / A (docs/camera.md, "Orthographic cameras"): both implementations must
    // agree on those densities, with the stored and with the re-evaluated subpath densities.
    for (bool stored : {false, true}) {
        Coverage cov;
        Comparison cmp;
        const Scene zoo = loadTestSceneOrthographic("scenes/mis-zoo.gltf", 32, 32, 1.6f, Rgb(0.3f, 0.35f, 0.4f));
        sweep(zoo, 6, 2, 8000, 20250402u, stored, cov, cmp);
        const Scene cornell = loadTestSceneOrthographic("scenes/cornell-box.gltf", 32, 32, 290.f);
        sweep(cornell, 5, 2, 3000, 20250403u, stored, cov, cmp);
        INFO(cmp.firstFailures.str());
        INFO("stored densities " << stored << ": paths " << cov.paths << ", t=1 " << cov.t1 << ", s=0 " << cov.s0
                                 << "; worst |sum - 1| " << cmp.worstSumError << "; worst ratio " << cmp.worstRatio);
        CHECK(cmp.rangeFailures == 0);
        CHECK(cmp.sumFailures == 0);
        CHECK(cmp.invalidButUsed == 0);
        CHECK(cmp.weightFailures == 0);
        CHECK(cmp.connectionFailures == 0);
        CHECK(cov.paths >= 10000);
        CHECK(cov.t1 >= 1000);
        CHECK(cov.s0 >= 100);
    }
}

TEST_CASE("MIS: 256-vertex paths give finite weights that sum to 1 and a finite contribution", "[mis][long]") {
    const Scene scene = loadTestScene("scenes/white-box.gltf", 16, 16);
    BdptSettings settings;
    settings.maxDepth = 254;  // 256 vertices
    std::vector<PathVertex> camera(size_t(settings.maxCameraVertices())), light(size_t(settings.maxLightVertices()));

    SECTION("sampled") {
        // Find pixel samples whose subpaths connect into a 256-vertex path (Russian roulette keeps a
        // subpath alive with probability 0.999 per bounce in this box).
        int found = 0;
        for (uint64_t k = 0; k < 200 && found < 3; ++k) {
            const PixelSampler sampler(7u, uint32_t(k % 256u), k);
            const Vec2 raster = Vec2(float(k % 16u), float((k / 16u) % 16u)) + sampler.get2D(RngStream::Camera, dim::kFilm);
            const int nc = generateCameraSubpath(scene, sampler, raster, settings, camera.data());
            const int nl = generateLightSubpath(scene, sampler, settings, light.data());
            for (int t = nc; t >= 1 && found < 3; --t) {
                const int s = 256 - t;
                if (s < 0 || s > nl || (s == 1 && t == 1)) continue;
                for (int h = 0; h < 3; ++h) {
                    settings.mis = misSettings(kHeuristics[h]);
                    fillRecursiveMis(scene, camera.data(), nc, settings.mis);  // for connectStrategy's weight
                    fillRecursiveMis(scene, light.data(), nl, settings.mis);
                    Connection c;
                    PathVertex sampled;
                    if (!connectStrategy(scene, light.data(), s, camera.data(), t, sampler, settings, &c, &sampled)) break;
                    const std::vector<PathVertex> x = fullPath(camera.data(), t, light.data(), s, sampled);
                    REQUIRE(x.size() == 256);
                    const std::vector<double> w = misWeightsDefinition(scene, x, settings.mis);
                    double sum = 0.0;
                    for (double v : w) {
                        REQUIRE(std::isfinite(v));
                        sum += v;
                    }
                    INFO(kHeuristicNames[h] << " s = " << s << " t = " << t);
                    CHECK(sum == Approx(1.0).margin(kSumTolerance));
                    CHECK(w[size_t(s)] > 0.0);
                    CHECK(std::isfinite(c.weight));
                    CHECK(c.weight > 0.0);
                    CHECK(c.weight <= 1.0);
                    const Rgb contribution = c.unweighted * float(c.weight);
                    CHECK(isFinite(contribution));
                    if (h == 2) ++found;
                }
            }
        }
        CHECK(found >= 1);
    }

    SECTION("constructed so that the density products overflow double") {
        // x1 in the middle of the back wall, then a zig-zag along the edge between the back wall
        // (z = -1) and the floor (y = -1): vertices alternate between the two faces, ~0.009 apart,
        // so every area density is ~1e3 and a product of 250 of them (~1e800) is far outside
        // double's range. The last vertex is on the light patch.
        std::vector<PathVertex> x;
        x.push_back(cameraVertex(scene));
        x.push_back(surfaceVertex(Vec3(0, 0, -1), Vec3(0, 0, 1), 0));
        for (int i = 2; i < 255; ++i) {
            const float u = -0.9f + 1.8f * float(i) / 255.f;
            const bool onWall = (i % 2) == 1;
            x.push_back(onWall ? surfaceVertex(Vec3(u, -0.995f, -1.f), Vec3(0, 0, 1), 0)
                               : surfaceVertex(Vec3(u, -1.f, -0.995f), Vec3(0, 1, 0), 0));
        }
        int patchLight = -1;
        for (size_t l = 0; l < scene.lights.size(); ++l)
            if (scene.lights[l].type == LightType::Area) patchLight = int(l);
        REQUIRE(patchLight >= 0);
        const Light& L = scene.lights[size_t(patchLight)];
        x.push_back(lightVertex(patchLight, Vec3(scene.toWorld((L.v0 + L.v1 + L.v2) / 3.f)), L.normal));
        REQUIRE(x.size() == 256);
        x = toRenderSpace(scene, x);

        // The naive product of the camera subpath's densities overflows.
        double naive = 1.0;
        for (size_t i = 1; i < x.size(); ++i) naive *= vertexPdf(scene, x[i - 1], i >= 2 ? &x[i - 2] : nullptr, x[i]);
        CHECK(std::isinf(naive));

        // Subpaths for strategy (s, t) = (128, 128), densities from the positions, for the walk.
        const int s = 128, t = 128;
        for (int i = 0; i < t; ++i) camera[size_t(i)] = x[size_t(i)];
        for (int j = 0; j < s; ++j) light[size_t(j)] = x[x.size() - 1 - size_t(j)];
        densitiesFromPositions(scene, camera.data(), t, false);
        densitiesFromPositions(scene, light.data(), s, true);
        for (int h = 0; h < 3; ++h) {
            const MisSettings mis = misSettings(kHeuristics[h]);
            const std::vector<double> w = misWeightsDefinition(scene, x, mis);
            double sum = 0.0;
            int valid = 0;
            for (double v : w) {
                REQUIRE(std::isfinite(v));
                sum += v;
                valid += v > 0.0;
            }
            INFO(kHeuristicNames[h]);
            CHECK(sum == Approx(1.0).margin(kSumTolerance));
            CHECK(valid == 256);  // no delta vertex, an area light: every strategy can sample it
            const double prod = misWeight(scene, light.data(), s, camera.data(), t, PathVertex{}, mis);
            CHECK(std::isfinite(prod));
            CHECK(std::abs(prod - w[size_t(s)]) <= w[size_t(s)] * test::misRelativeTolerance(x, mis.exponent()));
        }
    }
}

TEST_CASE("MIS: worked examples (docs/mis.md)", "[mis]") {
    const double pi = double(kPi);

    SECTION("camera, Lambertian floor, area light: three strategies") {
        HandScene hs;
        Material lamp;
        lamp.baseColor = Rgb(0.f);
        lamp.metallic = 0.f;
        lamp.specular = 0.f;
        lamp.emission = Rgb(1.f);
        // Triangle of area 3/4 in the plane z = 1 facing -z, centroid (1, 0, 1).
        hs.triangle(Vec3(0.5f, -0.5f, 1), Vec3(1, 1, 1), Vec3(1.5f, -0.5f, 1), hs.addMaterial(lamp));
        hs.scene.finalize();
        const Scene& scene = hs.scene;
        REQUIRE(scene.lights.size() == 1);
        REQUIRE(scene.lights[0].area == Approx(0.75f));
        const std::vector<PathVertex> x = toRenderSpace(scene, {cameraVertex(scene), surfaceVertex(Vec3(0, 0, 0), Vec3(0, 0, 1), 0),
                                                                lightVertex(0, Vec3(1, 0, 1), Vec3(0, 0, -1))});
        // x0 -> x1: straight down the axis: pdfWe = 1/(A cos^3) = 1/4, |cos1| / d^2 = 1   -> 1/4.
        // x1 -> x2: d^2 = 2, cos at x1 = cos at x2 = 1/sqrt2.
        //   camera side x2: (cos1/pi) * cos2 / d^2 = 1/(4 pi);  light choice: pmf = 1, 1/area = 4/3;
        //   light side x1 (emission cos/pi): (cos2/pi) * cos1 / d^2 = 1/(4 pi).
        const double p0 = 1.0 / 4.0 * (1.0 / (4.0 * pi));  // (s,t) = (0,3): x1 and x2 by the camera
        const double p1 = 1.0 / 4.0 * (4.0 / 3.0);          // (1,2): x1 by the camera, x2 by NEE
        const double p2 = (4.0 / 3.0) * (1.0 / (4.0 * pi));  // (2,1): x2 and x1 by the light
        checkWorkedExample(scene, x, {p0, p1, p2}, 1e-6);
        // Balance: 1/(16 pi), 1/3, 1/(3 pi) normalised (docs/mis.md, "Worked examples").
        const double sum = p0 + p1 + p2;
        const std::vector<double> w = misWeightsDefinition(scene, x, misSettings(MisHeuristic::Balance));
        CHECK(w[0] == Approx(0.0433116).epsilon(1e-5));
        CHECK(w[1] == Approx(0.7256931).epsilon(1e-5));
        CHECK(w[2] == Approx(0.2309953).epsilon(1e-5));
        CHECK(w[1] == Approx(p1 / sum).epsilon(1e-6));
        const std::vector<double> wp = misWeightsDefinition(scene, x, misSettings(MisHeuristic::Power));
        CHECK(wp[0] == Approx(0.0032239).epsilon(1e-4));
        CHECK(wp[1] == Approx(0.9050730).epsilon(1e-6));
        CHECK(wp[2] == Approx(0.0917031).epsilon(1e-5));

        // The production walk for (s, t) = (1, 2), from hand-made subpaths: the camera subpath
        // (x0, x1) with x1's forward density 1/4, and the light sample x2 (pdfFwd = pmf / area).
        std::vector<PathVertex> cam = {x[0], x[1]};
        cam[1].pdfFwd = 0.25;
        PathVertex sampled = x[2];
        sampled.pdfFwd = 4.0 / 3.0;
        for (int h = 0; h < 3; ++h) {
            const MisSettings mis = misSettings(kHeuristics[h]);
            INFO(kHeuristicNames[h]);
            CHECK(misWeight(scene, nullptr, 1, cam.data(), 2, sampled, mis) == Approx(expectedWeights({p0, p1, p2}, mis.exponent())[1]).epsilon(1e-6));
        }
    }

    SECTION("emitters seen directly: depth 0 is strategy (0, 2) alone") {
        HandScene hs;
        Material lamp;
        lamp.emission = Rgb(1.f);
        lamp.specular = 0.f;
        lamp.metallic = 0.f;
        hs.triangle(Vec3(-0.5f, -0.5f, 0.5f), Vec3(0.5f, -0.5f, 0.5f), Vec3(0, 0.5f, 0.5f), hs.addMaterial(lamp));  // faces +z
        Light point;
        point.type = LightType::Point;
        point.position = Vec3(0.1f, 0.1f, 0.5f);
        point.emission = Rgb(1.f);
        hs.scene.lights.push_back(point);
        hs.scene.finalize();
        const Scene& scene = hs.scene;
        const int area = 0, pointIndex = 1;
        REQUIRE(scene.lights[size_t(pointIndex)].type == LightType::Point);
        checkWorkedExample(scene, toRenderSpace(scene, {cameraVertex(scene), lightVertex(area, Vec3(0, 0, 0.5f), Vec3(0, 0, 1))}), {1.0, 0.0}, 1e-12);
        // A point light cannot be hit and (1, 1) is not a BDPT strategy: no strategy renders it.
        checkWorkedExample(scene, toRenderSpace(scene, {cameraVertex(scene), lightVertex(pointIndex, point.position, Vec3(0.f))}), {0.0, 0.0}, 1e-12);
    }

    SECTION("mirror then diffuse then point light: only next-event estimation can sample it") {
        HandScene hs;
        Material mirror;
        mirror.baseColor = Rgb(0.9f);
        mirror.metallic = 1.f;
        mirror.roughness = 0.f;
        const uint32_t mirrorMat = hs.addMaterial(mirror);
        Light point;
        point.type = LightType::Point;
        point.position = Vec3(0, 0, 2);
        point.emission = Rgb(1.f);
        hs.scene.lights.push_back(point);
        hs.scene.camera = Camera::lookAt(Vec3(-1, 0, 1), Vec3(0, 0, 0), Vec3(0, 0, 1), 0.5f * kPi, 8, 8);
        hs.scene.finalize();
        const Scene& scene = hs.scene;
        // x1: the mirror at the origin (normal +z) reflects the camera ray (1,0,-1)/sqrt2 to (1,0,1)/sqrt2,
        // which reaches the diffuse wall point x2 = (1, 0, 1) facing -x; x3: the point light.
        const std::vector<PathVertex> x = toRenderSpace(scene, {cameraVertex(scene), surfaceVertex(Vec3(0, 0, 0), Vec3(0, 0, 1), mirrorMat, true),
                                                                surfaceVertex(Vec3(1, 0, 1), Vec3(-1, 0, 0), 0), lightVertex(0, point.position, Vec3(0.f))});
        // s = 0: a point light cannot be hit; s = 2 connects x1 (delta) to x2; s = 3 connects the
        // pinhole to x1 (delta). Only s = 1 remains: weight 1 under every heuristic.
        checkWorkedExample(scene, x, {0.0, 1.0, 0.0, 0.0}, 1e-12);
    }

    SECTION("directional light: next-event estimation and light tracing") {
        HandScene hs;
        Light sun;
        sun.type = LightType::Directional;
        sun.direction = Vec3(0, 0, -1);
        sun.emission = Rgb(1.f);
        hs.scene.lights.push_back(sun);
        hs.scene.finalize();
        const Scene& scene = hs.scene;
        // The scene is the floor alone: bounding sphere radius R = 2 sqrt2, disk density 1/(pi R^2) = 1/(8 pi).
        REQUIRE(double(scene.boundingRadius()) == Approx(2.0 * std::sqrt(2.0)).epsilon(1e-6));
        const std::vector<PathVertex> x = toRenderSpace(scene, {cameraVertex(scene), surfaceVertex(Vec3(0, 0, 0), Vec3(0, 0, 1), 0),
                                                                lightVertex(0, Vec3(0, 0, 10), Vec3(0, 0, 1), true)});
        // s = 0: the direction is a delta, it cannot be hit. s = 1: x1 by the camera (1/4) and the
        // light's direction by NEE (pmf 1, a delta: factor 1). s = 2: the direction by emission
        // (pmf, factor 1) and x1 from the disk: 1/(8 pi) * |cos1| = 1/(8 pi).
        checkWorkedExample(scene, x, {0.0, 0.25, 1.0 / (8.0 * pi)}, 1e-6);
        const std::vector<double> w = misWeightsDefinition(scene, x, misSettings(MisHeuristic::Balance));
        CHECK(w[1] == Approx(2.0 * pi / (2.0 * pi + 1.0)).epsilon(1e-6));
    }

    SECTION("environment: solid-angle measure at the infinite vertex") {
        HandScene hs;
        hs.scene.setEnvironment(Rgb(1.f));
        hs.scene.finalize();
        const Scene& scene = hs.scene;
        REQUIRE(scene.environmentLight() == 0);
        const std::vector<PathVertex> x = toRenderSpace(scene, {cameraVertex(scene), surfaceVertex(Vec3(0, 0, 0), Vec3(0, 0, 1), 0),
                                                                lightVertex(0, Vec3(0, 0, 10), Vec3(0, 0, 1), true)});
        // s = 0: x1 (1/4), then the direction straight up by the Lambertian lobe, cos/pi = 1/pi
        //        (solid angle: no distance, no cosine at infinity).
        // s = 1: x1 (1/4), the direction by NEE: pmf * 1/(4 pi).
        // s = 2: the direction by emission 1/(4 pi), x1 from the disk 1/(8 pi) * cos1.
        checkWorkedExample(scene, x, {0.25 / pi, 0.25 / (4.0 * pi), 1.0 / (4.0 * pi) / (8.0 * pi)}, 1e-6);
    }
}
