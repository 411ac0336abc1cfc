// The benchmark scenes (scenes/README.md, "Benchmark scenes") load as generated, carry the
// properties the benchmark relies on, and render to a non-black image; the ray counters count.
#include "bdptref/scene.h"
#include "support/render_util.h"

#include <catch2/catch.hpp>

#include <map>
#include <string>

using namespace bdptref;
using namespace bdptref::test;

namespace {

size_t areaLightCount(const Scene& s) {
    size_t n = 0;
    for (const Light& l : s.lights) n += l.type == LightType::Area ? 1 : 0;
    return n;
}

const Material& materialNamed(const Scene& s, const std::string& name) {
    for (const Material& m : s.materials)
        if (m.name == name) return m;
    FAIL("no material named " << name);
    return s.materials.front();
}

// Every pixel sample pooled: the image must be lit, by more than k = 5 standard errors.
void requireLit(const Scene& scene, const std::string& integrator) {
    const Film film = renderFilm(scene, integrator, 16, 8, 7u);
    const PooledMean m = pooledMean(film);
    const double lum = m.mean.x + m.mean.y + m.mean.z;
    const double se = m.standardError.x + m.standardError.y + m.standardError.z;
    REQUIRE(lum > 5.0 * se);
}

}  // namespace

TEST_CASE("Bench scene veach-mis: four plates of increasing roughness, four spheres of equal power", "[bench-scenes]") {
    const Scene s = loadTestScene("scenes/veach-mis.gltf", 32, 32);
    // 2 walls (2 triangles each), 4 plates (2 each), 4 level-2 icospheres (320 each).
    CHECK(s.mesh.triangleCount() == 4 + 8 + 4 * 320);
    CHECK(areaLightCount(s) == 4 * 320);
    float previous = 0.f;
    for (int i = 0; i < 4; ++i) {
        const Material& plate = materialNamed(s, "plate_" + std::to_string(i));
        CHECK(plate.metallic == 1.f);
        CHECK(plate.roughness > previous);
        previous = plate.roughness;
    }
    // Equal power per sphere: radiance ~ 1/r^2 and area ~ r^2 (same tessellation), so the summed
    // power of each sphere's triangles agrees to float rounding (relative 1e-4 allows for it).
    std::map<uint32_t, double> power;
    for (const Light& l : s.lights)
        if (l.type == LightType::Area) power[s.mesh.triangleMaterial[l.triangle]] += double(l.power);
    REQUIRE(power.size() == 4);
    const double first = power.begin()->second;
    for (const auto& [mat, p] : power) CHECK(p == Approx(first).epsilon(1e-4));
    requireLit(s, "bdpt");
}

TEST_CASE("Bench scene narrow-gap: the light is behind a wall with a slit", "[bench-scenes]") {
    const Scene s = loadTestScene("scenes/narrow-gap.gltf", 32, 32);
    CHECK(s.mesh.triangleCount() == 12 + 12 + 2);
    REQUIRE(areaLightCount(s) == 2);
    // In world coordinates (the scene is in camera-centred render space after finalize()).
    for (const Light& l : s.lights) CHECK(s.toWorld(l.v0).x < -0.05);  // light in the left half
    CHECK(s.toWorld(s.camera.position()).x > 0.05);                    // camera in the right half
    // No straight line joins the camera to the light's centre: the wall is in between.
    const Light& l = s.lights.front();
    const Vec3 centre = (l.v0 + l.v1 + l.v2) / 3.f;
    CHECK_FALSE(s.visible(s.camera.position(), Vec3(0.f), centre, l.normal));
    requireLit(s, "bdpt");
}

TEST_CASE("Bench scene caustic-glass: a smooth glass sphere under a small light", "[bench-scenes]") {
    const Scene s = loadTestScene("scenes/caustic-glass.gltf", 32, 32);
    CHECK(s.mesh.triangleCount() == 2 + 2 + 1280 + 2);
    REQUIRE(areaLightCount(s) == 2);
    double area = 0.0;
    for (const Light& l : s.lights) area += double(l.area);
    CHECK(area == Approx(0.01).epsilon(1e-4));
    const Material& glass = materialNamed(s, "glass");
    CHECK(glass.transmission == 1.f);
    CHECK(glass.roughness == 0.f);
    CHECK(glass.ior == 1.5f);
    requireLit(s, "lt");
}

TEST_CASE("Bench scene sphere-grid: over a million triangles from one instanced mesh", "[bench-scenes]") {
    const Scene s = loadTestScene("scenes/sphere-grid.glb", 16, 16);
    CHECK(s.mesh.triangleCount() == 196u * 5120u + 2u + 2u);
    CHECK(s.mesh.triangleCount() >= 1000000u);
    CHECK(areaLightCount(s) == 2);
    requireLit(s, "path");
}

TEST_CASE("Ray counters: a path-traced image traces at least one extension ray per sample", "[bench-scenes]") {
    const Scene s = loadTestScene("scenes/cornell-box.gltf", 16, 16);
    const RayCounts before = rayCountsSoFar();
    const Film film = renderFilm(s, "path", 2, 4, 3u, 2);
    const RayCounts after = rayCountsSoFar();
    const uint64_t samples = 16u * 16u * 2u;
    const uint64_t ext = after.extension - before.extension, shadow = after.shadow - before.shadow;
    CHECK(ext >= samples);
    // At most maxDepth + 1 = 5 extension rays and one shadow ray per bounce (4 bounces) per sample.
    CHECK(ext <= 5 * samples);
    CHECK(shadow > 0u);
    CHECK(shadow <= 4 * samples);
}

TEST_CASE("Ray counters count every ray exactly whatever the thread count", "[bench-scenes]") {
    // The rays a render traces depend only on its samples, so the per-thread counters (one cache
    // line per thread, src/scene/ray_counters.h) must add up to the same totals for 1 and 2 threads.
    const Scene s = loadTestScene("scenes/cornell-box.gltf", 16, 16);
    RayCounts counts[2];
    for (int threads = 1; threads <= 2; ++threads) {
        const RayCounts before = rayCountsSoFar();
        (void)renderFilm(s, "bdpt", 4, 5, 9u, threads);
        const RayCounts after = rayCountsSoFar();
        counts[threads - 1] = RayCounts{after.extension - before.extension, after.shadow - before.shadow};
    }
    CHECK(counts[0].extension > 16u * 16u * 4u);
    CHECK(counts[0].shadow > 0u);
    CHECK(counts[1].extension == counts[0].extension);
    CHECK(counts[1].shadow == counts[0].shadow);
}
