// Light sampling: every density a sampler reports equals the one its pdf function gives, and
// every sampler is an unbiased estimator of the quantity it is for (checked against an
// independent estimator or a closed form within k = 5 standard errors).
#include "bdptref/light.h"
#include "bdptref/rng.h"
#include "bdptref/sampling.h"

#include <catch2/catch.hpp>

using namespace bdptref;

namespace {

Light areaLight(bool twoSided) {
    Light l;
    l.type = LightType::Area;
    l.v0 = Vec3(-1, 2, -1);
    l.v1 = Vec3(1.5f, 2.2f, -0.5f);
    l.v2 = Vec3(0, 1.8f, 1.2f);
    const Vec3 c = glm::cross(l.v1 - l.v0, l.v2 - l.v0);
    l.normal = glm::normalize(c);
    l.area = 0.5f * glm::length(c);
    l.emission = Rgb(2.f, 1.f, 0.5f);
    l.twoSided = twoSided;
    l.power = lightPower(l);
    return l;
}

Light punctual(LightType t) {
    Light l;
    l.type = t;
    l.position = Vec3(0.3f, 1.f, -0.2f);
    l.direction = glm::normalize(Vec3(0.2f, -1.f, 0.1f));
    l.cosInner = std::cos(0.3f);
    l.cosOuter = std::cos(0.6f);
    l.emission = Rgb(3.f);
    l.sceneCenter = Vec3(0.f, 0.5f, 0.f);
    l.sceneRadius = 2.5f;
    return l;
}

Vec2 rand2(uint32_t seed, uint64_t i, uint32_t d) { return PixelSampler(seed, 0, i).get2D(RngStream::Light, d); }

struct MeanSe { double mean, se; };
template <class F> MeanSe estimate(int n, F f) {
    double s = 0, s2 = 0;
    for (int i = 0; i < n; ++i) {
        const double v = f(i);
        s += v;
        s2 += v * v;
    }
    const double m = s / n;
    return {m, std::sqrt(std::max(0.0, s2 / n - m * m) / n)};
}

// Ray-triangle intersection (Moller-Trumbore) for the independent estimator.
bool hitsTriangle(const Light& l, const Vec3& o, const Vec3& d) {
    const Vec3 e1 = l.v1 - l.v0, e2 = l.v2 - l.v0, p = glm::cross(d, e2);
    const float det = glm::dot(e1, p);
    if (std::abs(det) < 1e-12f) return false;
    const Vec3 t = o - l.v0;
    const float u = glm::dot(t, p) / det;
    const Vec3 q = glm::cross(t, e1);
    const float v = glm::dot(d, q) / det;
    return u >= 0 && v >= 0 && u + v <= 1 && glm::dot(e2, q) / det > 0;
}

}  // namespace

TEST_CASE("Area light: sampleLi's density equals pdfLi, and it estimates irradiance without bias", "[lights]") {
    for (bool twoSided : {false, true}) {
        const Light l = areaLight(twoSided);
        for (const Vec3 ref : {Vec3(0.1f, 0.f, 0.2f), Vec3(0.3f, 3.f, 0.f)}) {
            const Vec3 n = Vec3(0, 1, 0) * (ref.y > 2.f ? -1.f : 1.f);  // a receiver facing the light plane
            // Irradiance with sampleLi (light sampling) ...
            const MeanSe a = estimate(200000, [&](int i) {
                LightLiSample s;
                if (!sampleLi(l, ref, rand2(1, uint64_t(i), 0), &s)) return 0.0;
                CHECK(s.pdf == Approx(pdfLi(l, ref, s.pLight, s.nLight)).epsilon(1e-4));
                return double(s.Li.r) * std::max(0.f, glm::dot(n, s.wi)) / double(s.pdf);
            });
            // ... and with uniform directions that have to hit the triangle (independent).
            const MeanSe b = estimate(400000, [&](int i) {
                const Vec3 w = squareToUniformSphere(rand2(2, uint64_t(i), 0));
                if (glm::dot(n, w) <= 0.f || !hitsTriangle(l, ref, w)) return 0.0;
                return double(emittedRadiance(l, -w).r) * double(glm::dot(n, w)) / double(uniformSpherePdf());
            });
            INFO("twoSided " << twoSided << " ref.y " << ref.y << ": " << a.mean << " +- " << a.se << " vs " << b.mean << " +- " << b.se);
            if (!twoSided && ref.y > 2.f) {
                CHECK(a.mean == 0.0);  // behind a one-sided emitter: nothing
                CHECK(b.mean == 0.0);
            } else {
                CHECK(b.mean > 0.0);
                CHECK(std::abs(a.mean - b.mean) < 5.0 * std::hypot(a.se, b.se));
            }
        }
    }
}

TEST_CASE("sampleLe's densities equal pdfLe's for every light type", "[lights]") {
    std::vector<Light> lights = {areaLight(false), areaLight(true), punctual(LightType::Point),
                                 punctual(LightType::Spot), punctual(LightType::Directional)};
    Light env = punctual(LightType::Environment);
    lights.push_back(env);
    for (const Light& l : lights) {
        for (int i = 0; i < 2000; ++i) {
            LightLeSample s;
            if (!sampleLe(l, rand2(3, uint64_t(i), 1), rand2(3, uint64_t(i), 2), &s)) continue;
            float pp, pd;
            pdfLe(l, s.ray.origin, s.ray.dir, s.nLight, &pp, &pd);
            INFO("light type " << int(l.type));
            CHECK(glm::length(s.ray.dir) == Approx(1.f).epsilon(1e-5));
            CHECK(s.pdfPos == Approx(pp).epsilon(1e-5));
            if (!isDeltaDirection(l)) CHECK(s.pdfDir == Approx(pd).epsilon(1e-5));
        }
    }
}

TEST_CASE("sampleLe estimates each light's emitted flux", "[lights]") {
    // Flux = integral over positions and directions of Le |cos| (area), of I (point/spot),
    // E * (disk area) for the directional light. The estimator Le |cos| / (pdfPos pdfDir) must
    // match the closed forms: pi A Le (one-sided), 2 pi A Le (two-sided), 4 pi I,
    // 2 pi I * integral of the glTF spot falloff, E pi R^2.
    auto flux = [](const Light& l) {
        return estimate(200000, [&](int i) {
            LightLeSample s;
            if (!sampleLe(l, rand2(4, uint64_t(i), 1), rand2(4, uint64_t(i), 2), &s)) return 0.0;
            const double cosTerm = l.type == LightType::Area ? std::abs(glm::dot(s.nLight, s.ray.dir)) : 1.0;
            return double(s.Le.r) * cosTerm / (double(s.pdfPos) * double(s.pdfDir));
        });
    };
    for (bool twoSided : {false, true}) {
        const Light l = areaLight(twoSided);
        const MeanSe m = flux(l);
        const double exact = kPi * l.area * l.emission.r * (twoSided ? 2.0 : 1.0);
        CHECK(std::abs(m.mean - exact) < 5 * m.se + 1e-6 * exact);
    }
    {
        const Light l = punctual(LightType::Point);
        CHECK(flux(l).mean == Approx(4.0 * kPi * 3.0).epsilon(1e-5));  // exact: constant integrand
    }
    {
        const Light l = punctual(LightType::Spot);
        // 2 pi * integral over cos in [cosOuter, 1] of falloff(cos): midpoint rule, 1e5 steps.
        double integral = 0;
        const int steps = 100000;
        for (int k = 0; k < steps; ++k) {
            const double c = l.cosOuter + (1.0 - l.cosOuter) * (k + 0.5) / steps;
            const double scale = 1.0 / std::max(0.001, double(l.cosInner - l.cosOuter));
            const double a = std::clamp(c * scale - l.cosOuter * scale, 0.0, 1.0);
            integral += a * a * (1.0 - l.cosOuter) / steps;
        }
        const double exact = 2.0 * kPi * 3.0 * integral;
        const MeanSe m = flux(l);
        CHECK(std::abs(m.mean - exact) < 5 * m.se + 1e-4 * exact);
    }
    {
        const Light l = punctual(LightType::Directional);
        CHECK(flux(l).mean == Approx(3.0 * kPi * 2.5 * 2.5).epsilon(1e-5));
    }
}

TEST_CASE("Delta lights: sampleLi gives intensity / distance^2 and the spot cone", "[lights]") {
    const Light p = punctual(LightType::Point);
    const Vec3 ref(1.f, -1.f, 0.5f);
    LightLiSample s;
    REQUIRE(sampleLi(p, ref, Vec2(0.5f), &s));
    const float d2 = glm::dot(p.position - ref, p.position - ref);
    CHECK(s.delta);
    CHECK(s.Li.r == Approx(3.f / d2));
    CHECK(pdfLi(p, ref, s.pLight, s.nLight) == 0.f);  // a delta light cannot be hit

    const Light spot = punctual(LightType::Spot);
    REQUIRE(sampleLi(spot, spot.position + spot.direction * 2.f, Vec2(0.5f), &s));  // on the axis
    CHECK(s.Li.r == Approx(3.f / 4.f));
    const Vec3 outside = spot.position + Frame(spot.direction).toWorld(Vec3(std::sin(0.7f), 0, std::cos(0.7f)));
    CHECK_FALSE(sampleLi(spot, outside, Vec2(0.5f), &s));  // beyond the outer cone

    const Light dir = punctual(LightType::Directional);
    REQUIRE(sampleLi(dir, ref, Vec2(0.5f), &s));
    CHECK(glm::dot(s.wi, -dir.direction) == Approx(1.f));
    CHECK(s.Li.r == Approx(3.f));
}

TEST_CASE("LightSampler chooses lights in proportion to power", "[lights]") {
    std::vector<Light> lights = {areaLight(false), punctual(LightType::Point), punctual(LightType::Spot)};
    for (Light& l : lights) l.power = lightPower(l);
    const LightSampler sampler(lights);
    double total = 0;
    for (const Light& l : lights) total += l.power;
    std::vector<int> counts(lights.size(), 0);
    const int n = 100000;
    for (int i = 0; i < n; ++i) {
        float pmf;
        const int k = sampler.sample(PixelSampler(6, 0, uint64_t(i)).get1D(RngStream::Light, 0), &pmf);
        REQUIRE(k >= 0);
        CHECK(pmf == Approx(lights[size_t(k)].power / total).epsilon(1e-5));
        ++counts[size_t(k)];
    }
    for (size_t k = 0; k < lights.size(); ++k) {
        const double p = lights[k].power / total;
        // Binomial count: mean n p, standard deviation sqrt(n p (1-p)); k = 5.
        CHECK(std::abs(counts[k] - n * p) < 5 * std::sqrt(n * p * (1 - p)));
    }
    // No lights, or only zero-power lights: nothing can be chosen.
    float pmf = 1.f;
    CHECK(LightSampler(std::vector<Light>{}).sample(0.3f, &pmf) == -1);
    CHECK(pmf == 0.f);
}

// ---- Chi-square tests of the light samplers' directions (family-wise alpha 1% over the
// kLightChi2Tests tests below, Šidák-corrected).
#include "support/chi2.h"

namespace {
constexpr int kLightChi2Tests = 5;
}

TEST_CASE("Chi-square: area light sampleLi directions follow pdfLi", "[lights][chi2]") {
    // pdfLi is a solid-angle density; converted to the triangle's area (times |cos_light| / d^2)
    // and then to the smooth coordinates (b0, s = b1 / (1 - b0)) on the unit square
    // (dA = 2 area (1 - b0) db0 ds), it must describe where sampleLi puts its points.
    const double alpha = test::sidakAlpha(0.01, kLightChi2Tests);
    for (bool twoSided : {false, true}) {
        const Light l = areaLight(twoSided);
        const Vec3 ref(0.2f, 0.4f, 0.1f);
        auto toBary = [&](const Vec3& p) {  // barycentrics of p w.r.t. (v0, v1, v2): weights of v0, v1
            const Vec3 e1 = l.v0 - l.v2, e2 = l.v1 - l.v2, q = p - l.v2;
            const float d11 = glm::dot(e1, e1), d12 = glm::dot(e1, e2), d22 = glm::dot(e2, e2);
            const float q1 = glm::dot(q, e1), q2 = glm::dot(q, e2), det = d11 * d22 - d12 * d12;
            return Vec2((d22 * q1 - d12 * q2) / det, (d11 * q2 - d12 * q1) / det);
        };
        const auto r = test::chi2Test2D(
            [&](uint64_t i, Vec2* out) {
                LightLiSample s;
                if (!sampleLi(l, ref, test::TestRng(10, i).uniform2D(), &s)) return false;
                const Vec2 b = toBary(s.pLight);
                *out = Vec2(glm::clamp(b.x, 0.f, 1.f), b.x < 1.f ? glm::clamp(b.y / (1.f - b.x), 0.f, 1.f) : 0.f);
                return true;
            },
            [&](const Vec2& c) {
                const float b0 = c.x, b1 = c.y * (1.f - c.x);
                const Vec3 p = b0 * l.v0 + b1 * l.v1 + (1.f - b0 - b1) * l.v2;
                const Vec3 d = p - ref;
                const float dist2 = glm::dot(d, d);
                const double cosLight = std::abs(glm::dot(l.normal, d)) / std::sqrt(dist2);
                return double(pdfLi(l, ref, p, l.normal)) * cosLight / dist2 * 2.0 * l.area * (1.0 - b0);
            },
            200000, 16, 16);
        INFO("twoSided " << twoSided << "\n" << r.report);
        CHECK(r.pValue > alpha);
    }
}

TEST_CASE("Chi-square: emission directions of area, spot and environment lights", "[lights][chi2]") {
    const double alpha = test::sidakAlpha(0.01, kLightChi2Tests);
    const Light area = areaLight(true), env = punctual(LightType::Environment);
    for (const Light* l : {&area, &env}) {
        test::DirectionBinning b;
        b.frame = Frame(l->normal);
        const auto r = test::chi2DirectionTest(
            [&](uint64_t i, Vec3* d) {
                test::TestRng rng(11, i);
                LightLeSample s;
                const Vec2 up = rng.uniform2D();
                if (!sampleLe(*l, up, rng.uniform2D(), &s)) return false;
                *d = s.ray.dir;
                return true;
            },
            [&](const Vec3& d) {
                float pp, pd;
                pdfLe(*l, Vec3(0.f), d, l->normal, &pp, &pd);
                return double(pd);
            },
            200000, b);
        INFO("light type " << int(l->type) << "\n" << r.report);
        CHECK(r.pValue > alpha);
    }
    // Spot: its cone has a sharp edge, so test in the smooth coordinates of the cone
    // (a = (1 - cos) / (1 - cosOuter), b = phi / 2 pi), where pdfLe * (1 - cosOuter) 2 pi is the density.
    const Light spot = punctual(LightType::Spot);
    const Frame f(spot.direction);
    const auto r = test::chi2Test2D(
        [&](uint64_t i, Vec2* out) {
            test::TestRng rng(12, i);
            LightLeSample s;
            const Vec2 up = rng.uniform2D();
            if (!sampleLe(spot, up, rng.uniform2D(), &s)) return false;
            const Vec3 loc = f.toLocal(s.ray.dir);
            float phi = std::atan2(loc.y, loc.x);
            if (phi < 0.f) phi += 2.f * kPi;
            *out = Vec2(glm::clamp((1.f - loc.z) / (1.f - spot.cosOuter), 0.f, 1.f), phi / (2.f * kPi));
            return true;
        },
        [&](const Vec2& c) {
            const float cosT = 1.f - c.x * (1.f - spot.cosOuter), sinT = safeSqrt(1.f - cosT * cosT);
            const float phi = 2.f * kPi * c.y;
            float pp, pd;
            pdfLe(spot, spot.position, f.toWorld(Vec3(sinT * std::cos(phi), sinT * std::sin(phi), cosT)), Vec3(0.f), &pp, &pd);
            return double(pd) * (1.0 - spot.cosOuter) * 2.0 * kPi;
        },
        200000, 16, 16);
    INFO("spot\n" << r.report);
    CHECK(r.pValue > alpha);
}
