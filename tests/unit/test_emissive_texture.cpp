// Emissive textures on area lights (docs/lights.md, "Emissive textures"): the loader builds
// emission = emissiveFactor * strength * emissiveTexture (sRGB); sampleLi / sampleLe return the
// sampled point's barycentrics and the radiance there; positions stay uniform by area (chi-square
// against pdfLi / pdfLe); known answers: a textured emitter seen directly shows each texel's
// radiance, and the irradiance from a large textured emitter equals the texture integrated
// numerically here (independently of Texture::lookup); light power for selection is positive
// wherever the texture can emit.
#include "support/chi2.h"
#include "support/gltf_builder.h"
#include "support/render_util.h"

#include "bdptref/gltf_loader.h"
#include "bdptref/integrator.h"
#include "bdptref/light.h"
#include "bdptref/renderer.h"
#include "bdptref/scene.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <stdexcept>

using namespace bdptref;
using namespace bdptref::test;

namespace {

constexpr double kPiD = 3.14159265358979323846;

// The sRGB transfer function (IEC 61966-2-1), written out here so the expected values do not come
// from the code under test.
double srgbDecode(int v) {
    const double c = v / 255.0;
    return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

// A 2 x 2 emitter at z = 0 facing +z, uv (0, 0) at its top-left corner (-1, 1), textured with
// `texels` (RGB, w x h, nearest filtering), emissive factor `factor` times strength 3.
constexpr double kStrength = 3.0;
const std::array<double, 3> kFactor = {1.0, 0.8, 0.5};

Scene emitterScene(int w, int h, const std::vector<uint16_t>& texels, int width, int height, bool withFloor = false) {
    Doc d;
    const int tex = pngTexture(d, w, h, 3, texels, true);
    const int mat = d.lambert({0, 0, 0}, kFactor, kStrength);
    d.j["materials"][size_t(mat)]["emissiveTexture"] = {{"index", tex}};
    texturedQuad(d, {{{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}}}, {{{0, 1}, {1, 1}, {1, 0}, {0, 0}}}, mat);
    if (withFloor) d.quad({-1, -1, 2}, {-1, 1, 2}, {1, 1, 2}, {1, -1, 2}, d.lambert({0.5, 0.5, 0.5}));
    LoadOptions o;
    o.width = width;
    o.height = height;
    Scene s = loadGltfScene(d.write("emissive-texture.gltf"), o);
    s.camera = Camera::lookAt(Vec3(0, 0, 1), Vec3(0, 0, 0), Vec3(0, 1, 0), 0.5f * kPi, width, height);
    s.finalize();
    return s;
}

// Radiance of texel (i, j) of an RGB texel list, from the file's bytes.
DVec3 texelRadiance(const std::vector<uint16_t>& texels, int w, int i, int j) {
    DVec3 r;
    for (int c = 0; c < 3; ++c) r[c] = kFactor[size_t(c)] * kStrength * srgbDecode(texels[size_t((j * w + i) * 3 + c)]);
    return r;
}

// 4 x 4 texels: black and bright ones, and some colours.
const std::vector<uint16_t> kTexels4 = {
    255, 255, 255, 0,   0,   0,   200, 40,  10,  0,  0,  0,   //
    0,   0,   0,   90,  180, 255, 0,   0,   0,   30, 30, 30,  //
    128, 128, 128, 0,   0,   0,   255, 220, 160, 0,  0,  0,   //
    0,   0,   0,   10,  250, 20,  0,   0,   0,   64, 64, 200,
};

}  // namespace

TEST_CASE("Emissive texture: the loader builds textured area lights and their emission at a point", "[lights][emissive-texture]") {
    const Scene s = emitterScene(4, 4, kTexels4, 8, 8);
    REQUIRE(s.lights.size() == 2);  // two triangles, no environment
    for (const Light& l : s.lights) {
        CHECK(l.type == LightType::Area);
        REQUIRE(l.emissiveTexture.valid());
        CHECK(l.power > 0.0);
    }
    // The centre of texel (2, 1) is at uv (0.625, 0.375): position (0.25, 0.25, 0), in the second
    // triangle (0, 2, 3). Its barycentrics there, and the emission = factor * strength * texel.
    const Light& l = s.lights[1];
    const Vec3 target = s.toRender(DVec3(0.25, 0.25, 0.0));
    const Vec2 bary = s.barycentricsOf(l.triangle, target);
    const Rgb e = areaEmission(l, s.textures, bary);
    const DVec3 expect = texelRadiance(kTexels4, 4, 2, 1);
    for (int c = 0; c < 3; ++c) CHECK(double(e[c]) == Approx(expect[c]).epsilon(1e-5));
    CHECK(isBlack(areaEmission(l, s.textures, s.barycentricsOf(l.triangle, s.toRender(DVec3(-0.25, 0.75, 0.0))))));  // texel (1, 0)
    // emittedRadiance / lightEmission: the same value on the front, zero behind (one-sided).
    CHECK(emittedRadiance(l, s.textures, bary, Vec3(0, 0, 1)) == e);
    CHECK(lightEmission(l, s.textures, bary, Vec3(0.6f, 0, 0.8f)) == e);
    CHECK(isBlack(emittedRadiance(l, s.textures, bary, Vec3(0, 0, -1))));
    // Without the scene's textures a textured light cannot be evaluated: an internal error, not a
    // silently untextured light.
    CHECK_THROWS_AS(areaEmission(l, {}, bary), std::logic_error);
    CHECK_THROWS_AS(lightPower(l), std::logic_error);
}

TEST_CASE("Emissive texture: sampleLi and sampleLe return the point's barycentrics and the radiance there", "[lights][emissive-texture]") {
    const Scene s = emitterScene(4, 4, kTexels4, 8, 8);
    const Vec3 ref = s.toRender(DVec3(0.1, -0.2, 0.7));
    int nonBlack = 0, black = 0;
    for (const Light& l : s.lights)
        for (uint64_t i = 0; i < 2000; ++i) {
            TestRng rng(31, i);
            LightLiSample li;
            REQUIRE(sampleLi(l, s.textures, ref, rng.uniform2D(), &li));
            const Vec3 p = (1.f - li.bary.x - li.bary.y) * l.v0 + li.bary.x * l.v1 + li.bary.y * l.v2;
            CHECK(glm::length(p - li.pLight) <= 1e-5f);
            CHECK(li.Li == areaEmission(l, s.textures, li.bary));
            (isBlack(li.Li) ? black : nonBlack)++;
            LightLeSample le;
            REQUIRE(sampleLe(l, s.textures, rng.uniform2D(), rng.uniform2D(), &le));
            const Vec3 q = (1.f - le.bary.x - le.bary.y) * l.v0 + le.bary.x * l.v1 + le.bary.y * l.v2;
            CHECK(glm::length(q - le.ray.origin) <= 1e-5f);
            CHECK(le.Le == areaEmission(l, s.textures, le.bary));
        }
    // Half the texels are black: both kinds of points are drawn (the radiance really varies).
    CHECK(black > 1000);
    CHECK(nonBlack > 1000);
}

namespace {
constexpr int kEmissiveChi2Tests = 2;
}

TEST_CASE("Chi-square: sampleLi and sampleLe positions on an emissive-textured light follow pdfLi and pdfLe",
          "[lights][emissive-texture][chi2]") {
    // As test_lights.cpp: the point in smooth coordinates (b0, s = b1 / (1 - b0)) of the unit
    // square, where dA = 2 area (1 - b0) db0 ds; pdfLi (solid angle) times |cos_light| / d^2 and
    // pdfLe's pdfPos (area) are the densities the sampler must follow.
    const double alpha = sidakAlpha(0.01, kEmissiveChi2Tests);
    const Scene s = emitterScene(4, 4, kTexels4, 8, 8);
    const Light& l = s.lights[0];
    const Vec3 ref = s.toRender(DVec3(0.3, 0.2, 0.4));
    // Barycentrics (b1, b2) -> (b0, s).
    auto toSquare = [](Vec2 b) {
        const float b0 = 1.f - b.x - b.y;
        return Vec2(glm::clamp(b0, 0.f, 1.f), b0 < 1.f ? glm::clamp(b.x / (1.f - b0), 0.f, 1.f) : 0.f);
    };
    auto pointAt = [&](const Vec2& c) {
        const float b0 = c.x, b1 = c.y * (1.f - c.x);
        return b0 * l.v0 + b1 * l.v1 + (1.f - b0 - b1) * l.v2;
    };
    const auto li = chi2Test2D(
        [&](uint64_t i, Vec2* out) {
            LightLiSample ls;
            if (!sampleLi(l, s.textures, ref, TestRng(40, i).uniform2D(), &ls)) return false;
            *out = toSquare(ls.bary);
            return true;
        },
        [&](const Vec2& c) {
            const Vec3 p = pointAt(c), d = p - ref;
            const float dist2 = glm::dot(d, d);
            const double cosLight = std::abs(glm::dot(l.normal, d)) / std::sqrt(dist2);
            return double(pdfLi(l, ref, p, l.normal)) * cosLight / dist2 * 2.0 * l.area * (1.0 - c.x);
        },
        200000, 16, 16);
    INFO(li.report);
    CHECK(li.pValue > alpha);
    const auto le = chi2Test2D(
        [&](uint64_t i, Vec2* out) {
            TestRng rng(41, i);
            LightLeSample ls;
            const Vec2 uPos = rng.uniform2D();
            if (!sampleLe(l, s.textures, uPos, rng.uniform2D(), &ls)) return false;
            *out = toSquare(ls.bary);
            return true;
        },
        [&](const Vec2& c) {
            float pdfPos = 0.f, pdfDir = 0.f;
            pdfLe(l, pointAt(c), l.normal, l.normal, &pdfPos, &pdfDir);
            return double(pdfPos) * 2.0 * l.area * (1.0 - c.x);
        },
        200000, 16, 16);
    INFO(le.report);
    CHECK(le.pValue > alpha);
}

TEST_CASE("Emissive texture: a textured emitter seen directly shows each texel's radiance (PT)", "[lights][emissive-texture][render]") {
    // The camera at (0, 0, 1) with a 90 degree field of view sees exactly the 2 x 2 emitter; with
    // 8 x 8 pixels and a 4 x 4 nearest-filtered texture every pixel lies inside one texel, so its
    // value is that texel's radiance exactly (every sample hits the same texel; no other light).
    const Scene s = emitterScene(4, 4, kTexels4, 8, 8);
    const Film f = renderFilm(s, "path", 4, 1, 5);
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) {
            const DVec3 expect = texelRadiance(kTexels4, 4, x / 2, y / 2);  // raster row 0 = top = texel row 0
            const DVec3 got = f.mean(x, y);
            INFO("pixel " << x << "," << y);
            for (int c = 0; c < 3; ++c) CHECK(got[c] == Approx(expect[c]).epsilon(1e-5).margin(1e-7));
        }
}

TEST_CASE("Emissive texture: next-event irradiance from a textured emitter equals the integrated texture", "[lights][emissive-texture]") {
    // E(r) = sum over texels of Le(texel) * integral over its square of cos_r cos_l / d^2 dA, the
    // integral by the midpoint rule on a 64 x 64 grid per texel (relative error ~1e-4 for a
    // receiver at height 0.5 over texels of size 0.5: the integrand's second derivative over the
    // cell size squared / 24). The Monte Carlo estimate from sampleLi (all light triangles) must
    // agree within 5 standard errors plus that quadrature bound.
    const Scene s = emitterScene(4, 4, kTexels4, 8, 8);
    const DVec3 refWorld(0.2, 0.1, 0.5);
    const Vec3 ref = s.toRender(refWorld);
    const Vec3 n(0, 0, -1);  // the receiver faces the emitter
    DVec3 exact(0.0);
    constexpr int kGrid = 64;
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
            double g = 0.0;
            for (int b = 0; b < kGrid; ++b)
                for (int a = 0; a < kGrid; ++a) {
                    const double x = -1.0 + 0.5 * (i + (a + 0.5) / kGrid), y = 1.0 - 0.5 * (j + (b + 0.5) / kGrid);
                    const DVec3 d = DVec3(x, y, 0.0) - refWorld;
                    const double d2 = glm::dot(d, d), cosR = -d.z / std::sqrt(d2), cosL = cosR;
                    g += cosR * cosL / d2 * (0.25 / (kGrid * kGrid));
                }
            exact += texelRadiance(kTexels4, 4, i, j) * g;
        }
    constexpr uint64_t kN = 400000;
    DVec3 sum(0.0), sumSq(0.0);
    for (uint64_t k = 0; k < kN; ++k) {
        DVec3 e(0.0);
        for (const Light& l : s.lights) {
            LightLiSample ls;
            if (!sampleLi(l, s.textures, ref, TestRng(50 + uint64_t(&l - s.lights.data()), k).uniform2D(), &ls)) continue;
            e += DVec3(ls.Li.r, ls.Li.g, ls.Li.b) * (std::max(0.0, double(glm::dot(n, ls.wi))) / double(ls.pdf));
        }
        sum += e;
        sumSq += e * e;
    }
    const DVec3 mean = sum / double(kN);
    const DVec3 se = glm::sqrt((sumSq / double(kN) - mean * mean) / double(kN - 1));
    for (int c = 0; c < 3; ++c) {
        INFO("channel " << c << ": Monte Carlo " << mean[c] << " +- " << se[c] << ", integrated " << exact[c]);
        CHECK(std::abs(mean[c] - exact[c]) <= 5.0 * se[c] + 1e-4 * exact[c]);
        CHECK(se[c] < 0.01 * exact[c]);  // not vacuous: the estimate is precise
    }
}

TEST_CASE("Emissive texture: light power is the texture's mean over the triangle, floored where it can emit",
          "[lights][emissive-texture]") {
    // A constant texture: power = pi * area * luminance(Le) exactly as for an untextured light.
    {
        const Scene s = emitterScene(1, 1, {255, 128, 0}, 8, 8);
        const Rgb le = s.lights[0].emission * Rgb(float(srgbDecode(255)), float(srgbDecode(128)), float(srgbDecode(0)));
        const double y = 0.2126 * double(le.r) + 0.7152 * double(le.g) + 0.0722 * double(le.b);
        for (const Light& l : s.lights) CHECK(l.power == Approx(kPiD * double(l.area) * y).epsilon(1e-5));
    }
    // A triangle whose 64 fixed points all land on black texels but that emits near one corner:
    // texture 8 x 1 (texel 4 white, the others black), the triangle's uvs reach u = 0.5001 at one
    // vertex only, so it emits on a sliver (b1 > 0.9998) that no grid point reaches. Its power
    // must still be positive (the floor: 1e-3 of the largest value its texels can give), or light
    // tracing would never start there.
    std::vector<uint16_t> texels(8 * 3, 0);
    for (int c = 0; c < 3; ++c) texels[size_t(4 * 3 + c)] = 255;
    const Scene s = emitterScene(8, 1, texels, 8, 8);
    Light l = s.lights[0];
    l.uv0 = Vec2(0.f, 0.5f);
    l.uv1 = Vec2(0.5001f, 0.5f);
    l.uv2 = Vec2(0.f, 0.5f);
    const double yWhite = 0.2126 * kFactor[0] * kStrength + 0.7152 * kFactor[1] * kStrength + 0.0722 * kFactor[2] * kStrength;
    CHECK(isBlack(areaEmission(l, s.textures, Vec2(0.5f, 0.25f))));  // dark almost everywhere ...
    CHECK(!isBlack(areaEmission(l, s.textures, Vec2(1.f, 0.f))));   // ... but not at v1
    CHECK(lightPower(l, s.textures) == Approx(1e-3 * yWhite * kPiD * double(l.area)).epsilon(1e-5));
    // An all-black region of the texture (texels 7, 0, 1, 2 with the one-texel margin and the
    // repeat wrap): the triangle cannot emit and gets power 0.
    l.uv1 = Vec2(0.2f, 0.5f);
    CHECK(lightPower(l, s.textures) == 0.0);
}
