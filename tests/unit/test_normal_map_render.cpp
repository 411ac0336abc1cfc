// Normal maps through every estimator (docs/materials.md, "Normal maps"): on a small scene with a
// normal-mapped Lambert floor and a normal-mapped glossy metal wall lit by an area light,
//  * PT, LT, BDPT-balance and BDPT-power agree per pixel (Welch's t-test per pixel, alpha 0.01,
//    binomial bound at 1 - 1e-4: tests/support/image_stats.h), and each comparison detects a
//    uniform 10% error in either image (power check);
//  * the MIS weights of >= 1e4 sampled full paths sum to 1 (1e-9) for the balance, power and
//    uniform heuristics, and the production weight equals the definition (the float32 bound of
//    tests/support/mis_tolerance.h);
//  * the wavefront mode renders the same films as the megakernel, bit for bit.
#include "support/gltf_builder.h"
#include "support/image_stats.h"
#include "support/mis_tolerance.h"
#include "support/render_util.h"

#include "bdptref/bdpt.h"
#include "bdptref/gltf_loader.h"
#include "bdptref/integrator.h"
#include "bdptref/renderer.h"
#include "bdptref/wavefront.h"
#include "render/bdpt_vertex.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <sstream>

using namespace bdptref;
using namespace bdptref::test;

namespace {

// A quad p0..p3 (counter-clockwise from its front) with flat normals and uv (0,1) (1,1) (1,0)
// (0,0) at its corners, on a root node.
void mappedQuad(Doc& d, const std::array<float, 12>& p, int mat) {
    const Vec3 a(p[0], p[1], p[2]), b(p[3], p[4], p[5]), c(p[6], p[7], p[8]);
    const Vec3 n = glm::normalize(glm::cross(b - a, c - a));
    const int pos = d.floats(std::vector<float>(p.begin(), p.end()), "VEC3");
    const int nrm = d.floats({n.x, n.y, n.z, n.x, n.y, n.z, n.x, n.y, n.z, n.x, n.y, n.z}, "VEC3");
    const int uv = d.floats({0, 1, 1, 1, 1, 0, 0, 0}, "VEC2");
    const int idx = d.indices(std::vector<uint16_t>{0, 1, 2, 0, 2, 3});
    d.node({{"mesh", d.mesh(Doc::prim(pos, idx, nrm, uv, 4, mat))}});
}

// Floor z = 0 (normal-mapped Lambert), back wall y = 1 (normal-mapped GGX metal, roughness 0.4),
// a 0.6 x 0.6 area light at z = 1.6 facing down.
Scene normalMapScene(int size) {
    Doc d;
    // A 4x4 normal map of varied tilts (bilinear): every texel differs. The scales (0.4 floor, 0.3
    // wall: tilts up to ~20 degrees) keep light tracing's variance finite enough for a per-pixel
    // t-test: at scale 1 / 0.8 (tilts up to ~60 degrees) LT's estimates in a few wall pixels were
    // 3-4 standard errors low at 1024 spp and still 1.5-4 at 16384 spp, converging upwards (a
    // heavy tail: the adjoint factor |wo.ns| / |wo.ng| is unbounded for light arriving grazing to
    // ng; docs/materials.md, "Normal maps"), while PT and BDPT agreed (1 rejected pixel of 234).
    std::vector<uint16_t> texels;
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) texels.insert(texels.end(), {uint16_t(40 + 50 * i), uint16_t(220 - 45 * j), uint16_t(200 + 10 * ((i + j) % 4))});
    d.j["images"] = json::array({json{{"uri", "data:image/png;base64," + base64(makePng(4, 4, 3, 8, texels))}}});
    d.j["textures"] = json::array({json{{"source", 0}}});
    const int floor = d.lambert({0.6, 0.6, 0.6});
    d.j["materials"][size_t(floor)]["normalTexture"] = {{"index", 0}, {"scale", 0.4}};
    const int wall = d.metal({0.9, 0.7, 0.5}, 0.4);
    d.j["materials"][size_t(wall)]["normalTexture"] = {{"index", 0}, {"scale", 0.3}};
    const int light = d.lambert({0, 0, 0}, {1, 1, 1}, 8.0);
    mappedQuad(d, {-2, -1, 0, 2, -1, 0, 2, 1, 0, -2, 1, 0}, floor);
    mappedQuad(d, {-2, 1, 0, 2, 1, 0, 2, 1, 1.6f, -2, 1, 1.6f}, wall);
    d.quad({-0.3, -0.3, 1.6}, {-0.3, 0.3, 1.6}, {0.3, 0.3, 1.6}, {0.3, -0.3, 1.6}, light);
    // Rotated 60 degrees about x: looking along (0, sin 60, -cos 60), i.e. 30 degrees down, at
    // (0, 0.2, 0.4) from 2.6 away; every pixel sees the floor or the wall, none the light.
    d.j["cameras"] = json::array({json{{"type", "perspective"}, {"perspective", {{"yfov", 0.75}, {"znear", 0.01}}}}});
    d.node({{"camera", 0}, {"translation", {0, -2.0517, 1.7}}, {"rotation", {0.5, 0, 0, 0.8660254037844386}}});
    LoadOptions o;
    o.width = o.height = size;
    Scene s = loadGltfScene(d.write("normal-map-scene.gltf"), o);
    s.finalize();
    return s;
}

struct Setup {
    std::string integrator = "bdpt";
    MisHeuristic heuristic = MisHeuristic::Balance;
    int spp = 2, maxDepth = 5, threads = 2;
    uint32_t seed = 7;
    bool strategies = false;
};

Film render(const Scene& scene, const Setup& s, GpuReport* wavefrontReport = nullptr) {
    IntegratorSettings is;
    is.maxDepth = s.maxDepth;
    is.mis.heuristic = s.heuristic;
    is.recordStrategies = s.strategies;
    const auto integrator = makeIntegrator(s.integrator, is);
    RenderOptions ro;
    ro.spp = s.spp;
    ro.seed = s.seed;
    ro.threads = s.threads;
    std::unique_ptr<WavefrontScheduler> wavefront;
    if (wavefrontReport) {
        wavefront = std::make_unique<WavefrontScheduler>(s.integrator, is, WavefrontOptions{});
        ro.scheduler = wavefront.get();
    }
    Film film(scene.camera.width(), scene.camera.height());
    if (s.strategies) film.enableStrategies(s.maxDepth);
    renderImage(scene, *integrator, ro, film);
    if (wavefrontReport) *wavefrontReport = wavefront->report();
    return film;
}

MomentImage scaled(MomentImage img, double factor) {
    for (PixelMoments& p : img.pixels) {
        p.mean *= factor;
        p.varianceOfMean *= factor * factor;
    }
    return img;
}

// The normal maps must matter in this scene: the share of visible surface hits whose shading
// normal differs from the interpolated (here: geometric) one.
double perturbedFraction(const Scene& scene) {
    int hits = 0, perturbed = 0;
    for (int y = 0; y < scene.camera.height(); ++y)
        for (int x = 0; x < scene.camera.width(); ++x) {
            const Ray ray = scene.camera.generateRay(Vec2(float(x) + 0.5f, float(y) + 0.5f));
            SurfaceHit h;
            if (!scene.intersect(ray, &h)) continue;
            ++hits;
            perturbed += glm::dot(h.ns, h.ng) < 0.999f;
        }
    return hits ? double(perturbed) / hits : 0.0;
}

}  // namespace

TEST_CASE("Normal maps: PT LT BDPT-balance and BDPT-power agree per pixel", "[normalmap][agreement]") {
    const Scene scene = normalMapScene(16);
    CHECK(perturbedFraction(scene) > 0.9);
    const std::pair<const char*, MisHeuristic> estimators[] = {
        {"path", MisHeuristic::Balance}, {"lt", MisHeuristic::Balance}, {"bdpt", MisHeuristic::Balance}, {"bdpt", MisHeuristic::Power}};
    const int spp[] = {1024, 1024, 512, 512};
    std::vector<std::pair<std::string, MomentImage>> images;
    for (int i = 0; i < 4; ++i) {
        Setup s;
        s.integrator = estimators[i].first;
        s.heuristic = estimators[i].second;
        s.spp = spp[i];
        s.seed = 100u + uint32_t(i);  // different seeds: independent estimates per pixel
        s.threads = 0;
        const Film f = render(scene, s);
        CHECK(f.nonFiniteSamples() == 0);
        images.emplace_back(std::string(s.integrator) + (i == 3 ? "-power" : ""), momentsOf(f));
    }
    constexpr double kDetectableBias = 0.10;
    for (size_t i = 0; i < images.size(); ++i)
        for (size_t j = i + 1; j < images.size(); ++j) {
            const auto& [na, a] = images[i];
            const auto& [nb, b] = images[j];
            const ImageComparison c = compareImages(a, b, kPixelAlpha, na, nb);
            INFO(c.report);
            CHECK(c.passed());
            CHECK(c.tested >= c.pixels * 9 / 10);
            const ImageComparison up = compareImages(scaled(a, 1.0 + kDetectableBias), b, kPixelAlpha, na + " (scaled)", nb);
            const ImageComparison down = compareImages(a, scaled(b, 1.0 + kDetectableBias), kPixelAlpha, na, nb + " (scaled)");
            CHECK_FALSE(up.passed());
            CHECK_FALSE(down.passed());
        }
}

TEST_CASE("Normal maps: MIS weights of sampled paths sum to 1 and equal the definition", "[normalmap][mis]") {
    const Scene scene = normalMapScene(16);
    BdptSettings settings;
    settings.maxDepth = 5;
    std::vector<PathVertex> camera(size_t(settings.maxCameraVertices())), light(size_t(settings.maxLightVertices()));
    const uint32_t width = uint32_t(scene.camera.width()), pixels = width * uint32_t(scene.camera.height());
    const MisHeuristic heuristics[3] = {MisHeuristic::Balance, MisHeuristic::Power, MisHeuristic::Uniform};
    long paths = 0, perturbedPaths = 0, sumFailures = 0, weightFailures = 0, invalid = 0;
    double worstSum = 0.0, worstRatio = 0.0;
    std::ostringstream first;
    for (int k = 0; k < 6000; ++k) {
        const uint32_t pixel = uint32_t(k) * 7919u % pixels;
        const PixelSampler sampler(4242u, pixel, uint64_t(k));
        const Vec2 raster = Vec2(float(pixel % width), float(pixel / width)) + sampler.get2D(RngStream::Camera, dim::kFilm);
        const int nc = generateCameraSubpath(scene, sampler, raster, settings, camera.data());
        const int nl = generateLightSubpath(scene, sampler, settings, light.data());
        for (int t = 1; t <= nc; ++t)
            for (int s = 0; s <= nl; ++s) {
                const int depth = s + t - 2;
                if (depth < 0 || depth > settings.maxDepth || (s == 1 && t == 1)) continue;
                Connection c;
                PathVertex sampled;
                if (!connectStrategy(scene, light.data(), s, camera.data(), t, sampler, settings, &c, &sampled)) continue;
                // The full path, camera first (as tests/unit/test_mis.cpp's fullPath).
                std::vector<PathVertex> x;
                for (int i = 0; i < t; ++i) x.push_back(t == 1 ? sampled : camera[size_t(i)]);
                for (int j = s - 1; j >= 0; --j) x.push_back(s == 1 ? sampled : light[size_t(j)]);
                x[size_t(t - 1)].delta = false;
                if (s > 0) x[size_t(t)].delta = false;
                ++paths;
                bool perturbed = false;
                for (const PathVertex& v : x) perturbed = perturbed || (v.isOnSurface() && glm::dot(v.ns, v.ng) < 0.999f);
                perturbedPaths += perturbed;
                for (MisHeuristic h : heuristics) {
                    MisSettings mis;
                    mis.heuristic = h;
                    mis.beta = 2.0;
                    const std::vector<double> w = misWeightsDefinition(scene, x, mis);
                    double sum = 0.0;
                    for (double v : w) sum += v;
                    worstSum = std::max(worstSum, std::abs(sum - 1.0));
                    if (!(std::abs(sum - 1.0) <= 1e-9)) ++sumFailures;
                    if (!(w.size() == x.size() && w[size_t(s)] > 0.0)) {
                        ++invalid;
                        continue;
                    }
                    const double prod = h == MisHeuristic::Balance ? c.weight
                                                                   : misWeight(scene, light.data(), s, camera.data(), t, sampled, mis);
                    const double tol = w[size_t(s)] * misRelativeTolerance(x, mis.exponent());
                    const double err = std::abs(prod - w[size_t(s)]);
                    worstRatio = std::max(worstRatio, err / tol);
                    if (!(err <= tol)) {
                        if (weightFailures++ < 5) first << "s=" << s << " t=" << t << " prod " << prod << " def " << w[size_t(s)] << "\n";
                    }
                }
            }
    }
    INFO(first.str() << "paths " << paths << " (through a perturbed normal: " << perturbedPaths << "), worst |sum - 1| " << worstSum
                     << ", worst error / tolerance " << worstRatio);
    CHECK(paths >= 10000);
    CHECK(perturbedPaths >= 10000);
    CHECK(sumFailures == 0);
    CHECK(invalid == 0);
    CHECK(weightFailures == 0);
}

TEST_CASE("Normal maps: wavefront equals megakernel bit for bit", "[normalmap][wavefront]") {
    const Scene scene = normalMapScene(16);
    for (const char* integrator : {"path", "lt", "bdpt"})
        for (MisHeuristic h : {MisHeuristic::Balance, MisHeuristic::Power}) {
            if (std::string(integrator) != "bdpt" && h == MisHeuristic::Power) continue;
            INFO("integrator " << integrator << ", heuristic " << int(h));
            Setup s;
            s.integrator = integrator;
            s.heuristic = h;
            s.strategies = std::string(integrator) != "path";
            GpuReport report;
            const Film mega = render(scene, s);
            const Film wave = render(scene, s, &report);
            int beauty = 0, lightImage = 0, layers = 0;
            double total = 0.0;
            for (int y = 0; y < mega.height(); ++y)
                for (int x = 0; x < mega.width(); ++x) {
                    beauty += !(mega.sum(x, y) == wave.sum(x, y) && mega.sumSquares(x, y) == wave.sumSquares(x, y) &&
                                mega.count(x, y) == wave.count(x, y));
                    lightImage += !(mega.lightMean(x, y) == wave.lightMean(x, y));
                    total += mega.mean(x, y).y;
                    if (!s.strategies) continue;
                    for (int depth = 0; depth <= s.maxDepth; ++depth)
                        for (int sl = 0; sl <= depth + 1; ++sl)
                            for (bool weighted : {false, true})
                                layers += !(mega.strategies().mean(sl, depth + 2 - sl, weighted, x, y) ==
                                            wave.strategies().mean(sl, depth + 2 - sl, weighted, x, y));
                }
            CHECK(beauty == 0);
            CHECK(lightImage == 0);
            CHECK(layers == 0);
            CHECK(total > 1e-3);  // not vacuous
        }
}
