// Environment maps in every estimator (docs/lights.md, "Environment"), on a floor with a diffuse
// and a glossy box lit only by the sun-and-sky map (a 2000x sun in one texel of a 64x32 map):
//  * PT, LT, BDPT-balance and BDPT-power agree per pixel and per 2x2 block (tests/support/
//    image_stats.h: Welch's t-test per pixel, binomial bound on the rejections; renders with
//    different seeds), and each block comparison detects a uniform 5% error in either image;
//  * MIS: on >= 10^4 sampled full paths ending on the map (s = 0 escapes, s = 1 next-event
//    connections, s >= 2 emission from the map's disk), the definition's weights sum to 1 (1e-9)
//    for the balance, power and uniform heuristics and the production weight equals the
//    definition's within the float32 bound of tests/support/mis_tolerance.h (as test_mis.cpp);
//  * the wavefront mode renders the same image bit for bit as the megakernel (PT, LT, BDPT).
#include "scenes/test_env_map_scenes.h"
#include "support/image_stats.h"
#include "support/mis_tolerance.h"

#include "bdptref/bdpt.h"
#include "bdptref/integrator.h"
#include "bdptref/renderer.h"
#include "bdptref/wavefront.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <memory>
#include <sstream>

using namespace bdptref;
using namespace bdptref::test;

namespace {

struct Setup {
    std::string integrator = "bdpt";
    MisHeuristic heuristic = MisHeuristic::Balance;
    int spp = 16, maxDepth = 5, threads = 0;
    uint32_t seed = 1;
    bool wavefront = false;
};

Film render(const Scene& scene, const Setup& s) {
    IntegratorSettings is;
    is.maxDepth = s.maxDepth;
    is.mis.heuristic = s.heuristic;
    const auto integ = makeIntegrator(s.integrator, is);
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
    renderImage(scene, *integ, ro, film);
    return film;
}

MomentImage scaled(MomentImage img, double factor) {
    for (PixelMoments& p : img.pixels) {
        p.mean *= factor;
        p.varianceOfMean *= factor * factor;
    }
    return img;
}

// The full path of strategy (s, t), camera first (as tests/unit/test_mis.cpp builds it).
std::vector<PathVertex> fullPath(const PathVertex* camera, int t, const PathVertex* light, int s, const PathVertex& sampled) {
    std::vector<PathVertex> x;
    for (int i = 0; i < t; ++i) x.push_back(t == 1 ? sampled : camera[i]);
    for (int j = s - 1; j >= 0; --j) x.push_back(s == 1 ? sampled : light[j]);
    x[size_t(t - 1)].delta = false;
    if (s > 0) x[size_t(t)].delta = false;
    return x;
}

}  // namespace

TEST_CASE("Environment map: PT LT BDPT-balance and BDPT-power agree per pixel on a sun-and-sky lit scene",
          "[envmap][agreement]") {
    const Scene scene = sunSkyBoxesScene(20, 16);
    struct Run {
        const char* name;
        const char* integrator;
        MisHeuristic h;
        int spp;
    };
    const Run runs[] = {{"path", "path", MisHeuristic::Balance, 512},
                        {"lt", "lt", MisHeuristic::Balance, 8192},
                        {"bdpt-balance", "bdpt", MisHeuristic::Balance, 256},
                        {"bdpt-power", "bdpt", MisHeuristic::Power, 256}};
    std::vector<std::pair<std::string, MomentImage>> images;
    for (size_t i = 0; i < 4; ++i) {
        Setup s;
        s.integrator = runs[i].integrator;
        s.heuristic = runs[i].h;
        s.spp = runs[i].spp;
        s.seed = uint32_t(3000 + 31 * i);  // independent renders
        const Film f = render(scene, s);
        CHECK(f.nonFiniteSamples() == 0);
        images.emplace_back(runs[i].name, momentsOf(f));
    }
    for (size_t i = 0; i < images.size(); ++i)
        for (size_t j = i + 1; j < images.size(); ++j) {
            const auto& [na, a] = images[i];
            const auto& [nb, b] = images[j];
            const ImageComparison c = compareImages(a, b, kPixelAlpha, na, nb);
            INFO(c.report);
            CHECK(c.passed());
            CHECK(c.tested >= c.pixels * 9 / 10);
            // The same on 2x2 blocks (80 of them), where the power check is made: light tracing
            // from a map whose disk covers the whole floor is too noisy per pixel for a 5% error
            // to show at a bearable sample count, but not per block.
            const MomentImage a2 = mergeBlocks(a, 2), b2 = mergeBlocks(b, 2);
            const ImageComparison blocks = compareImages(a2, b2, kPixelAlpha, na + " 2x2", nb + " 2x2");
            INFO(blocks.report);
            CHECK(blocks.passed());
            const ImageComparison up = compareImages(scaled(a2, 1.05), b2, kPixelAlpha, na + " 2x2 (scaled)", nb + " 2x2");
            const ImageComparison down = compareImages(a2, scaled(b2, 1.05), kPixelAlpha, na + " 2x2", nb + " 2x2 (scaled)");
            INFO(up.report);
            INFO(down.report);
            CHECK_FALSE(up.passed());
            CHECK_FALSE(down.passed());
        }
}

TEST_CASE("Environment map: MIS weights of sampled paths sum to 1 and equal the definition (every strategy)",
          "[envmap][mis]") {
    const Scene scene = sunSkyBoxesScene(16, 16);
    const MisHeuristic heuristics[3] = {MisHeuristic::Balance, MisHeuristic::Power, MisHeuristic::Uniform};
    BdptSettings settings;
    settings.maxDepth = 4;
    std::vector<PathVertex> camera(size_t(settings.maxCameraVertices())), light(size_t(settings.maxLightVertices()));
    const uint32_t width = uint32_t(scene.camera.width()), pixels = width * uint32_t(scene.camera.height());
    long paths = 0, s0 = 0, s1 = 0, sLight = 0, t1 = 0, sumFailures = 0, weightFailures = 0, invalid = 0;
    std::ostringstream failures;
    for (int k = 0; k < 9000; ++k) {
        const uint32_t pixel = uint32_t(k) * 7919u % pixels;
        const PixelSampler sampler(77u, pixel, uint64_t(k));
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
                const std::vector<PathVertex> x = fullPath(camera.data(), t, light.data(), s, sampled);
                if (!x.back().infinite) continue;  // the environment is the only light: always true
                ++paths;
                s0 += s == 0;
                s1 += s == 1;
                sLight += s >= 2;
                t1 += t == 1;
                for (MisHeuristic h : heuristics) {
                    MisSettings mis;
                    mis.heuristic = h;
                    mis.beta = 2.0;
                    const std::vector<double> w = misWeightsDefinition(scene, x, mis);
                    double sum = 0.0;
                    for (double v : w) sum += v;
                    if (!(std::abs(sum - 1.0) <= 1e-9)) {
                        ++sumFailures;
                        failures << "sum " << sum << " s=" << s << " t=" << t << "\n";
                    }
                    if (!(w[size_t(s)] > 0.0)) {
                        ++invalid;
                        continue;
                    }
                    const double prod = misWeight(scene, light.data(), s, camera.data(), t, sampled, mis);
                    const double tol = w[size_t(s)] * misRelativeTolerance(x, mis.exponent());
                    if (!(std::abs(prod - w[size_t(s)]) <= tol)) {
                        ++weightFailures;
                        if (weightFailures < 8)
                            failures << "heuristic " << int(h) << " s=" << s << " t=" << t << " production " << prod << " definition "
                                     << w[size_t(s)] << "\n";
                    }
                    if (h == MisHeuristic::Balance && !(c.weight == prod)) ++weightFailures;
                }
            }
    }
    INFO(failures.str());
    INFO("paths " << paths << " s=0 " << s0 << " s=1 " << s1 << " s>=2 " << sLight << " t=1 " << t1);
    CHECK(paths >= 10000);
    CHECK(s0 >= 1000);
    CHECK(s1 >= 1000);
    CHECK(sLight >= 1000);
    CHECK(t1 >= 500);
    CHECK(sumFailures == 0);
    CHECK(weightFailures == 0);
    CHECK(invalid == 0);
}

TEST_CASE("Environment map: the wavefront mode equals the megakernel bit for bit", "[envmap][wavefront]") {
    const Scene scene = sunSkyBoxesScene(16, 12);
    for (const char* integrator : {"path", "lt", "bdpt"}) {
        INFO(integrator);
        Setup s;
        s.integrator = integrator;
        s.spp = 2;
        s.threads = 2;
        const Film mega = render(scene, s);
        s.wavefront = true;
        const Film wave = render(scene, s);
        int differing = 0;
        double mean = 0.0;
        for (int y = 0; y < mega.height(); ++y)
            for (int x = 0; x < mega.width(); ++x) {
                differing += !(mega.sum(x, y) == wave.sum(x, y) && mega.sumSquares(x, y) == wave.sumSquares(x, y) &&
                               mega.count(x, y) == wave.count(x, y) && mega.lightMean(x, y) == wave.lightMean(x, y));
                mean += mega.mean(x, y).y;
            }
        CHECK(differing == 0);
        CHECK(mean > 1e-3);  // not vacuous: the image is lit
    }
}
