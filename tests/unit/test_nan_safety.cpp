// Every table lookup and sampling routine is safe for NaN, +-Inf and huge inputs (issue 29;
// docs/hard-cases.md, "NaN-safe lookups"). Each routine is fed those values and must return a
// result in its range, never read outside a table (the sanitizer build checks the reads):
//  * a direction that is no direction (NaN, infinite, zero) has value 0 and density 0 (BSDFs,
//    lights, the environment map, the camera), and the direction between coincident vertices is
//    the zero vector, whose densities are 0;
//  * a table lookup with a NaN argument returns a finite value in the table's range (the sheen
//    albedo: 0), +-Inf the table's edge;
//  * a sampling routine given a NaN number fails (Distribution1D: pmf 0) or, for the warps,
//    treats it as 0: the point returned is always in the warp's domain; a BSDF or light sample is
//    either rejected or finite with a positive finite density.
// The random numbers of a render are in [0, 1) and the directions unit vectors: the clamps leave
// them unchanged, so no image changes (the chi-square and bit-identity tests hold that).
#include "bdptref/bsdf.h"
#include "bdptref/camera.h"
#include "bdptref/env_map.h"
#include "bdptref/light.h"
#include "bdptref/material.h"
#include "bdptref/rng.h"
#include "bdptref/sampling.h"
#include "render/bdpt_vertex.h"
#include "scene/bsdf_sheen.h"
#include "scene/bsdf_terms.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

using namespace bdptref;

namespace {

constexpr float kNan = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();
const std::vector<float> kBadNumbers = {kNan, kInf, -kInf, 1e30f, -1e30f, std::numeric_limits<float>::max()};

// Random numbers with at least one bad component (and the good value 0.5 in the other).
std::vector<Vec2> badPairs() {
    std::vector<Vec2> out;
    for (float b : kBadNumbers) {
        out.push_back(Vec2(b, 0.5f));
        out.push_back(Vec2(0.5f, b));
        out.push_back(Vec2(b, b));
    }
    return out;
}

// Directions that are none: NaN, infinite, zero, and a NaN in one component only.
std::vector<Vec3> badDirections() {
    return {Vec3(kNan), Vec3(kNan, 0.f, 1.f), Vec3(0.f), Vec3(kInf, 0.f, 0.f), Vec3(-kInf, kInf, 1.f)};
}

bool unit(const Vec3& w) { return isFinite(w) && std::abs(glm::length(w) - 1.f) < 1e-4f; }
bool finitePositive(float p) { return std::isfinite(p) && p > 0.f; }

MaterialParams layered(bool coat, bool transmission) {
    MaterialParams p;
    p.baseColor = Rgb(0.6f, 0.5f, 0.4f);
    p.roughness = 0.5f;
    p.sheenColor = Rgb(0.9f, 0.8f, 0.7f);
    p.sheenRoughness = 0.3f;
    if (coat) {
        p.clearcoat = 0.7f;
        p.clearcoatRoughness = 0.2f;
    }
    if (transmission) p.transmission = 1.f;
    return p;
}

}  // namespace

TEST_CASE("NaN-safe: the sheen albedo table", "[nan-safe][sheen]") {
    using bsdf_detail::sheenAlbedo;
    // The table's largest value bounds every interpolated one (bilinear in ln E).
    float largest = 0.f;
    for (int j = 0; j < bsdf_detail::kTableRoughness; ++j)
        for (int i = 0; i < bsdf_detail::kTableMu; ++i) largest = std::max(largest, std::exp(bsdf_detail::sheenLogAlbedoNode(i, j)));
    for (float mu : {kNan, kInf, -kInf, 1e30f, -1e30f, 0.f, 0.5f, 1.f})
        for (float r : {kNan, kInf, -kInf, 1e30f, -1e30f, 0.f, 0.5f, 1.f}) {
            const float e = sheenAlbedo(mu, r);
            INFO("mu " << mu << ", roughness " << r << ": E " << e);
            CHECK(std::isfinite(e));
            CHECK(e >= 0.f);
            CHECK(e <= largest);
            if (std::isnan(mu) || std::isnan(r)) CHECK(e == 0.f);
        }
    // +-Inf are the table's edges.
    CHECK(sheenAlbedo(kInf, 0.5f) == sheenAlbedo(1.f, 0.5f));
    CHECK(sheenAlbedo(-kInf, 0.5f) == sheenAlbedo(0.f, 0.5f));
    CHECK(sheenAlbedo(0.5f, kInf) == sheenAlbedo(0.5f, 1.f));
}

TEST_CASE("NaN-safe: the sampling warps stay in their domains", "[nan-safe][sampling]") {
    for (const Vec2 u : badPairs()) {
        INFO("u = (" << u.x << ", " << u.y << ")");
        const Vec2 d = squareToConcentricDisk(u);
        CHECK((std::isfinite(d.x) && std::isfinite(d.y) && glm::length(d) <= 1.f + 1e-6f));
        CHECK(unit(squareToUniformSphere(u)));
        const Vec3 h = squareToCosineHemisphere(u);
        CHECK((unit(h) && h.z >= 0.f));
        const float cosMax = std::cos(0.3f);
        const Vec3 c = squareToUniformCone(u, cosMax);
        CHECK((unit(c) && c.z >= cosMax - 1e-6f));
        const Vec2 b = squareToUniformTriangle(u);
        CHECK((b.x >= 0.f && b.y >= 0.f && b.x + b.y <= 1.f + 1e-6f));
        // GGX visible normals: a unit half vector above the surface.
        const glm::dvec3 m = bsdf_detail::sampleGgxVndf(glm::normalize(glm::dvec3(0.3, 0.1, 0.9)), 0.2, double(u.x), double(u.y));
        CHECK((std::isfinite(m.x) && std::isfinite(m.y) && std::isfinite(m.z) && m.z >= 0.0));
        CHECK(std::abs(glm::length(m) - 1.0) < 1e-9);
    }
}

TEST_CASE("NaN-safe: Distribution1D and light selection", "[nan-safe][sampling]") {
    const Distribution1D dist({0.0, 2.0, 0.0, 1.0, 0.0});
    for (float u : kBadNumbers) {
        INFO("u = " << u);
        float pmf = -1.f, remapped = -1.f;
        const size_t i = dist.sample(u, &pmf, &remapped);
        CHECK(i < dist.size());
        CHECK(std::isfinite(pmf));
        CHECK(pmf == dist.pmf(i));  // a chosen index is reported with its own probability, or 0
        CHECK((remapped >= 0.f && remapped < 1.f));
        if (std::isnan(u)) CHECK(pmf == 0.f);  // a failed sample
    }
    const std::vector<Light> lights(3);
    const LightSampler sampler([&] {
        std::vector<Light> l = lights;
        for (size_t k = 0; k < l.size(); ++k) l[k].power = double(k + 1);
        return l;
    }());
    float pmf = -1.f;
    sampler.sample(kNan, &pmf);
    CHECK(pmf == 0.f);
    for (float u : {kInf, -kInf, 1e30f}) {
        const int i = sampler.sample(u, &pmf);
        CHECK((i >= 0 && i < 3));
        CHECK(pmf == sampler.pmf(i));
    }
}

TEST_CASE("NaN-safe: environment map lookup, density and sampling", "[nan-safe][envmap]") {
    std::vector<Rgb> texels;
    for (int k = 0; k < 5 * 3; ++k) texels.push_back(Rgb(float(k + 1), 0.5f, float(k % 4)));
    for (float rotation : {0.f, 0.7f}) {
        const EnvironmentMap map(5, 3, texels, rotation);
        for (const Vec3& w : badDirections()) {
            INFO("w = (" << w.x << ", " << w.y << ", " << w.z << "), rotation " << rotation);
            CHECK(map.lookup(w) == Rgb(0.f));
            CHECK(map.pdf(w) == 0.f);
            int col = -1, row = -1;
            map.texelOf(w, &col, &row);
            CHECK((col >= 0 && col < 5 && row >= 0 && row < 3));
        }
        for (const Vec2 u : badPairs()) {
            Vec3 w;
            float pdf = -1.f;
            if (map.sample(u, &w, &pdf)) {
                CHECK(unit(w));
                CHECK(finitePositive(pdf));
                CHECK(pdf == map.pdf(w));
            } else {
                CHECK(pdf == 0.f);
            }
        }
    }
}

TEST_CASE("NaN-safe: light emission, densities and sampling", "[nan-safe][lights]") {
    Light area;
    area.type = LightType::Area;
    area.v0 = Vec3(-1, 2, -1);
    area.v1 = Vec3(1.5f, 2.2f, -0.5f);
    area.v2 = Vec3(0, 1.8f, 1.2f);
    const Vec3 c = glm::cross(area.v1 - area.v0, area.v2 - area.v0);
    area.normal = glm::normalize(c);
    area.area = 0.5f * glm::length(c);
    area.emission = Rgb(2.f, 1.f, 0.5f);
    std::vector<Light> lights = {area, area};
    lights[1].twoSided = true;
    for (LightType t : {LightType::Point, LightType::Spot, LightType::Directional, LightType::Environment}) {
        Light l;
        l.type = t;
        l.position = Vec3(0.3f, 1.f, -0.2f);
        l.direction = glm::normalize(Vec3(0.2f, -1.f, 0.1f));
        l.cosInner = std::cos(0.3f);
        l.cosOuter = std::cos(0.6f);
        l.emission = Rgb(3.f);
        l.sceneCenter = Vec3(0.f, 0.5f, 0.f);
        l.sceneRadius = 2.5f;
        lights.push_back(l);
    }
    for (const Light& l : lights) {
        INFO("light type " << int(l.type) << (l.twoSided ? " (two-sided)" : ""));
        for (const Vec3& w : badDirections()) {
            INFO("w = (" << w.x << ", " << w.y << ", " << w.z << ")");
            const Rgb e = lightEmission(l, w);
            CHECK(isFinite(e));
            float pdfPos = -1.f, pdfDir = -1.f;
            pdfLe(l, Vec3(0.f), w, l.type == LightType::Area ? l.normal : Vec3(0.f), &pdfPos, &pdfDir);
            CHECK((std::isfinite(pdfPos) && std::isfinite(pdfDir) && pdfPos >= 0.f && pdfDir >= 0.f));
            // A NaN or zero direction is emitted into with no radiance and no density, except by
            // the lights whose emission does not depend on it (the point light's density is
            // uniform, the directional light's a Dirac).
            const bool nanOrZero = std::isnan(w.x) || w == Vec3(0.f);
            if (nanOrZero && l.type != LightType::Point) CHECK(pdfDir == 0.f);
            if (nanOrZero && l.type != LightType::Point && l.type != LightType::Directional) CHECK(isBlack(e));
            if (l.type == LightType::Area || l.type == LightType::Environment) CHECK(pdfDir == 0.f);
        }
        for (const Vec2 u : badPairs()) {
            LightLeSample le;
            if (sampleLe(l, u, u, &le)) {
                CHECK(isFinite(le.ray.origin));
                CHECK(unit(le.ray.dir));
                CHECK((finitePositive(le.pdfPos) && finitePositive(le.pdfDir)));
                CHECK(isFinite(le.Le));
            }
            LightLiSample li;
            if (sampleLi(l, Vec3(0.1f, 0.2f, 0.3f), u, &li)) {
                CHECK(unit(li.wi));
                CHECK(finitePositive(li.pdf));
                CHECK(isFinite(li.Li));
            }
        }
        // A reference point that is no point.
        for (const Vec3& ref : badDirections()) {
            if (ref == Vec3(0.f)) continue;  // a valid point
            LightLiSample li;
            if (sampleLi(l, ref, Vec2(0.3f, 0.6f), &li)) {
                CHECK(unit(li.wi));
                CHECK(finitePositive(li.pdf));
            }
        }
    }
}

TEST_CASE("NaN-safe: texture lookups of NaN, infinite and huge uv in every wrap mode", "[nan-safe][texture]") {
    // Sizes that are not powers of two, so that the wrap's period is not exact in binary.
    std::vector<Vec4> texels;
    for (int j = 0; j < 5; ++j)
        for (int i = 0; i < 3; ++i) texels.push_back(Vec4(float(i), float(j), 1.f, 1.f));
    for (Texture::Wrap wrap : {Texture::Wrap::Repeat, Texture::Wrap::MirroredRepeat, Texture::Wrap::ClampToEdge})
        for (bool nearest : {false, true}) {
            Texture t = Texture::fromLinear(3, 5, texels);
            t.wrapS = t.wrapT = wrap;
            t.nearest = nearest;
            for (const Vec2 uv : badPairs()) {
                INFO("uv (" << uv.x << ", " << uv.y << "), wrap " << int(wrap) << (nearest ? ", nearest" : ""));
                const Vec4 v = t.lookup(uv);
                CHECK((v.x >= 0.f && v.x <= 2.f && v.y >= 0.f && v.y <= 4.f && std::abs(v.z - 1.f) < 1e-6f));
            }
        }
}

TEST_CASE("NaN-safe: layered BSDFs give 0 for no direction and never a bad sample", "[nan-safe][bsdf][sheen]") {
    const Vec3 ng = glm::normalize(Vec3(0.3f, -0.5f, 0.8f));
    const Vec3 ns = glm::normalize(Frame(ng).toWorld(Vec3(0.2f, 0.1f, 1.f)));
    const Vec3 good = glm::normalize(ng + Vec3(0.2f, 0.f, 0.f)), good2 = glm::normalize(ng - Vec3(0.f, 0.3f, 0.f));
    struct Named { std::string name; MaterialParams p; };
    std::vector<Named> materials = {{"sheen over GGX dielectric", layered(false, false)},
                                    {"coat over sheen", layered(true, false)},
                                    {"sheen over rough glass", layered(false, true)},
                                    {"coat over sheen over smooth glass", layered(true, true)}};
    materials[3].p.roughness = 0.f;
    MaterialParams lambert;
    lambert.specular = 0.f;
    materials.push_back({"Lambert", lambert});
    for (const Named& m : materials) {
        const Bsdf bsdf(m.p, ns, ng);
        for (TransportMode mode : {TransportMode::Radiance, TransportMode::Importance}) {
            INFO(m.name << (mode == TransportMode::Radiance ? ", radiance" : ", importance"));
            for (const Vec3& bad : badDirections())
                for (bool badIsWo : {true, false}) {
                    const Vec3 wo = badIsWo ? bad : good, wi = badIsWo ? good : bad;
                    CHECK(bsdf.f(wo, wi, mode) == Rgb(0.f));
                    CHECK(bsdf.pdf(wo, wi) == 0.f);
                    float pdf = -1.f;
                    CHECK(bsdf.evaluate(wo, wi, mode, &pdf) == Rgb(0.f));
                    CHECK(pdf == 0.f);
                    float ab = -1.f, ba = -1.f;
                    bsdf.pdfBothWays(wo, wi, &ab, &ba);
                    CHECK((ab == 0.f && ba == 0.f));
                    BsdfSample s;
                    CHECK_FALSE(bsdf.sample(bad, 0.3f, Vec2(0.4f, 0.6f), mode, &s));
                }
            CHECK(bsdf.pdf(good, good2) > 0.f);  // the directions above are valid ones
            std::vector<std::pair<float, Vec2>> numbers;
            for (float b : kBadNumbers) {
                numbers.push_back({b, Vec2(0.4f, 0.6f)});
                for (const Vec2 u : badPairs()) numbers.push_back({0.3f, u});
                numbers.push_back({b, Vec2(b)});
            }
            for (const auto& [uLobe, u] : numbers) {
                BsdfSample s;
                if (!bsdf.sample(good, uLobe, u, mode, &s)) continue;
                INFO("uLobe " << uLobe << ", u (" << u.x << ", " << u.y << ")");
                CHECK(unit(s.wi));
                CHECK(finitePositive(s.pdf));
                CHECK(isFinite(s.f));
            }
        }
    }
}

TEST_CASE("NaN-safe: coincident vertices have the zero direction and zero densities", "[nan-safe][mis]") {
    PathVertex a, b;
    a.p = b.p = Vec3(0.25f, -1.f, 3.f);
    a.ng = a.ns = b.ng = b.ns = Vec3(0.f, 1.f, 0.f);
    CHECK(directionTo(a, b) == Vec3(0.f));
    CHECK(convertDensity(1.0, a, b) == 0.0);
    b.p = Vec3(kNan);
    CHECK(directionTo(a, b) == Vec3(0.f));
    b.p = Vec3(1e30f, -1e30f, 1e30f);  // a squared distance that overflows float
    CHECK(directionTo(a, b) == Vec3(0.f));
    b.p = a.p + Vec3(0.f, 1.f, 0.f);  // a valid pair is unaffected
    CHECK(directionTo(a, b) == Vec3(0.f, 1.f, 0.f));
}

TEST_CASE("NaN-safe: camera importance of no direction is 0", "[nan-safe][camera]") {
    const Camera cam = Camera::lookAt(Vec3(0, 0, 3), Vec3(0), Vec3(0, 1, 0), 0.8f, 16, 12);
    for (const Vec3& w : badDirections()) {
        Vec2 raster(-1.f);
        CHECK(cam.We(w, &raster) == 0.f);
        float pdfPos = -1.f, pdfDir = -1.f;
        cam.pdfWe(w, &pdfPos, &pdfDir);
        CHECK((pdfPos == 0.f && pdfDir == 0.f));
        if (w == Vec3(0.f)) continue;
        CameraImportanceSample s;
        CHECK_FALSE(cam.sampleWi(w, &s));  // a reference point that is no point
    }
}
