// Emissive textures through the estimators (docs/lights.md, "Emissive textures"), on a small scene
// lit only by an emissive-textured area light (a checkerboard of bright and black texels, bilinear,
// facing down over a floor and in front of a wall; the camera sees the emitter and what it lights):
//  * PT, LT, BDPT-balance and BDPT-power agree per pixel (the Welch + binomial rule of
//    tests/support/image_stats.h, as tests/scenes/test_bdpt_agreement.cpp), and each comparison
//    detects a uniform 5% error in either image (its power, measured on these very renders);
//  * the MIS weights of >= 1e4 sampled paths sum to 1 and the production weight equals the
//    definition's (tests/unit/test_mis.cpp's rule and tolerance, tests/support/mis_tolerance.h);
//  * the wavefront mode renders bit-identically to the megakernel (tests/scenes/test_wavefront.cpp).
#include "support/gltf_builder.h"
#include "support/image_stats.h"
#include "support/mis_tolerance.h"
#include "support/render_util.h"

#include "bdptref/bdpt.h"
#include "bdptref/gltf_loader.h"
#include "bdptref/integrator.h"
#include "bdptref/renderer.h"
#include "bdptref/scene.h"
#include "bdptref/wavefront.h"

#include <catch2/catch.hpp>

#include <memory>

using namespace bdptref;
using namespace bdptref::test;

namespace {

// 16 x 16 pixels; the emitter (y = 1, facing down) carries a 4 x 4 checkerboard, bright texels
// (255, 230, 180) and black ones, bilinear filtered, emissive factor 1 times strength 8.
Scene checkerLitScene() {
    Doc d;
    std::vector<uint16_t> texels;
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i)
            for (uint16_t v : {uint16_t(255), uint16_t(230), uint16_t(180)}) texels.push_back((i + j) % 2 ? uint16_t(0) : v);
    const int tex = pngTexture(d, 4, 4, 3, texels, false);
    const int lamp = d.lambert({0, 0, 0}, {1, 1, 1}, 8.0);
    d.j["materials"][size_t(lamp)]["emissiveTexture"] = {{"index", tex}};
    texturedQuad(d, {{{-0.6, 1, -0.6}, {0.6, 1, -0.6}, {0.6, 1, 0.6}, {-0.6, 1, 0.6}}}, {{{0, 0}, {1, 0}, {1, 1}, {0, 1}}}, lamp);
    // Floor (facing +y) and wall (facing +z) fill the whole image, so every pixel is t-tested.
    d.quad({-3, 0, -1}, {-3, 0, 3}, {3, 0, 3}, {3, 0, -1}, d.lambert({0.6, 0.6, 0.6}));
    d.quad({-3, 0, -1}, {3, 0, -1}, {3, 3, -1}, {-3, 3, -1}, d.lambert({0.7, 0.4, 0.3}));
    LoadOptions o;
    o.width = o.height = 16;
    Scene s = loadGltfScene(d.write("emissive-checker.gltf"), o);
    s.camera = Camera::lookAt(Vec3(0, 0.35f, 2.2f), Vec3(0, 0.55f, 0), Vec3(0, 1, 0), 1.0f, 16, 16);
    s.finalize();
    return s;
}

struct Setup {
    std::string integrator = "bdpt";
    MisHeuristic heuristic = MisHeuristic::Balance;
    int spp = 16, maxDepth = 5, threads = 0;
    uint32_t seed = 1;
    bool strategies = false;
    bool wavefront = false;
};

Film render(const Scene& scene, const Setup& s) {
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
    if (s.wavefront) {
        wavefront = std::make_unique<WavefrontScheduler>(s.integrator, is, WavefrontOptions{});
        ro.scheduler = wavefront.get();
    }
    Film film(scene.camera.width(), scene.camera.height());
    if (s.strategies) film.enableStrategies(s.maxDepth);
    renderImage(scene, *integrator, ro, film);
    return film;
}

MomentImage scaled(MomentImage img, double factor) {
    for (PixelMoments& p : img.pixels) {
        p.mean *= factor;
        p.varianceOfMean *= factor * factor;
    }
    return img;
}

}  // namespace

TEST_CASE("Emissive texture: PT LT BDPT-balance and BDPT-power agree per pixel on a scene lit by a textured light",
          "[emissive-texture][agreement]") {
    const Scene scene = checkerLitScene();
    REQUIRE(scene.lights.size() == 2);
    REQUIRE(scene.lights[0].emissiveTexture.valid());
    std::vector<Setup> setups(4);
    setups[0].integrator = "path";
    setups[1].integrator = "lt";
    setups[3].heuristic = MisHeuristic::Power;
    const int spp[4] = {1024, 1024, 512, 512};
    const char* names[4] = {"path", "lt", "bdpt-balance", "bdpt-power"};
    std::vector<MomentImage> images;
    for (size_t i = 0; i < 4; ++i) {
        setups[i].spp = spp[i];
        setups[i].seed = uint32_t(3000 + 17 * i);  // independent renders
        const Film f = render(scene, setups[i]);
        CHECK(f.nonFiniteSamples() == 0);
        images.push_back(momentsOf(f));
    }
    constexpr double kDetectableBias = 0.05;
    for (size_t i = 0; i < 4; ++i)
        for (size_t j = i + 1; j < 4; ++j) {
            const ImageComparison c = compareImages(images[i], images[j], kPixelAlpha, names[i], names[j]);
            INFO(c.report);
            CHECK(c.passed());
            CHECK(c.tested >= c.pixels * 9 / 10);  // not vacuous: (almost) every pixel is tested
            const ImageComparison up = compareImages(scaled(images[i], 1.0 + kDetectableBias), images[j], kPixelAlpha, names[i], names[j]);
            const ImageComparison down = compareImages(images[i], scaled(images[j], 1.0 + kDetectableBias), kPixelAlpha, names[i], names[j]);
            INFO(up.report);
            INFO(down.report);
            CHECK_FALSE(up.passed());
            CHECK_FALSE(down.passed());
        }
}

TEST_CASE("Emissive texture: MIS weights of sampled paths on a textured light sum to 1 and equal the definition",
          "[emissive-texture][mis]") {
    const Scene scene = checkerLitScene();
    BdptSettings settings;
    settings.maxDepth = 5;
    std::vector<PathVertex> camera(size_t(settings.maxCameraVertices())), light(size_t(settings.maxLightVertices()));
    const uint32_t width = uint32_t(scene.camera.width()), pixels = width * uint32_t(scene.camera.height());
    long paths = 0, sumFailures = 0, weightFailures = 0, s0 = 0, s1 = 0, t1 = 0, onBlack = 0;
    double worstSum = 0.0, worstRatio = 0.0;
    for (int k = 0; k < 6000; ++k) {
        const uint32_t pixel = uint32_t(k) * 7919u % pixels;
        const PixelSampler sampler(777u, pixel, uint64_t(k));
        const Vec2 raster = Vec2(float(pixel % width), float(pixel / width)) + sampler.get2D(RngStream::Camera, dim::kFilm);
        const int nc = generateCameraSubpath(scene, sampler, raster, settings, camera.data());
        const int nl = generateLightSubpath(scene, sampler, settings, light.data());
        for (int t = 1; t <= nc; ++t)
            for (int s = 0; s <= nl; ++s) {
                const int depth = s + t - 2;
                if (depth < 0 || depth > settings.maxDepth || (s == 1 && t == 1)) continue;  // as the integrator
                Connection c;
                PathVertex sampled;
                if (!connectStrategy(scene, light.data(), s, camera.data(), t, sampler, settings, &c, &sampled)) continue;
                // The full path camera first (test_mis.cpp's fullPath).
                std::vector<PathVertex> x;
                for (int i = 0; i < t; ++i) x.push_back(t == 1 ? sampled : camera[size_t(i)]);
                for (int j = s - 1; j >= 0; --j) x.push_back(s == 1 ? sampled : light[size_t(j)]);
                x[size_t(t - 1)].delta = false;
                if (s > 0) x[size_t(t)].delta = false;
                ++paths;
                s0 += s == 0;
                s1 += s == 1;
                t1 += t == 1;
                const Light& l = scene.lights[size_t(x.back().light)];
                onBlack += isBlack(areaEmission(l, scene.textures, x.back().bary));
                for (MisHeuristic h : {MisHeuristic::Balance, MisHeuristic::Power}) {
                    MisSettings mis;
                    mis.heuristic = h;
                    const std::vector<double> w = misWeightsDefinition(scene, x, mis);
                    double sum = 0.0;
                    for (double v : w) sum += v;
                    worstSum = std::max(worstSum, std::abs(sum - 1.0));
                    sumFailures += !(std::abs(sum - 1.0) <= 1e-9);
                    const double prod = misWeight(scene, light.data(), s, camera.data(), t, sampled, mis);
                    const double tol = w[size_t(s)] * misRelativeTolerance(x, mis.exponent());
                    worstRatio = std::max(worstRatio, std::abs(prod - w[size_t(s)]) / tol);
                    weightFailures += !(std::abs(prod - w[size_t(s)]) <= tol);
                }
            }
    }
    INFO(paths << " paths (s = 0: " << s0 << ", s = 1: " << s1 << ", t = 1: " << t1 << "), worst |sum - 1| " << worstSum
               << ", worst |prod - def| / tolerance " << worstRatio);
    CHECK(paths >= 10000);
    CHECK(s0 > 100);
    CHECK(s1 > 100);
    CHECK(t1 > 100);
    CHECK(onBlack == 0);  // a path ending on a black texel carries nothing and is never connected
    CHECK(sumFailures == 0);
    CHECK(weightFailures == 0);
}

TEST_CASE("Emissive texture: wavefront equals megakernel bit for bit on a scene lit by a textured light",
          "[emissive-texture][wavefront]") {
    const Scene scene = checkerLitScene();
    for (const char* integrator : {"path", "lt", "bdpt"})
        for (MisHeuristic h : {MisHeuristic::Balance, MisHeuristic::Power}) {
            if (std::string(integrator) != "bdpt" && h == MisHeuristic::Power) continue;
            Setup s;
            s.integrator = integrator;
            s.heuristic = h;
            s.spp = 2;
            s.threads = 2;
            s.strategies = std::string(integrator) != "path";
            const Film mega = render(scene, s);
            s.wavefront = true;
            const Film wave = render(scene, s);
            INFO("integrator " << integrator << ", heuristic " << int(h));
            int differ = 0;
            double total = 0.0;
            for (int y = 0; y < mega.height(); ++y)
                for (int x = 0; x < mega.width(); ++x) {
                    differ += !(mega.sum(x, y) == wave.sum(x, y) && mega.sumSquares(x, y) == wave.sumSquares(x, y) &&
                                mega.count(x, y) == wave.count(x, y) && mega.lightMean(x, y) == wave.lightMean(x, y));
                    total += mega.mean(x, y).y;
                }
            CHECK(differ == 0);
            CHECK(total > 1e-3);  // not vacuous: the image is not black
        }
}
