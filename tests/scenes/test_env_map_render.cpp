// Known answers for environment map lighting, in PT, LT and BDPT (docs/lights.md, "Environment"):
//  * furnace: a convex Lambert cube of albedo rho under a 64x32 map of constant value L (through the
//    general map code, rotated) shows rho L in every pixel;
//  * a Lambert floor under the sun-and-sky map (a 20000x sun in one texel) has radiance
//    rho / pi * E, E = the cosine-weighted integral of the map over the upper hemisphere computed
//    here by numerical quadrature of the generated texels (not through EnvironmentMap), with and
//    without --env-rotate (a turn about the floor's normal leaves E unchanged).
// Tolerance: 5 standard errors of the image mean, the error estimated from the spread of the
// per-pass image means (passes are independent; pixels of an LT pass are not). Each test also
// checks that 5 standard errors are below a third of the error it must detect (5% for PT and
// BDPT, 10% for the far less efficient LT), so such an error would fail.
#include "scenes/test_env_map_scenes.h"

#include "support/estimators.h"
#include "support/pass_statistics.h"

#include <catch2/catch.hpp>

#include <cmath>

using namespace bdptref;
using namespace bdptref::test;

namespace {

constexpr double kPiD = 3.14159265358979323846;
constexpr double kSigmas = 5.0;

struct PassMean {
    DVec3 mean{0.0}, standardError{0.0};
    uint64_t nonFinite = 0;
};

// Image mean of a render with the per-pass standard error (support/pass_statistics.h).
PassMean renderMean(const Scene& scene, const std::string& integrator, int spp, uint32_t seed) {
    EstimatorSetup s;
    s.integrator = integrator;
    s.spp = spp;
    s.seed = seed;
    s.maxDepth = 4;
    PassImageMean stat;
    const Film film = renderEstimator(scene, s, [&](const Film& f, int) { stat.afterPass(f); });
    return PassMean{stat.mean(), stat.standardError(), film.nonFiniteSamples()};
}

// detectable: the relative error the test must be able to see (5 standard errors below it / 3).
void checkKnownAnswer(const Scene& scene, const DVec3& expected, const std::string& integrator, int spp, double detectable = 0.05) {
    const PassMean m = renderMean(scene, integrator, spp, 4242u);
    INFO(integrator << ": mean " << m.mean.x << " " << m.mean.y << " " << m.mean.z << " +- " << m.standardError.x << " "
                    << m.standardError.y << " " << m.standardError.z << ", expected " << expected.x << " " << expected.y << " "
                    << expected.z);
    CHECK(m.nonFinite == 0);
    for (int c = 0; c < 3; ++c) {
        CHECK(std::abs(m.mean[c] - expected[c]) <= kSigmas * m.standardError[c]);
        CHECK(kSigmas * m.standardError[c] <= detectable / 3.0 * expected[c]);  // the test can see that error
    }
}

// E = integral over the upper hemisphere of L(w) cos(theta) dw for the sun-and-sky map (w x h,
// unrotated texel function), by the midpoint rule in theta inside each row (64 steps; L is
// constant over a texel, and the phi integral of a texel is its width 2 pi / w).
DVec3 upperHemisphereIrradiance(int w, int h) {
    DVec3 e(0.0);
    for (int r = 0; r < h; ++r) {
        const double t0 = kPiD * r / h, t1 = kPiD * (r + 1) / h;
        if (t1 > 0.5 * kPiD + 1e-12) break;  // h even: the horizon is a row boundary
        double rowWeight = 0.0;
        const int steps = 64;
        for (int k = 0; k < steps; ++k) {
            const double t = t0 + (t1 - t0) * (k + 0.5) / steps;
            rowWeight += std::cos(t) * std::sin(t) * (t1 - t0) / steps;
        }
        for (int c = 0; c < w; ++c) e += DVec3(sunAndSky(c, r, w, h)) * (rowWeight * 2.0 * kPiD / w);
    }
    return e;
}

}  // namespace

TEST_CASE("Environment map furnace: a convex Lambert cube under a constant map shows rho L in PT, LT and BDPT",
          "[envmap][furnace]") {
    const Rgb rho(0.6f, 0.45f, 0.3f), L(0.8f, 1.f, 1.25f);
    const Scene scene = furnaceCubeScene(rho, L, 16);
    const DVec3 expected = DVec3(rho) * DVec3(L);
    checkKnownAnswer(scene, expected, "path", 64);
    checkKnownAnswer(scene, expected, "bdpt", 64);
    checkKnownAnswer(scene, expected, "lt", 2048, 0.1);  // light tracing is far less efficient here
}

TEST_CASE("Environment map: a sun-and-sky map lights a Lambert floor with rho / pi times the map's irradiance integral",
          "[envmap]") {
    const Rgb rho(0.5f, 0.6f, 0.7f);
    const DVec3 expected = DVec3(rho) / kPiD * upperHemisphereIrradiance(64, 32);
    for (float rotation : {0.f, 1.1f}) {
        INFO("rotation " << rotation);
        const Scene scene = sunSkyPlaneScene(rho, rotation, 16);
        checkKnownAnswer(scene, expected, "path", 64);
        checkKnownAnswer(scene, expected, "bdpt", 64);
        checkKnownAnswer(scene, expected, "lt", 1024, 0.1);
    }
}
