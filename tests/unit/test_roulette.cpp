// The Russian-roulette policy (src/render/roulette.h, docs/path-tracer.md "Russian roulette"):
// one rule for camera and light subpaths, normalised by the walk's starting throughput.
//
// In the furnace box (closed, every face Lambert of albedo rho = 0.5, so f |cos| / pdf = rho at
// every bounce) the policy fixes the distribution of a subpath's length exactly: the first
// three surface vertices always exist (roulette starts after the BSDF sample of the third), the
// normalised throughput there is rho^3, so vertex 4 exists with probability rho^3, and after
// that each survivor's normalised throughput is 1 again and each later vertex survives with rho:
//     P(surface vertex k exists) = 1 (k <= 3),  rho^(k-1) (k >= 4),  up to the length limit.
// The light subpath starts with a power (here Le pi A / pmf = 75, the camera 1): with the raw
// throughput, the rule before, it would not play roulette until rho^k < 1/75 (k >= 7), and its
// mean length would be about 7 instead of 3.25.
#include "bdptref/bdpt.h"
#include "bdptref/scene.h"
#include "render/roulette.h"
#include "support/render_util.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

using namespace bdptref;

namespace {

// E[number of surface vertices] under the policy, with at most `maxSurface` of them.
double expectedSurfaceVertices(double rho, int maxSurface) {
    double sum = 0.0;
    for (int k = 1; k <= maxSurface; ++k) sum += k <= 3 ? 1.0 : std::pow(rho, k - 1);
    return sum;
}

struct Moments {
    double n = 0, sum = 0, sumSq = 0;
    void add(double x) {
        ++n;
        sum += x;
        sumSq += x * x;
    }
    double mean() const { return sum / n; }
    double standardError() const { return std::sqrt((sumSq / n - mean() * mean()) / (n - 1)); }
};

}  // namespace

TEST_CASE("roulette: survival is the throughput over the starting throughput, floored at 0.05", "[roulette]") {
    CHECK(rouletteSurvival(Rgb(0.5f, 0.2f, 0.1f), 1.f) == 0.5f);
    CHECK(rouletteSurvival(Rgb(30.f, 10.f, 5.f), rouletteStartScale(Rgb(60.f, 1.f, 1.f))) == 0.5f);
    CHECK(rouletteSurvival(Rgb(3.f), 1.f) == 1.f);              // capped at 1: no reweighting
    CHECK(rouletteSurvival(Rgb(1e-6f), 1.f) == kRouletteFloor);  // survivors weigh at most 20
    CHECK(rouletteStartScale(Rgb(0.f)) == 0.f);                  // a black start: the floor decides
    CHECK(rouletteStartScale(Rgb(INFINITY, 1.f, 1.f)) == 0.f);
}

TEST_CASE("roulette: camera and light subpath lengths in the furnace box follow the policy", "[roulette][bdpt]") {
    const Scene scene = test::loadTestScene("scenes/furnace-box.gltf", 16, 16);
    const double rho = 0.5;
    BdptSettings settings;
    settings.maxDepth = 12;
    REQUIRE(settings.rouletteStartDepth == 3);  // the default the formula above is written for
    const int maxCameraSurface = settings.maxCameraVertices() - 1, maxLightSurface = settings.maxLightVertices() - 1;
    std::vector<PathVertex> cam(size_t(settings.maxCameraVertices())), light(size_t(settings.maxLightVertices()));
    Moments camLength, lightLength;
    const uint32_t n = 40000;
    for (uint32_t k = 0; k < n; ++k) {
        const PixelSampler sampler(11u, k % 256u, k);
        const Vec2 raster = Vec2(float(k % 16u), float((k / 16u) % 16u)) + sampler.get2D(RngStream::Camera, dim::kFilm);
        camLength.add(generateCameraSubpath(scene, sampler, raster, settings, cam.data()) - 1);
        lightLength.add(generateLightSubpath(scene, sampler, settings, light.data()) - 1);
    }
    // k = 5 standard errors (estimated from the same samples): a false failure has probability
    // below 1e-6 per check; the raw-throughput rule is off by ~4 vertices, i.e. > 100 sigma.
    const double k = 5.0;
    const double wantCamera = expectedSurfaceVertices(rho, maxCameraSurface);
    const double wantLight = expectedSurfaceVertices(rho, maxLightSurface);
    INFO("camera: mean " << camLength.mean() << " +- " << camLength.standardError() << ", want " << wantCamera);
    INFO("light: mean " << lightLength.mean() << " +- " << lightLength.standardError() << ", want " << wantLight);
    CHECK(std::abs(camLength.mean() - wantCamera) <= k * camLength.standardError());
    CHECK(std::abs(lightLength.mean() - wantLight) <= k * lightLength.standardError());
}
