// Tests of the KHR_materials_clearcoat layer (src/scene/bsdf_clearcoat.cpp, the layering in
// src/scene/bsdf.cpp; docs/materials.md "Clearcoat"):
//  * sample() realises pdf() (chi-square) for rough and delta coats over Lambert, rough metal,
//    rough and smooth glass, with the coat's normal equal to and tilted from the shading normal;
//  * sample() reports f() and pdf(); f() equals an independent transcription of the extension's
//    layering mix(base, coat_brdf, clearcoat F_c(|V.n_c|)) (the base from a Bsdf without coat);
//  * Importance mode is the adjoint: f(wi, wo) in Radiance mode times the shading-normal factor
//    (the layering is not reciprocal), for f() and for the delta coat's samples;
//  * furnaces: a white Lambert base under a delta coat reflects exactly 1 (what the coat takes
//    from the base it reflects); under a rough coat the albedo is (1 - cF(wo)) + the coat's
//    directional albedo, computed here by quadrature, within k = 5 standard errors.
// Chi-square tests REQUIRE p > sidakAlpha(0.01, kChi2Tests), kChi2Tests = 8 cases x 4 wo = 32.
#include "bdptref/bsdf.h"
#include "bdptref/sampling.h"
#include "support/bsdf_checks.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <string>
#include <vector>

using namespace bdptref;
using namespace bdptref::test;

namespace {

constexpr double kPiD = 3.14159265358979323846;
const Vec3 kNg = glm::normalize(Vec3(0.3f, -0.5f, 0.8f));
// A shading normal tilted ~21 degrees from ng (a base normal map) and a coat normal tilted the
// other way (a coat normal map); "untilted" cases use ng for all three.
const Vec3 kNsTilted = glm::normalize(Frame(kNg).toWorld(Vec3(0.35f, 0.15f, 1.f)));
const Vec3 kNcTilted = glm::normalize(Frame(kNg).toWorld(Vec3(-0.2f, 0.25f, 1.f)));

struct Case {
    std::string name;
    MaterialParams p;
    bool tilted;
    Vec3 ns() const { return tilted ? kNsTilted : kNg; }
    Vec3 nc() const { return tilted ? kNcTilted : kNg; }
};

MaterialParams coated(Rgb base, float metallic, float roughness, float coat, float coatRoughness) {
    MaterialParams p;
    p.baseColor = base;
    p.metallic = metallic;
    p.roughness = roughness;
    p.clearcoat = coat;
    p.clearcoatRoughness = coatRoughness;
    return p;
}

std::vector<Case> allCases() {
    std::vector<Case> c;
    MaterialParams lambert = coated(Rgb(0.7f, 0.3f, 0.2f), 0.f, 1.f, 1.f, 0.3f);
    lambert.specular = 0.f;
    c.push_back({"rough coat 0.3 over Lambert", lambert, false});
    c.push_back({"rough coat 0.1 (weight 0.7) over rough metal", coated(Rgb(0.9f, 0.6f, 0.5f), 1.f, 0.5f, 0.7f, 0.1f), false});
    c.push_back({"rough coat 0.2 over a glossy dielectric, tilted normals", coated(Rgb(0.2f, 0.5f, 0.8f), 0.f, 0.4f, 1.f, 0.2f), true});
    MaterialParams deltaCoat = lambert;
    deltaCoat.clearcoatRoughness = 0.f;
    c.push_back({"delta coat over Lambert", deltaCoat, false});
    Case tiltedDelta{"delta coat over a glossy dielectric, tilted normals", coated(Rgb(0.5f, 0.5f, 0.3f), 0.f, 0.5f, 0.8f, 0.f), true};
    c.push_back(tiltedDelta);
    MaterialParams roughGlass = coated(Rgb(1.f), 0.f, 0.3f, 1.f, 0.25f);
    roughGlass.transmission = 1.f;
    c.push_back({"rough coat 0.25 over rough glass", roughGlass, false});
    MaterialParams smoothGlass = roughGlass;
    smoothGlass.roughness = 0.f;
    c.push_back({"rough coat 0.25 over smooth glass", smoothGlass, false});
    MaterialParams blackBase = coated(Rgb(0.f), 0.f, 1.f, 1.f, 0.05f);
    blackBase.specular = 0.f;
    c.push_back({"narrow coat 0.05 over a black base", blackBase, true});
    return c;
}

Bsdf makeBsdf(const Case& c) {
    MaterialParams p = c.p;
    if (c.tilted) p.clearcoatNormal = c.nc();
    return Bsdf(p, c.ns(), kNg);
}

// The same material without its coat: the base the layering mixes with.
Bsdf baseOf(const Case& c) {
    MaterialParams p = c.p;
    p.clearcoat = 0.f;
    return Bsdf(p, c.ns(), kNg);
}

const float kWoTheta[4] = {0.f, 40.f, 75.f, 135.f};  // from the shading normal; 135: the back side
// The extension's coat, transcribed in double in world space with the spec's forms of D and V:
// clearcoat F_c(|V.Nc|) D V_smith |L.Nc| / |L.Ns| (the |L.Nc| / |L.Ns| converts to the integrators'
// cosine against Ns), for V = v, L = l on one side of ng and above Ns and Nc there.
double referenceCoat(const Case& c, const Vec3& vF, const Vec3& lF) {
    const glm::dvec3 ng(kNg), v = glm::normalize(glm::dvec3(vF)), l = glm::normalize(glm::dvec3(lF));
    const double gv = glm::dot(v, ng), gl = glm::dot(l, ng);
    if (!(gv * gl > 0.0)) return 0.0;
    const glm::dvec3 Ns = glm::normalize(glm::dvec3(c.ns())) * (gv > 0 ? 1.0 : -1.0);
    const glm::dvec3 Nc = glm::normalize(glm::dvec3(c.nc())) * (gv > 0 ? 1.0 : -1.0);
    const double NsV = glm::dot(Ns, v), NsL = glm::dot(Ns, l), NcV = glm::dot(Nc, v), NcL = glm::dot(Nc, l);
    if (!(NsV > 0 && NsL > 0 && NcV > 0 && NcL > 0)) return 0.0;
    const double r = c.p.clearcoatRoughness;
    const double alpha = std::max(r * r, 1e-4), a2 = alpha * alpha;
    const glm::dvec3 H = glm::normalize(v + l);
    const double NdotH = glm::dot(Nc, H);
    const double D = NdotH > 0.0 ? a2 / (kPiD * std::pow(NdotH * NdotH * (a2 - 1.0) + 1.0, 2.0)) : 0.0;
    auto g1 = [&](double NdotX) { return 2.0 * NdotX / (NdotX + std::sqrt(a2 + (1.0 - a2) * NdotX * NdotX)); };
    const double Vis = g1(NcV) * g1(NcL) / (4.0 * NcV * NcL);
    const double F = 0.04 + 0.96 * std::pow(1.0 - NcV, 5.0);
    return c.p.clearcoat * F * D * Vis * NcL / NsL;
}

double coatFresnel(const Case& c, const Vec3& v) {
    return 0.04 + 0.96 * std::pow(1.0 - std::min(1.0, std::abs(double(glm::dot(glm::dvec3(v), glm::normalize(glm::dvec3(c.nc())))))), 5.0);
}

// The layering, Radiance mode: (1 - clearcoat F_c(|wo.Nc|)) f_base(wo, wi) + coat(wo, wi).
Rgb referenceF(const Case& c, const Vec3& wo, const Vec3& wi) {
    const double scale = 1.0 - c.p.clearcoat * coatFresnel(c, wo);
    const Rgb base = baseOf(c).f(wo, wi, TransportMode::Radiance);
    return Rgb(glm::dvec3(base) * scale + glm::dvec3(c.p.clearcoatRoughness > 0.f ? referenceCoat(c, wo, wi) : 0.0));
}

constexpr int kChi2Tests = 8 * 4;
const double kChi2Alpha = sidakAlpha(0.01, kChi2Tests);

}  // namespace

TEST_CASE("Clearcoat: sample() realises pdf() (chi-square, rough and delta coats over every kind of base)",
          "[bsdf][clearcoat][chi2]") {
    const std::vector<Case> cases = allCases();
    REQUIRE(int(cases.size()) * 4 == kChi2Tests);
    int performed = 0;
    for (const Case& c : cases) {
        const Bsdf b = makeBsdf(c);
        for (float theta : kWoTheta) {
            const Vec3 wo = woAtAngle(c.ns(), theta);
            const bool front = glm::dot(wo, kNg) > 0.f;
            DirectionBinning bins;
            const float coatAlpha = c.p.clearcoatRoughness * c.p.clearcoatRoughness;
            if (c.p.clearcoatRoughness > 0.f && coatAlpha < 0.05f) {
                // A narrow coat lobe: log-spaced bins about its mirror direction.
                const Vec3 n = front ? c.nc() : -c.nc();
                bins.frame = Frame(glm::normalize(2.f * glm::dot(wo, n) * n - wo));
                bins.theta = ThetaBinning::LogOneMinusCos;
                bins.thetaBins = 14;
                bins.minOneMinusCos = 0.01 * double(coatAlpha) * double(coatAlpha);
            } else {
                bins.frame = Frame(front ? c.ns() : -c.ns());
                bins.thetaBins = 12;
            }
            bins.phiBins = 16;
            const Chi2Result r = bsdfSamplingChi2(b, wo, bins, 4321, 200000);
            INFO(c.name << ", wo theta " << theta << ": " << r.report);
            REQUIRE(r.pValue > kChi2Alpha);
            ++performed;
        }
    }
    CHECK(performed == kChi2Tests);
}

TEST_CASE("Clearcoat: sample() reports f() and pdf(), and f() is the extension's layering of the base and the coat",
          "[bsdf][clearcoat]") {
    for (const Case& c : allCases()) {
        const Bsdf b = makeBsdf(c);
        long sampled = 0, coatNonZero = 0;
        for (float theta : kWoTheta) {
            const Vec3 wo = woAtAngle(c.ns(), theta);
            for (int i = 0; i < 3000; ++i) {
                TestRng rng(81, uint64_t(i));
                const float uLobe = rng.uniform();
                const Vec2 u = rng.uniform2D();
                const std::string where = c.name + ", wo theta " + std::to_string(theta) + ", sample " + std::to_string(i);
                for (TransportMode mode : {TransportMode::Radiance, TransportMode::Importance}) {
                    BsdfSample s;
                    if (!b.sample(wo, uLobe, u, mode, &s) || s.delta) continue;
                    ++sampled;
                    REQUIRE_QUIET(s.pdf > 0.f, where);
                    REQUIRE_QUIET(std::abs(s.pdf - b.pdf(wo, s.wi)) <= 1e-4f * s.pdf, where);
                    REQUIRE_QUIET(closeRgb(s.f, b.f(wo, s.wi, mode), 1e-4f, 0.f), where);
                }
                // Arbitrary pairs (half across the surface) against the transcription.
                const Vec3 wi = squareToUniformSphere(rng.uniform2D());
                const Rgb f = b.f(wo, wi, TransportMode::Radiance), ref = referenceF(c, wo, wi);
                REQUIRE_QUIET(closeRgb(f, ref, 2e-4f, 1e-6f), where << ": f " << str(f) << ", reference " << str(ref));
                coatNonZero += referenceCoat(c, wo, wi) > 0.0;
            }
        }
        INFO(c.name);
        if (b.hasNonDelta()) CHECK(sampled > 0);
        if (c.p.clearcoatRoughness > 0.f) CHECK(coatNonZero > 100);  // the transcription saw the coat
    }
}

TEST_CASE("Clearcoat: Importance mode is the adjoint f(wi, wo) times the shading-normal factor, delta coat included",
          "[bsdf][clearcoat]") {
    for (const Case& c : allCases()) {
        if (c.p.transmission > 0.f) continue;  // refraction: the eta^2 rule is test_rough_dielectric's
        const Bsdf b = makeBsdf(c);
        long checked = 0, delta = 0;
        for (float theta : kWoTheta) {
            const Vec3 wo = woAtAngle(c.ns(), theta);
            for (int i = 0; i < 3000; ++i) {
                TestRng rng(56, uint64_t(i));
                const Vec3 wi = squareToUniformSphere(rng.uniform2D());
                const Rgb fi = b.f(wo, wi, TransportMode::Importance);
                const Rgb adj = b.f(wi, wo, TransportMode::Radiance) * float(adjointFactorOf(wo, wi, c.ns(), kNg));
                const std::string where = c.name + " theta " + std::to_string(theta) + " pair " + std::to_string(i);
                REQUIRE_QUIET(closeRgb(fi, adj, 2e-5f, 1e-7f), where << ": " << str(fi) << " vs " << str(adj));
                checked += !isBlack(fi);
                // The delta coat: the throughput f |wi.ns| in Importance mode is R_c |wi.ng| / |wo.ng|
                // (the mirror about n_c keeps solid angle, so only the geometric cosines remain).
                BsdfSample s;
                if (b.sample(wo, rng.uniform(), rng.uniform2D(), TransportMode::Importance, &s) && s.delta) {
                    const double R = c.p.clearcoat * coatFresnel(c, s.wi);
                    const double expected = R * absDot(s.wi, kNg) / absDot(wo, kNg);
                    const double got = double(s.f.g) * absDot(s.wi, c.ns());
                    REQUIRE_QUIET(std::abs(got - expected) <= 1e-5 * expected, where << ": " << got << " vs " << expected);
                    ++delta;
                }
            }
        }
        INFO(c.name);
        CHECK(checked > 0);
        if (c.p.clearcoatRoughness == 0.f) CHECK(delta > 100);
    }
}

namespace {
// E[f |wi.ns| / pdf] over sample() (failures count 0) and its standard error, per channel.
void albedo(const Bsdf& b, const Vec3& wo, int n, glm::dvec3* mean, glm::dvec3* se) {
    glm::dvec3 s(0.0), s2(0.0);
    for (int i = 0; i < n; ++i) {
        TestRng rng(17, uint64_t(i));
        const float uLobe = rng.uniform();
        const Vec2 u = rng.uniform2D();
        BsdfSample bs;
        if (!b.sample(wo, uLobe, u, TransportMode::Radiance, &bs)) continue;
        const glm::dvec3 w = glm::dvec3(bs.f) * double(absDot(bs.wi, b.shadingNormal())) / double(bs.pdf);
        s += w;
        s2 += w * w;
    }
    *mean = s / double(n);
    *se = glm::sqrt(glm::max(s2 / double(n) - *mean * *mean, glm::dvec3(0.0)) / double(n));
}

// The rough coat's directional albedo for wo (ns = nc = ng): the integral of referenceCoat times
// |wi.n| over the hemisphere, by a midpoint rule in (theta, phi) with 800 x 400 cells (0.002 rad
// in theta, far finer than the lobes of alpha >= 0.16 used here).
double coatAlbedoQuadrature(const Case& c, const Vec3& wo) {
    const Frame f(kNg);
    const int nt = 800, np = 400;
    double sum = 0.0;
    for (int i = 0; i < nt; ++i) {
        const double theta = 0.5 * kPiD * (i + 0.5) / nt, cosT = std::cos(theta), sinT = std::sin(theta);
        for (int k = 0; k < np; ++k) {
            const double phi = 2.0 * kPiD * (k + 0.5) / np;
            const Vec3 wi = f.toWorld(Vec3(float(sinT * std::cos(phi)), float(sinT * std::sin(phi)), float(cosT)));
            sum += referenceCoat(c, wo, wi) * cosT * sinT;
        }
    }
    return sum * (0.5 * kPiD / nt) * (2.0 * kPiD / np);
}
}  // namespace

TEST_CASE("Clearcoat: furnaces: a white Lambert base under a delta coat reflects 1, under a rough coat 1 - cF + the coat's albedo",
          "[bsdf][clearcoat][furnace]") {
    MaterialParams white = coated(Rgb(1.f), 0.f, 1.f, 1.f, 0.f);
    white.specular = 0.f;
    for (float theta : {0.f, 50.f, 80.f}) {
        const Vec3 wo = woAtAngle(kNg, theta);
        {   // delta coat: (1 - cF) * 1 + cF = 1 at every wo, exactly (every sample weighs 1).
            const Case c{"delta", white, false};
            glm::dvec3 m, se;
            albedo(makeBsdf(c), wo, 20000, &m, &se);
            INFO("theta " << theta << ": " << m.x << " +- " << se.x);
            CHECK(std::abs(m.x - 1.0) <= 1e-5);
            CHECK(se.x <= 1e-5);
        }
        for (float roughness : {0.4f, 0.7f}) {
            MaterialParams p = white;
            p.clearcoatRoughness = roughness;
            const Case c{"rough", p, false};
            const double expected = 1.0 - coatFresnel(c, wo) + coatAlbedoQuadrature(c, wo);
            glm::dvec3 m, se;
            albedo(makeBsdf(c), wo, 400000, &m, &se);
            INFO("theta " << theta << ", coat roughness " << roughness << ": " << m.x << " +- " << se.x << ", quadrature "
                          << expected);
            CHECK(std::abs(m.x - expected) <= 5.0 * se.x);
            CHECK(m.x <= 1.0 + 5.0 * se.x);  // the layering conserves energy
        }
    }
}

TEST_CASE("Clearcoat: the coat adds a non-delta lobe only when rough", "[bsdf][clearcoat]") {
    // A delta coat over smooth glass has no non-delta lobe; a rough one has.
    MaterialParams glass = allCases()[6].p;
    glass.clearcoatRoughness = 0.f;
    CHECK_FALSE(Bsdf::hasNonDelta(glass));
    glass.clearcoatRoughness = 0.2f;
    CHECK(Bsdf::hasNonDelta(glass));
    CHECK(Bsdf(glass, kNg, kNg).hasNonDelta());
}
