// Environment map light (docs/lights.md, "Environment"): the direction <-> (u, v) convention, the
// densities of next-event and emission sampling against chi-square tests, pdf(sample) equal to the
// returned density, the power estimate, and the constant environment as the 1x1 map.
//
// Chi-square tests: tests/support/chi2.h; 6 tests in this file, each at the Sidak level that gives
// the file a 1% false-failure rate; fixed seeds. Maps: unit/test_env_map_maps.h (64x32, generated).
#include "support/chi2.h"
#include "unit/test_env_map_maps.h"

#include "bdptref/env_map.h"
#include "bdptref/light.h"
#include "bdptref/scene.h"

#include <catch2/catch.hpp>

#include <cmath>

using namespace bdptref;
using namespace bdptref::test;

namespace {

constexpr int kChi2Tests = 6;
constexpr double kPiD = 3.14159265358979323846;

// A scene holding only the map, and its environment light (as Scene::finalize makes it).
struct MapScene {
    Scene scene;
    Light light;
    explicit MapScene(EnvironmentMap map, Rgb scale = Rgb(1.f)) {
        scene.environmentMaps.push_back(std::move(map));
        light.type = LightType::Environment;
        light.envMap = 0;
        light.emission = scale;
        light.sceneCenter = Vec3(0.5f, -0.25f, 1.f);
        light.sceneRadius = 3.f;
    }
};

// Map-space (u, v) of a world direction for a map turned by `rotation` about +Y, written out
// independently of EnvironmentMap: undo R_y(rotation), then u = 0.5 + atan2(z, x) / 2pi,
// v = acos(y) / pi.
Vec2 uvOf(const Vec3& w, float rotation) {
    const double c = std::cos(double(rotation)), s = std::sin(double(rotation));
    const double x = c * w.x - s * w.z, z = s * w.x + c * w.z;
    const double u = 0.5 + std::atan2(z, x) / (2.0 * kPiD), v = std::acos(std::max(-1.0, std::min(1.0, double(w.y)))) / kPiD;
    return Vec2(float(std::min(u, 1.0 - 1e-7)), float(std::min(v, 1.0 - 1e-7)));
}
Vec3 directionOf(Vec2 uv, float rotation) {
    const double theta = kPiD * uv.y, phi = 2.0 * kPiD * uv.x - kPiD;
    const double x = std::sin(theta) * std::cos(phi), z = std::sin(theta) * std::sin(phi);
    const double c = std::cos(double(rotation)), s = std::sin(double(rotation));
    return Vec3(float(c * x + s * z), float(std::cos(theta)), float(-s * x + c * z));
}

// Direction of the centre of texel (col, row) of a w x h map without rotation (the convention of
// env_map.h written out independently: theta from +Y, phi = 2 pi u - pi from +X towards +Z).
Vec3 texelCentre(int col, int row, int w, int h) {
    const double theta = kPiD * (row + 0.5) / h, phi = 2.0 * kPiD * (col + 0.5) / w - kPiD;
    return Vec3(float(std::sin(theta) * std::cos(phi)), float(std::cos(theta)), float(std::sin(theta) * std::sin(phi)));
}

}  // namespace

TEST_CASE("Environment map: direction <-> (u, v) follows the documented convention", "[envmap]") {
    // u = 0.5 + atan2(z, x) / 2pi, v = acos(y) / pi, top row = +Y.
    const Vec2 px = EnvironmentMap::directionToUv(Vec3(1, 0, 0));
    CHECK(px.x == Approx(0.5));
    CHECK(px.y == Approx(0.5));
    CHECK(EnvironmentMap::directionToUv(Vec3(0, 0, 1)).x == Approx(0.75));
    CHECK(EnvironmentMap::directionToUv(Vec3(0, 0, -1)).x == Approx(0.25));
    CHECK(EnvironmentMap::directionToUv(Vec3(0, 1, 0)).y == Approx(0.0).margin(1e-6));
    CHECK(EnvironmentMap::directionToUv(Vec3(0, -1, 0)).y == Approx(1.0));

    // Each texel's centre direction finds that texel; lookup returns its value.
    const int w = 16, h = 8;
    const EnvironmentMap map(w, h, texelsOf(w, h, [&](int c, int r) { return Rgb(float(c), float(r), 1.f); }));
    for (int r = 0; r < h; ++r)
        for (int c = 0; c < w; ++c) {
            int col = -1, row = -1;
            map.texelOf(texelCentre(c, r, w, h), &col, &row);
            CHECK(col == c);
            CHECK(row == r);
            CHECK(map.lookup(texelCentre(c, r, w, h)) == Rgb(float(c), float(r), 1.f));
        }

    // --env-rotate 90: world = R_y(90 deg) map, so the image centre (map +X) appears at world -Z
    // and map +Z at world +X.
    const EnvironmentMap rotated(w, h, texelsOf(w, h, [&](int c, int r) { return Rgb(float(c), float(r), 1.f); }), 0.5f * kPi);
    int col, row;
    map.texelOf(Vec3(1, 0, 0), &col, &row);  // unrotated reference
    int colRot, rowRot;
    rotated.texelOf(Vec3(0, 0, -1), &colRot, &rowRot);
    CHECK(colRot == col);
    CHECK(rowRot == row);
    int colZ, rowZ, colX, rowX;
    map.texelOf(Vec3(0, 0, 1), &colZ, &rowZ);
    rotated.texelOf(Vec3(1, 0, 0), &colX, &rowX);
    CHECK(colX == colZ);
    CHECK(rowX == rowZ);
    const Vec3 d = glm::normalize(Vec3(0.3f, 0.5f, -0.8f));
    CHECK(glm::length(rotated.toWorld(rotated.toMap(d)) - d) < 1e-6f);
}

TEST_CASE("Environment map: sampled densities equal pdf(), which integrates to 1 over the sphere", "[envmap]") {
    const EnvironmentMap maps[] = {sunAndSkyMap(), smoothSkyMap(64, 32, 1.234f), EnvironmentMap::constant()};
    for (const EnvironmentMap& map : maps) {
        // Sum over texels of pdf(centre) x solid angle = 1 (the density is constant per texel).
        double total = 0.0;
        for (int r = 0; r < map.height(); ++r)
            for (int c = 0; c < map.width(); ++c)
                total += double(map.pdf(map.toWorld(texelCentre(c, r, map.width(), map.height())))) * map.texelSolidAngle(r);
        CHECK(total == Approx(1.0).epsilon(1e-5));
        // Every sample's returned density is pdf() of the returned direction, bit for bit, and the
        // direction is unit; the density is proportional to luminance (where the map is lit).
        int mismatches = 0;
        for (uint64_t i = 0; i < 20000; ++i) {
            Vec3 w;
            float pdf = 0.f;
            REQUIRE(map.sample(TestRng(3, i).uniform2D(), &w, &pdf));
            if (!(pdf == map.pdf(w)) || std::abs(glm::length(w) - 1.f) > 1e-5f) ++mismatches;
        }
        CHECK(mismatches == 0);
    }
    // The 1x1 map (the constant environment) is the uniform sphere: density 1 / 4pi everywhere.
    const EnvironmentMap unit = EnvironmentMap::constant();
    CHECK(unit.pdf(Vec3(0, 1, 0)) == kInv4Pi);
    CHECK(unit.pdf(glm::normalize(Vec3(0.2f, -0.7f, 0.4f))) == kInv4Pi);
    CHECK(unit.integratedLuminance(Rgb(2.f)) == Approx(4.0 * kPiD * 2.0).epsilon(1e-12));
}

TEST_CASE("Chi-square: environment map next-event directions follow pdfLi (sun and sky, smooth sky, rotated, tiny sun)",
          "[envmap][chi2]") {
    const double alpha = sidakAlpha(0.01, kChi2Tests);
    struct Case {
        const char* name;
        EnvironmentMap map;
    };
    const Case cases[] = {{"sun and sky", sunAndSkyMap()}, {"smooth sky", smoothSkyMap()},
                          {"sun and sky rotated 40 degrees", sunAndSkyMap(64, 32, 40.f * kPi / 180.f)},
                          // 256x128: the sun is one texel of ~1e-4 sr (0.6 degrees) near the
                          // zenith; each 64x32 cell holds 4x4 texels, whose edges the adaptive
                          // quadrature's halvings meet exactly.
                          {"tiny sun on a 256x128 sky", sunAndSkyMap(256, 128, 0.f, 1e5f)}};
    for (const Case& c : cases) {
        const MapScene ms(c.map);
        const float rot = c.map.rotation();
        const Vec3 ref(0.2f, 0.1f, -0.3f);
        // Binned in the map's (u, v) square, one cell per texel (the density jumps only at texel
        // edges, so each cell's integral is resolved); density there = pdfLi x 2 pi^2 sin(theta).
        const auto r = chi2Test2D(
            [&](uint64_t i, Vec2* uv) {
                LightLiSample s;
                if (!sampleLi(ms.light, ms.scene, ref, TestRng(21, i).uniform2D(), &s)) return false;
                *uv = uvOf(s.wi, rot);
                return true;
            },
            [&](const Vec2& uv) {
                const Vec3 d = glm::normalize(directionOf(uv, rot));
                return double(pdfLi(ms.light, ms.scene, ref, ref + d, d)) * 2.0 * kPiD * kPiD * std::sin(kPiD * uv.y);
            },
            400000, 64, 32);
        INFO(c.name << "\n" << r.report);
        CHECK(r.pValue > alpha);
    }
}

TEST_CASE("Environment map: sampleLi returns the map's radiance and density, and pdfLi of its direction", "[envmap]") {
    const MapScene ms(sunAndSkyMap(), Rgb(0.5f));
    const Vec3 ref(1.f, 2.f, -1.f);
    int sunHits = 0;
    for (uint64_t i = 0; i < 20000; ++i) {
        LightLiSample s;
        REQUIRE(sampleLi(ms.light, ms.scene, ref, TestRng(5, i).uniform2D(), &s));
        CHECK(s.pdf == ms.scene.environmentMaps[0].pdf(s.wi));
        CHECK(s.pdf == pdfLi(ms.light, ms.scene, ref, s.pLight, s.wi));
        CHECK(s.Li == Rgb(0.5f) * ms.scene.environmentMaps[0].lookup(s.wi));
        CHECK(environmentRadiance(ms.light, ms.scene, s.wi) == s.Li);
        CHECK(std::isinf(s.dist));
        CHECK_FALSE(s.delta);
        int col, row;
        ms.scene.environmentMaps[0].texelOf(s.wi, &col, &row);
        sunHits += col == kSunCol && row == kSunRow;
    }
    // The sun texel carries most of the luminance x solid angle: most samples go there.
    CHECK(sunHits > 10000);
    // A light with a map used without the scene is a programming error, not a constant map.
    LightLiSample s;
    CHECK_THROWS_AS(sampleLi(ms.light, Vec3(0.f), Vec2(0.5f), &s), std::logic_error);
}

TEST_CASE("Chi-square: environment map emission directions follow pdfLe, origins are uniform on the disk",
          "[envmap][chi2]") {
    const double alpha = sidakAlpha(0.01, kChi2Tests);
    const MapScene ms(sunAndSkyMap(64, 32, 0.3f), Rgb(2.f));
    const Light& l = ms.light;
    int offDisk = 0, badDensity = 0;
    const auto r = chi2Test2D(  // in the map's (u, v) of the direction the light comes from
        [&](uint64_t i, Vec2* uv) {
            TestRng rng(31, i);
            const Vec2 uPos = rng.uniform2D();
            LightLeSample s;
            if (!sampleLe(l, ms.scene, uPos, rng.uniform2D(), &s)) return false;
            *uv = uvOf(-s.ray.dir, 0.3f);
            // The origin lies on the disk of radius R centred at centre - dir R, perpendicular to dir.
            const Vec3 q = s.ray.origin - (l.sceneCenter - s.ray.dir * l.sceneRadius);
            if (std::abs(glm::dot(q, s.ray.dir)) > 1e-4f * l.sceneRadius || glm::length(q) > l.sceneRadius * (1.f + 1e-5f)) ++offDisk;
            float pp = 0.f, pd = 0.f;
            pdfLe(l, ms.scene, s.ray.origin, s.ray.dir, s.nLight, &pp, &pd);
            if (pp != s.pdfPos || pd != s.pdfDir || s.pdfPos != 1.f / (kPi * l.sceneRadius * l.sceneRadius) ||
                !(s.Le == l.emission * ms.scene.environmentMaps[0].lookup(-s.ray.dir)))
                ++badDensity;
            return true;
        },
        [&](const Vec2& uv) {
            const Vec3 d = -glm::normalize(directionOf(uv, 0.3f));  // direction of travel
            float pp, pd;
            pdfLe(l, ms.scene, Vec3(0.f), d, -d, &pp, &pd);
            return double(pd) * 2.0 * kPiD * kPiD * std::sin(kPiD * uv.y);
        },
        400000, 64, 32);
    INFO(r.report);
    CHECK(r.pValue > alpha);
    CHECK(offDisk == 0);
    CHECK(badDensity == 0);

    // Disk positions: r^2 / R^2 and the angle about the direction are uniform (area density 1 / pi R^2).
    const auto rd = chi2Test2D(
        [&](uint64_t i, Vec2* p) {
            TestRng rng(32, i);
            const Vec2 uPos = rng.uniform2D();
            LightLeSample s;
            if (!sampleLe(l, ms.scene, uPos, rng.uniform2D(), &s)) return false;
            const Vec3 q = (s.ray.origin - (l.sceneCenter - s.ray.dir * l.sceneRadius)) / l.sceneRadius;
            const Frame f(-s.ray.dir);
            const float a = std::atan2(glm::dot(q, f.t), glm::dot(q, f.s));
            *p = Vec2(glm::clamp(glm::dot(q, q), 0.f, 0x1.fffffep-1f), (a < 0.f ? a + 2.f * kPi : a) / (2.f * kPi));
            p->y = std::min(p->y, 0x1.fffffep-1f);
            return true;
        },
        [](const Vec2&) { return 1.0; }, 200000, 10, 10);
    INFO(rd.report);
    CHECK(rd.pValue > alpha);
}

TEST_CASE("Environment map: the power is pi R^2 times the integrated luminance, and sampleLe estimates it", "[envmap]") {
    const MapScene ms(sunAndSkyMap(), Rgb(0.7f));
    const EnvironmentMap& map = ms.scene.environmentMaps[0];
    // Independent integral: luminance of each texel (as generated) times its solid angle, the
    // solid angle written out as 2 pi / w (cos theta_top - cos theta_bottom).
    double integral = 0.0;
    for (int r = 0; r < 32; ++r)
        for (int c = 0; c < 64; ++c) {
            const Rgb t = 0.7f * sunAndSky(c, r, 64, 32);
            integral += (0.2126 * t.r + 0.7152 * t.g + 0.0722 * t.b) * 2.0 * kPiD / 64.0 *
                        (std::cos(kPiD * r / 32.0) - std::cos(kPiD * (r + 1) / 32.0));
        }
    const double r2 = double(ms.light.sceneRadius) * double(ms.light.sceneRadius);
    const double power = lightPower(ms.light, ms.scene);
    CHECK(power == Approx(double(kPi) * r2 * integral).epsilon(1e-6));
    CHECK(map.integratedLuminance(Rgb(0.7f)) == Approx(integral).epsilon(1e-6));
    // Flux through the disk: E[luminance(Le) / (pdfPos pdfDir)] (cos = 1: the disk faces the
    // direction), within 5 standard errors plus float32 rounding of the densities (1e-5: the
    // density is proportional to luminance, so every sample gives almost exactly the power).
    const int n = 200000;
    double sum = 0.0, sumSq = 0.0;
    for (int i = 0; i < n; ++i) {
        TestRng rng(41, uint64_t(i));
        const Vec2 uPos = rng.uniform2D();
        LightLeSample s;
        REQUIRE(sampleLe(ms.light, ms.scene, uPos, rng.uniform2D(), &s));
        const double v = double(luminance(s.Le)) / (double(s.pdfPos) * double(s.pdfDir));
        sum += v;
        sumSq += v * v;
    }
    const double mean = sum / n, se = std::sqrt(std::max(0.0, sumSq / n - mean * mean) / n);
    CHECK(std::abs(mean - power) <= 5.0 * se + 1e-5 * power);

    // The constant environment: a light without a map is the 1x1 map of value 1.
    Light constant = ms.light;
    constant.envMap = -1;
    constant.emission = Rgb(1.f, 2.f, 3.f);
    CHECK(lightPower(constant) == Approx(double(luminance(constant.emission)) * 4.0 * kPiD * kPiD * r2).epsilon(1e-6));
    LightLiSample s;
    REQUIRE(sampleLi(constant, Vec3(0.f), Vec2(0.3f, 0.6f), &s));
    CHECK(s.pdf == kInv4Pi);
    CHECK(s.Li == constant.emission);
}
