// Tests of the rough dielectric (GGX microfacet reflection + refraction, Walter et al. 2007) of a
// transmissive material with roughness > 0 (src/scene/bsdf_rough_dielectric.cpp,
// docs/materials.md "Rough transmission").
//
// Statistical tests: every chi-square test REQUIREs p > sidakAlpha(0.01, kChi2Tests) with
// kChi2Tests = 48 (4 materials x 6 wo x reflection/refraction; a 1% family-wise false-failure rate for the file). Monte Carlo albedos are
// compared with the quadrature within k = 5 standard errors estimated from the same samples.
// All seeds are fixed.
//
// Conventions tested (derivation in docs/materials.md): eta_o is the IOR on wo's side, eta_i on
// the refracted wi's side.
//  * Importance form f_I(wo, wi) = |wo.h||wi.h| / (|cos_o||cos_i|) eta_i^2 (1 - F) D G1 G1 / den^2,
//    den = eta_o wo.h + eta_i wi.h; Radiance f_R = (eta_o / eta_i)^2 f_I.
//  * Adjointness: f_I(wo, wi) = f_R(wi, wo) (ns = ng).
//  * Generalised reciprocity: f_R(wo, wi) / eta_o^2 = f_R(wi, wo) / eta_i^2.
#include "bdptref/bsdf.h"
#include "bdptref/sampling.h"
#include "support/chi2.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

using namespace bdptref;
using test::TestRng;

namespace {

constexpr int kChi2Tests = 48;
const double kChi2Alpha = test::sidakAlpha(0.01, kChi2Tests);
constexpr double kPiD = 3.14159265358979323846;
constexpr double kSigmas = 5.0;

const Vec3 kNg = glm::normalize(Vec3(0.3f, -0.5f, 0.8f));
const Vec3 kNsTilted = glm::normalize(Frame(kNg).toWorld(Vec3(0.25f, 0.1f, 1.f)));

MaterialParams roughGlass(float roughness, float ior = 1.5f) {
    MaterialParams p;
    p.baseColor = Rgb(1.f);
    p.metallic = 0.f;
    p.roughness = roughness;
    p.transmission = 1.f;
    p.ior = ior;
    return p;
}

// wo at polar angle theta from n (theta > 90: on the back side, i.e. inside), azimuth 200 degrees.
Vec3 woFor(const Vec3& n, double thetaDeg) {
    const double t = thetaDeg * kPiD / 180.0, ph = 200.0 * kPiD / 180.0;
    if (thetaDeg == 0.0) return n;
    return glm::normalize(Frame(n).toWorld(Vec3(float(std::sin(t) * std::cos(ph)), float(std::sin(t) * std::sin(ph)), float(std::cos(t)))));
}

// Exact unpolarised Fresnel (Hecht's angle form, independent of the code's cosine form).
double referenceFresnel(double cosI, double etaI, double etaT) {
    const double ti = std::acos(std::min(1.0, cosI));
    const double sinT = etaI / etaT * std::sin(ti);
    if (sinT >= 1.0) return 1.0;
    if (ti < 1e-9) return std::pow((etaT - etaI) / (etaT + etaI), 2.0);
    const double tt = std::asin(sinT);
    const double rs = std::pow(std::sin(ti - tt) / std::sin(ti + tt), 2.0);
    const double rp = std::pow(std::tan(ti - tt) / std::tan(ti + tt), 2.0);
    return 0.5 * (rs + rp);
}

// An independent transcription of Walter et al. 2007 (eqs. 20-21, GGX D eq. 33, Smith G1 eq. 34)
// for a white lossless glass (F exact), in double and world space, in its own notation: i is the
// direction the light arrives from (our wi in Radiance mode), o the outgoing one (our wo),
// eta_i / eta_o their IORs; radiance form (eq. 21's eta_o^2 numerator).
double walterF(const glm::dvec3& nIn, double alpha, double ior, const glm::dvec3& oIn, const glm::dvec3& iIn) {
    // Unit in double: float unit vectors are ~1e-7 off, which would move D by percents at narrow lobes.
    const glm::dvec3 n0 = glm::normalize(nIn), o = glm::normalize(oIn), i = glm::normalize(iIn);
    const glm::dvec3 n = glm::dot(o, n0) > 0.0 ? n0 : -n0;  // o's side
    const bool outside = glm::dot(o, n0) > 0.0;
    const double etaO = outside ? 1.0 : ior, etaI = outside ? ior : 1.0;
    const double a2 = alpha * alpha;
    auto D = [&](const glm::dvec3& m) {
        const double c = glm::dot(m, n);
        if (c <= 0.0) return 0.0;
        const double t2 = (1.0 - c * c) / (c * c);
        return a2 / (kPiD * std::pow(c, 4.0) * std::pow(a2 + t2, 2.0));
    };
    auto G1 = [&](const glm::dvec3& v, const glm::dvec3& m) {
        const double c = glm::dot(v, n);
        if (glm::dot(v, m) / c <= 0.0) return 0.0;
        const double t2 = (1.0 - c * c) / (c * c);
        return 2.0 / (1.0 + std::sqrt(1.0 + a2 * t2));
    };
    if (glm::dot(i, n) > 0.0) {  // reflection, eq. 20
        const glm::dvec3 hr = glm::normalize(i + o);
        const double F = referenceFresnel(std::abs(glm::dot(i, hr)), etaO, etaI);
        return F * G1(i, hr) * G1(o, hr) * D(hr) / (4.0 * std::abs(glm::dot(i, n)) * std::abs(glm::dot(o, n)));
    }
    // refraction, eq. 21: h_t = -(eta_i i + eta_o o), oriented to o's side
    glm::dvec3 ht = glm::normalize(-(etaI * i + etaO * o));
    if (glm::dot(ht, n) < 0.0) ht = -ht;
    if (!(glm::dot(o, ht) > 0.0 && glm::dot(i, ht) < 0.0)) return 0.0;
    const double F = referenceFresnel(std::abs(glm::dot(o, ht)), etaO, etaI);
    const double den = etaI * glm::dot(i, ht) + etaO * glm::dot(o, ht);
    return std::abs(glm::dot(i, ht)) * std::abs(glm::dot(o, ht)) / (std::abs(glm::dot(i, n)) * std::abs(glm::dot(o, n))) *
           etaO * etaO * (1.0 - F) * G1(i, ht) * G1(o, ht) * D(ht) / (den * den);
}

// Directional albedo (Importance form: reflectance + transmittance of flux) of a single rough
// interface of white lossless glass, by quadrature over the microfacet normals, independent of
// the BSDF code: albedo = integral over h of D_wo(h) [F(h) G1(wr) + (1 - F(h)) G1(wt)] where
// D_wo(h) = G1(wo) max(0, wo.h) D(h) / cos_o is the distribution of visible normals, wr and wt the
// mirror and refracted directions about h (G1(wt) with the wt side's orientation). The integral
// uses the GGX CDF substitution xi = tan^2 / (alpha^2 + tan^2): D (n.h) d(omega_h) = dxi dphi / 2 pi,
// then xi = 1 - s^2 (dxi = 2 s ds), which removes the integrable 1/sqrt(1 - xi) growth of
// (wo.h)/(n.h) at grazing microfacets, so that the midpoint rule converges at its normal rate.
double quadratureAlbedo(double alpha, double ior, double cosO, bool outside, int nXi = 600, int nPhi = 600) {
    const double etaO = outside ? 1.0 : ior, etaI = outside ? ior : 1.0;
    const glm::dvec3 o(std::sqrt(std::max(0.0, 1.0 - cosO * cosO)), 0.0, cosO);
    const double a2 = alpha * alpha;
    auto G1 = [&](const glm::dvec3& v) {
        const double c = std::abs(v.z);
        if (c == 0.0) return 0.0;
        const double t2 = (1.0 - c * c) / (c * c);
        return 2.0 / (1.0 + std::sqrt(1.0 + a2 * t2));
    };
    const double g1o = G1(o);
    double sum = 0.0;
    for (int a = 0; a < nXi; ++a) {
        const double sv = (a + 0.5) / nXi, xi = 1.0 - sv * sv;
        const double tanT = alpha * std::sqrt(xi) / sv;
        const double cosT = 1.0 / std::sqrt(1.0 + tanT * tanT), sinT = tanT * cosT;
        for (int b = 0; b < nPhi; ++b) {
            const double phi = 2.0 * kPiD * (b + 0.5) / nPhi;
            const glm::dvec3 h(sinT * std::cos(phi), sinT * std::sin(phi), cosT);
            const double oh = glm::dot(o, h);
            if (oh <= 0.0) continue;
            const double F = referenceFresnel(oh, etaO, etaI);
            const glm::dvec3 wr = 2.0 * oh * h - o;
            double value = wr.z > 0.0 ? F * G1(wr) : 0.0;
            if (F < 1.0) {
                const double e = etaO / etaI, k = 1.0 - e * e * (1.0 - oh * oh);
                const glm::dvec3 wt = -e * o + (e * oh - std::sqrt(k)) * h;
                if (wt.z < 0.0) value += (1.0 - F) * G1(wt);
            }
            // weight of the cell: D (n.h) dOmega = dxi dphi / 2pi; integrand D_wo / D / (n.h) = G1(o) oh / (cosO cosT)
            sum += 2.0 * sv * value * g1o * oh / (cosO * cosT);
        }
    }
    return sum / (double(nXi) * double(nPhi));
}

struct Albedo {
    double mean = 0.0, sigma = 0.0;
};
// E[f |cos(wi, ns)| / pdf] over sample() (green channel), failures counting 0.
Albedo monteCarloAlbedo(const Bsdf& b, const Vec3& wo, TransportMode mode, int n, uint64_t seed) {
    double s = 0.0, s2 = 0.0;
    for (int k = 0; k < n; ++k) {
        TestRng rng(seed, uint64_t(k));
        const float uLobe = rng.uniform();
        const Vec2 u = rng.uniform2D();
        BsdfSample bs;
        if (!b.sample(wo, uLobe, u, mode, &bs)) continue;
        const double w = double(bs.f.g) * double(absDot(bs.wi, b.shadingNormal())) / double(bs.pdf);
        s += w;
        s2 += w * w;
    }
    Albedo a;
    a.mean = s / n;
    a.sigma = std::sqrt(std::max(0.0, s2 / n - a.mean * a.mean) / n);
    return a;
}

// Refracted direction about n (eta = eta_o / eta_i); false under TIR.
bool refractAbout(const Vec3& wo, const Vec3& n, double eta, Vec3* wt) {
    const double c = glm::dot(glm::dvec3(wo), glm::dvec3(n));
    const double k = 1.0 - eta * eta * (1.0 - c * c);
    if (k <= 0.0) return false;
    *wt = Vec3(glm::normalize(-eta * glm::dvec3(wo) + (eta * c - std::sqrt(k)) * glm::dvec3(n)));
    return true;
}

}  // namespace

TEST_CASE("Rough dielectric: sample() realises pdf() (chi-square, roughness 0.05 0.3 0.8, both sides, grazing)",
          "[bsdf][rough-dielectric][chi2]") {
    struct Config {
        std::string name;
        MaterialParams p;
        bool tilted;
    };
    std::vector<Config> configs;
    for (float r : {0.05f, 0.3f, 0.8f}) configs.push_back({"glass roughness " + std::to_string(r), roughGlass(r), false});
    MaterialParams mixed = roughGlass(0.3f, 1.33f);  // transmission 0.5 with a diffuse base, tinted
    mixed.transmission = 0.5f;
    mixed.baseColor = Rgb(0.9f, 0.6f, 0.4f);
    configs.push_back({"transmission 0.5 with diffuse, tilted shading normal", mixed, true});
    // wo angles from the shading normal: outside normal, oblique, grazing; inside normal,
    // oblique beyond the critical angle (41.8 degrees for ior 1.5), grazing.
    const double thetas[6] = {0.0, 45.0, 85.0, 180.0, 130.0, 95.0};
    int performed = 0;
    for (const Config& c : configs) {
        const Vec3 ns = c.tilted ? kNsTilted : kNg;
        const Bsdf b(c.p, ns, kNg);
        for (double theta : thetas) {
            const Vec3 wo = woFor(ns, theta);
            const bool outside = glm::dot(wo, kNg) > 0.f;
            const Vec3 nSide = outside ? ns : -ns;
            const double eta = outside ? 1.0 / c.p.ior : c.p.ior;
            const float alpha = c.p.roughness * c.p.roughness;
            // Reflection and refraction are tested separately (samples of the other kind count as
            // lost, and so does the other kind's pdf mass), each binned in log(1 - cos) about its
            // own macro direction: one binning cannot resolve two narrow lobes far apart.
            for (const bool refraction : {false, true}) {
                test::DirectionBinning bins;
                Vec3 centre = glm::normalize(2.f * glm::dot(wo, nSide) * nSide - wo);
                bins.theta = test::ThetaBinning::LogOneMinusCos;
                bins.thetaBins = 16;
                bins.phiBins = 16;
                bins.minOneMinusCos = 0.01 * double(alpha) * double(alpha);
                if (refraction && !refractAbout(wo, nSide, eta, &centre)) {
                    // Total internal reflection about the macro normal: the refracted part comes
                    // only from tilted microfacets; bins uniform in cos about -n.
                    centre = -nSide;
                    bins.theta = test::ThetaBinning::UniformCos;
                    bins.thetaBins = 20;
                }
                bins.frame = Frame(centre);
                const auto isRefraction = [&](const Vec3& d) { return glm::dot(d, kNg) * glm::dot(wo, kNg) < 0.f; };
                const test::Chi2Result r = test::chi2DirectionTest(
                    [&](uint64_t i, Vec3* d) {
                        TestRng rng(4321, i);
                        const float uLobe = rng.uniform();
                        const Vec2 u = rng.uniform2D();
                        BsdfSample s;
                        if (!b.sample(wo, uLobe, u, TransportMode::Radiance, &s) || s.delta) return false;
                        if (isRefraction(s.wi) != refraction) return false;
                        *d = s.wi;
                        return true;
                    },
                    [&](const Vec3& d) { return isRefraction(d) == refraction ? double(b.pdf(wo, d)) : 0.0; }, 100000, bins);
                INFO(c.name << ", wo theta " << theta << (refraction ? ", refraction" : ", reflection") << ": " << r.report);
                REQUIRE(r.pValue > kChi2Alpha);
                ++performed;
            }
        }
    }
    CHECK(performed == kChi2Tests);
}

TEST_CASE("Rough dielectric: sample() reports f() and pdf(), f matches Walter et al. 2007, weights bounded",
          "[bsdf][rough-dielectric]") {
    for (float roughness : {0.05f, 0.3f, 0.8f}) {
        for (float ior : {1.5f, 1.33f}) {
            const MaterialParams p = roughGlass(roughness, ior);
            const Bsdf b(p, kNg, kNg);
            const double alpha = double(roughness) * double(roughness);
            long transmissions = 0, reflections = 0;
            for (double theta : {0.0, 30.0, 60.0, 85.0, 180.0, 160.0, 130.0, 95.0}) {
                const Vec3 wo = woFor(kNg, theta);
                for (uint64_t k = 0; k < 2000; ++k) {
                    TestRng rng(99, k);
                    const float uLobe = rng.uniform();
                    const Vec2 u = rng.uniform2D();
                    BsdfSample s, si;
                    if (!b.sample(wo, uLobe, u, TransportMode::Radiance, &s)) continue;
                    REQUIRE(b.sample(wo, uLobe, u, TransportMode::Importance, &si));
                    REQUIRE(si.wi == s.wi);
                    REQUIRE(!s.delta);
                    const bool transmitted = glm::dot(s.wi, kNg) * glm::dot(wo, kNg) < 0.f;
                    REQUIRE(s.transmission == transmitted);
                    (transmitted ? transmissions : reflections) += 1;
                    // sample() reports exactly f() and pdf() of its direction.
                    REQUIRE(s.f == b.f(wo, s.wi, TransportMode::Radiance));
                    REQUIRE(si.f == b.f(wo, s.wi, TransportMode::Importance));
                    REQUIRE(s.pdf == b.pdf(wo, s.wi));
                    // f equals the independent transcription of Walter et al.
                    const double ref = walterF(glm::dvec3(kNg), std::max(alpha, 1e-4), ior, glm::dvec3(wo), glm::dvec3(s.wi));
                    INFO("roughness " << roughness << " ior " << ior << " theta " << theta << " f " << s.f.g << " ref " << ref);
                    REQUIRE(std::abs(double(s.f.g) - ref) <= 2e-4 * ref + 1e-7);
                    // Importance-mode weight of white lossless glass = G1(wi) <= 1 (flux conserved).
                    const double w = double(si.f.g) * double(absDot(si.wi, kNg)) / double(si.pdf);
                    REQUIRE(w <= 1.0 + 1e-5);
                    REQUIRE(w > 0.0);
                }
            }
            CHECK(transmissions > 1000);
            CHECK(reflections > 100);
        }
    }
}

TEST_CASE("Rough dielectric: Importance is Radiance without (eta_o/eta_i)^2, adjoint and generalised reciprocity",
          "[bsdf][rough-dielectric]") {
    for (float roughness : {0.05f, 0.3f, 0.8f}) {
        const float ior = 1.5f;
        const Bsdf b(roughGlass(roughness, ior), kNg, kNg);
        int checkedT = 0, checkedR = 0;
        for (uint64_t k = 0; k < 4000; ++k) {
            TestRng rng(7, k);
            const Vec3 wo = Vec3(squareToUniformSphere(rng.uniform2D()));
            BsdfSample s;
            if (!b.sample(wo, rng.uniform(), rng.uniform2D(), TransportMode::Radiance, &s)) continue;
            const Vec3 wi = s.wi;
            const bool outside = glm::dot(wo, kNg) > 0.f;
            const bool transmitted = glm::dot(wi, kNg) * glm::dot(wo, kNg) < 0.f;
            const double etaO = outside ? 1.0 : ior, etaI = transmitted == outside ? ior : 1.0;
            const double fR = b.f(wo, wi, TransportMode::Radiance).g, fI = b.f(wo, wi, TransportMode::Importance).g;
            const double fRrev = b.f(wi, wo, TransportMode::Radiance).g;
            INFO("roughness " << roughness << " k " << k << " transmitted " << transmitted << " fR " << fR << " fI " << fI
                              << " fR(wi,wo) " << fRrev);
            if (!(fR > 0.0)) continue;
            // Importance vs Radiance: the (eta_o/eta_i)^2 factor (1 for reflection).
            REQUIRE(std::abs(fR - fI * (etaO * etaO) / (etaI * etaI)) <= 1e-5 * fR);
            // Adjoint: importance transport uses the radiance BSDF with the directions swapped.
            REQUIRE(std::abs(fI - fRrev) <= 2e-4 * fI + 1e-6);
            // Generalised reciprocity f_R(wo, wi) / eta_o^2 = f_R(wi, wo) / eta_i^2.
            REQUIRE(std::abs(fR / (etaO * etaO) - fRrev / (etaI * etaI)) <= 2e-4 * fR / (etaO * etaO) + 1e-6);
            (transmitted ? checkedT : checkedR) += 1;
        }
        CHECK(checkedT > 1000);
        CHECK(checkedR > 100);
    }
    // With a shading normal, Importance = Radiance x (eta_i/eta_o)^2 x the adjoint factor.
    const Bsdf tilted(roughGlass(0.3f, 1.5f), kNsTilted, kNg);
    int checked = 0;
    for (uint64_t k = 0; k < 2000; ++k) {
        TestRng rng(8, k);
        const Vec3 wo = Vec3(squareToUniformSphere(rng.uniform2D()));
        BsdfSample s;
        if (!tilted.sample(wo, rng.uniform(), rng.uniform2D(), TransportMode::Radiance, &s)) continue;
        const bool outside = glm::dot(wo, kNg) > 0.f, transmitted = s.transmission;
        const double etaO = outside ? 1.0 : 1.5, etaI = transmitted == outside ? 1.5 : 1.0;
        const double A = double(absDot(wo, kNsTilted)) * absDot(s.wi, kNg) / (double(absDot(wo, kNg)) * absDot(s.wi, kNsTilted));
        const double fR = tilted.f(wo, s.wi, TransportMode::Radiance).g, fI = tilted.f(wo, s.wi, TransportMode::Importance).g;
        REQUIRE(std::abs(fI - fR * (etaI * etaI) / (etaO * etaO) * A) <= 1e-4 * fI + 1e-7);
        ++checked;
    }
    CHECK(checked > 1000);
}

TEST_CASE("Rough dielectric: white furnace, quadrature albedo <= 1, -> 1 as roughness -> 0, Monte Carlo agrees",
          "[bsdf][rough-dielectric][furnace]") {
    const float ior = 1.5f;
    const double angles[5] = {0.0, 30.0, 60.0, 80.0, 89.0};
    const bool printTable = std::getenv("BDPTREF_PRINT_ALBEDO_TABLE") != nullptr;
    for (bool outside : {true, false}) {
        for (float roughness : {1e-3f, 0.05f, 0.3f, 0.6f, 1.f}) {
            const double alpha = std::max(double(roughness) * roughness, 1e-4);
            const Bsdf b(roughGlass(roughness, ior), kNg, kNg);
            if (printTable) std::printf("%s roughness %.3f:", outside ? "outside" : "inside", double(roughness));
            for (double theta : angles) {
                const double cosO = std::cos(theta * kPiD / 180.0);
                const double q = quadratureAlbedo(alpha, ior, cosO, outside);
                if (printTable) std::printf(" %.4f", q);
                INFO((outside ? "outside" : "inside") << " roughness " << roughness << " theta " << theta << " quadrature " << q);
                CHECK(q <= 1.0 + 1e-6);
                if (roughness <= 1e-3f && theta <= 80.0) CHECK(q >= 1.0 - 2e-3);  // -> 1 as roughness -> 0
                // Monte Carlo through sample() in Importance mode (flux), same quantity.
                const Vec3 wo = woFor(kNg, outside ? theta : 180.0 - theta);
                const Albedo mc = monteCarloAlbedo(b, wo, TransportMode::Importance, 20000, 5 + uint64_t(theta));
                INFO("Monte Carlo " << mc.mean << " +- " << mc.sigma);
                CHECK(std::abs(mc.mean - q) <= kSigmas * mc.sigma + 2e-4);
            }
            if (printTable) std::printf("\n");
        }
    }
    // Energy loss grows with roughness (single scattering), at normal incidence from outside.
    const double q03 = quadratureAlbedo(0.09, ior, 1.0, true), q10 = quadratureAlbedo(1.0, ior, 1.0, true);
    CHECK(q10 < q03);
    CHECK(q03 < 1.0);
}

TEST_CASE("Rough dielectric: near-delta roughness 1e-3 is finite and close to the smooth glass, tiny lobes are delta",
          "[bsdf][rough-dielectric]") {
    const MaterialParams smoothP = roughGlass(0.f);
    const Bsdf nearDelta(roughGlass(1e-3f), kNg, kNg), smooth(smoothP, kNg, kNg);
    CHECK(nearDelta.hasNonDelta());
    for (double theta : {0.0, 40.0, 80.0, 180.0, 150.0, 100.0}) {
        const Vec3 wo = woFor(kNg, theta);
        int transmitted = 0, matched = 0, close = 0;
        for (uint64_t k = 0; k < 2000; ++k) {
            TestRng rng(11, k);
            const float uLobe = rng.uniform();
            const Vec2 u = rng.uniform2D();
            BsdfSample s;
            if (!nearDelta.sample(wo, uLobe, u, TransportMode::Radiance, &s)) continue;
            REQUIRE(isFinite(s.f));
            REQUIRE(std::isfinite(s.pdf));
            REQUIRE(s.pdf > 0.f);
            const double w = double(s.f.g) * absDot(s.wi, kNg) / double(s.pdf);
            REQUIRE(std::isfinite(w));
            // The smooth glass's direction for the same side: within a few alpha (1e-4) of it.
            BsdfSample d;
            REQUIRE(smooth.sample(wo, s.transmission ? 0x1.fffffep-1f : 0.f, u, TransportMode::Radiance, &d));
            if (d.transmission == s.transmission) {
                // GGX has long tails (P(tan theta_h > x alpha) = 1 / (1 + x^2)): at 2e-3 rad
                // (theta_h > 10 alpha for reflection, more for refraction) at most ~1% lie beyond.
                ++matched;
                close += glm::dot(glm::dvec3(s.wi), glm::dvec3(d.wi)) > std::cos(2e-3);
                // weight = (eta_o/eta_i)^2 G1 (transmission) or G1 (reflection), as the delta lobe's
                const double dw = double(d.f.g) * absDot(d.wi, kNg) / double(d.pdf);
                REQUIRE(std::abs(w - dw) <= 1e-2 * dw);
            }
            transmitted += s.transmission;
        }
        INFO("theta " << theta << ": " << close << " of " << matched << " within 2e-3 rad of the delta direction");
        CHECK(close >= 0.97 * matched);
        CHECK(matched > 1900);
        if (theta < 90.0 || theta > 140.0) CHECK(transmitted > 1000);
    }
    // A refracted lobe narrower than 1e-5 rad is the delta lobe: ior 1.05 at roughness 0.01
    // (alpha 1e-4, width 4.8e-6), and ior 1 at any roughness.
    BsdfSample s;
    for (const MaterialParams& p : {roughGlass(0.01f, 1.05f), roughGlass(1.f, 1.f)}) {
        const Bsdf b(p, kNg, kNg);
        CHECK(!b.hasNonDelta());
        REQUIRE(b.sample(kNg, 0.9f, Vec2(0.3f, 0.7f), TransportMode::Radiance, &s));
        CHECK(s.delta);
    }
    CHECK(Bsdf(roughGlass(0.01f, 1.5f), kNg, kNg).hasNonDelta());
}
