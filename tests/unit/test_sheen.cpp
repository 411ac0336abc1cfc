// Tests of the KHR_materials_sheen layer (src/scene/bsdf_sheen.cpp, the layering in
// src/scene/bsdf.cpp; docs/materials.md "Sheen"):
//  * the Charlie distribution is normalised (the integral of D(h)(n.h) over the hemisphere is 1);
//  * the albedo table E(mu, roughness) matches a finer quadrature written here (1% where
//    mu >= 0.1, the bound the furnace below uses); the table, generated at build time, holds the
//    quadrature's values bit for bit, and sheenAlbedo at a node is exp of its entry;
//  * sample() realises pdf() (chi-square) for sheens over Lambert, rough metal, smooth and rough
//    glass and under a coat, with a tilted shading normal;
//  * f() equals an independent transcription of f = sheenColor D V + f_base min(1 - m E(wo),
//    1 - m E(wi)) (the base from a Bsdf without sheen, E from the table);
//  * reciprocity in Radiance mode; Importance = Radiance x the adjoint factor;
//  * furnaces: over a black base the albedo is the lobe's directional albedo by quadrature
//    (5 sigma); white sheen over white Lambert never exceeds 1 + the table's bound + 5 sigma.
// Chi-square tests REQUIRE p > sidakAlpha(0.01, kChi2Tests), kChi2Tests = 6 cases x 4 wo = 24.
#include "bdptref/bsdf.h"
#include "bdptref/sampling.h"
#include "scene/bsdf_sheen.h"
#include "support/bsdf_checks.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

using namespace bdptref;
using namespace bdptref::test;

namespace {

constexpr double kPiD = 3.14159265358979323846;
const Vec3 kNg = glm::normalize(Vec3(0.3f, -0.5f, 0.8f));
const Vec3 kNsTilted = glm::normalize(Frame(kNg).toWorld(Vec3(0.35f, 0.15f, 1.f)));

struct Case {
    std::string name;
    MaterialParams p;
    bool tilted;
    Vec3 ns() const { return tilted ? kNsTilted : kNg; }
};

MaterialParams sheened(Rgb base, float metallic, float roughness, Rgb sheen, float sheenRoughness) {
    MaterialParams p;
    p.baseColor = base;
    p.metallic = metallic;
    p.roughness = roughness;
    p.sheenColor = sheen;
    p.sheenRoughness = sheenRoughness;
    return p;
}

std::vector<Case> allCases() {
    std::vector<Case> c;
    MaterialParams velvet = sheened(Rgb(0.1f, 0.1f, 0.4f), 0.f, 1.f, Rgb(0.9f, 0.6f, 0.8f), 0.3f);
    velvet.specular = 0.f;
    c.push_back({"sheen 0.3 over Lambert", velvet, false});
    c.push_back({"sheen 0.8 over rough metal, tilted", sheened(Rgb(0.9f, 0.6f, 0.5f), 1.f, 0.4f, Rgb(0.5f), 0.8f), true});
    MaterialParams glass = sheened(Rgb(1.f), 0.f, 0.f, Rgb(0.7f, 0.7f, 0.3f), 0.5f);
    glass.transmission = 1.f;
    c.push_back({"sheen over smooth glass", glass, false});
    MaterialParams roughGlass = glass;
    roughGlass.roughness = 0.3f;
    c.push_back({"sheen over rough glass", roughGlass, false});
    MaterialParams coated = velvet;
    coated.clearcoat = 0.8f;
    coated.clearcoatRoughness = 0.15f;
    c.push_back({"coat over sheen over Lambert, tilted", coated, true});
    MaterialParams faint = sheened(Rgb(0.6f, 0.5f, 0.4f), 0.f, 0.6f, Rgb(0.05f), 0.1f);
    c.push_back({"faint narrow sheen 0.1 over a glossy dielectric", faint, false});
    return c;
}

Bsdf baseOf(const Case& c) {
    MaterialParams p = c.p;
    p.sheenColor = Rgb(0.f);
    return Bsdf(p, c.ns(), kNg);
}

const float kWoTheta[4] = {0.f, 45.f, 80.f, 135.f};
// The extension's formulas, transcribed in double in world space: D_charlie and the Charlie
// visibility with the fitted lambda as the extension writes them (alpha = sheenRoughness^2).
double referenceSheen(double sheenRoughness, const glm::dvec3& N, const glm::dvec3& V, const glm::dvec3& L) {
    const double NdotV = glm::dot(N, V), NdotL = glm::dot(N, L);
    if (!(NdotV > 0 && NdotL > 0)) return 0.0;
    const double alphaG = sheenRoughness * sheenRoughness, invR = 1.0 / alphaG;
    const glm::dvec3 H = glm::normalize(V + L);
    const double cos2h = glm::dot(N, H) * glm::dot(N, H), sin2h = 1.0 - cos2h;
    const double D = (2.0 + invR) * std::pow(sin2h, invR * 0.5) / (2.0 * kPiD);
    auto l = [&](double x) {
        const double t = (1.0 - alphaG) * (1.0 - alphaG);
        const double a = 21.5473 + (25.3245 - 21.5473) * t, b = 3.82987 + (3.32435 - 3.82987) * t;
        const double c = 0.19823 + (0.16801 - 0.19823) * t, d = -1.97760 + (-1.27393 + 1.97760) * t;
        const double e = -4.32054 + (-4.85967 + 4.32054) * t;
        return a / (1.0 + b * std::pow(x, c)) + d * x + e;
    };
    auto lambda = [&](double c) { return c < 0.5 ? std::exp(l(c)) : std::exp(2.0 * l(0.5) - l(1.0 - c)); };
    const double Vis = 1.0 / ((1.0 + lambda(NdotV) + lambda(NdotL)) * 4.0 * NdotV * NdotL);
    return D * Vis;
}

Rgb referenceF(const Case& c, const Vec3& woF, const Vec3& wiF) {
    const glm::dvec3 ng(kNg), wo = glm::normalize(glm::dvec3(woF)), wi = glm::normalize(glm::dvec3(wiF));
    const double r = std::max(double(c.p.sheenRoughness), double(bsdf_detail::kMinSheenRoughness));
    double lobe = 0.0;
    if (glm::dot(wo, ng) * glm::dot(wi, ng) > 0.0) {
        const glm::dvec3 N = glm::normalize(glm::dvec3(c.ns())) * (glm::dot(wo, ng) > 0 ? 1.0 : -1.0);
        lobe = referenceSheen(r, N, wo, wi);
    }
    const double m = std::max(c.p.sheenColor.r, std::max(c.p.sheenColor.g, c.p.sheenColor.b));
    const double eo = bsdf_detail::sheenAlbedo(absDot(woF, c.ns()), float(r));
    const double ei = bsdf_detail::sheenAlbedo(absDot(wiF, c.ns()), float(r));
    const double scale = std::min(1.0 - m * eo, 1.0 - m * ei);
    const Rgb base = baseOf(c).f(woF, wiF, TransportMode::Radiance);
    return Rgb(glm::dvec3(c.p.sheenColor) * lobe + glm::dvec3(base) * scale);
}

// The directional albedo of the sheen lobe by a fine midpoint rule (theta 1200, phi 600 over the
// half space, doubled), independent of the table's code.
double albedoReference(double mu, double roughness) {
    const glm::dvec3 N(0, 0, 1), V(std::sqrt(1.0 - mu * mu), 0.0, mu);
    const int nt = 1200, np = 600;
    double sum = 0.0;
    for (int i = 0; i < nt; ++i) {
        const double t = 0.5 * kPiD * (i + 0.5) / nt;
        for (int k = 0; k < np; ++k) {
            const double ph = kPiD * (k + 0.5) / np;
            const glm::dvec3 L(std::sin(t) * std::cos(ph), std::sin(t) * std::sin(ph), std::cos(t));
            sum += referenceSheen(roughness, N, V, L) * std::cos(t) * std::sin(t);
        }
    }
    return 2.0 * sum * (0.5 * kPiD / nt) * (kPiD / np);
}

constexpr int kChi2Tests = 6 * 4;
const double kChi2Alpha = sidakAlpha(0.01, kChi2Tests);

}  // namespace

TEST_CASE("Sheen: the Charlie distribution is normalised over the hemisphere", "[bsdf][sheen]") {
    for (double r : {0.07, 0.2, 0.5, 1.0}) {
        const double alpha = r * r;
        const int n = 20000;
        double sum = 0.0;  // the integral of D(h) cos(theta_h) over the hemisphere, in theta
        for (int i = 0; i < n; ++i) {
            const double t = 0.5 * kPiD * (i + 0.5) / n;
            sum += bsdf_detail::charlieD(std::cos(t), alpha) * std::cos(t) * std::sin(t);
        }
        INFO("roughness " << r);
        CHECK(sum * 2.0 * kPiD * (0.5 * kPiD / n) == Approx(1.0).epsilon(1e-4));
    }
}

TEST_CASE("Sheen: the albedo table matches a finer quadrature of the lobe", "[bsdf][sheen]") {
    double worst = 0.0;
    for (float mu : {0.1f, 0.25f, 0.5f, 0.8f, 1.f})
        for (float r : {0.07f, 0.2f, 0.45f, 0.9f}) {
            const double ref = albedoReference(mu, r), table = bsdf_detail::sheenAlbedo(mu, r);
            INFO("mu " << mu << ", roughness " << r << ": table " << table << ", quadrature " << ref);
            CHECK(std::abs(table - ref) <= 0.01 * std::max(ref, 0.05));
            worst = std::max(worst, std::abs(table - ref));
            CHECK(table <= 1.0);
        }
    INFO("worst absolute difference " << worst);
    CHECK(worst < 0.01);
}

// The table is generated at build time (tools/sheen_table_gen.cpp) from the quadrature the library
// compiles too: every node must be what the quadrature gives here, bit for bit, or images would
// differ from those of the table once computed at run time (and a stale or transposed table, or a
// literal that does not read back exactly, would go unnoticed by the 1% test above).
TEST_CASE("Sheen: the generated albedo table is the quadrature's, bit for bit, at every node", "[bsdf][sheen]") {
    using namespace bsdf_detail;
    auto bits = [](float f) {
        std::uint32_t u;
        std::memcpy(&u, &f, sizeof u);
        return u;
    };
    int differing = 0;
    for (int j = 0; j < kTableRoughness; ++j)
        for (int i = 0; i < kTableMu; ++i) {
            const float expected = float(std::log(std::max(albedoQuadrature(tableMu(i), tableRoughness(j)), 1e-30)));
            if (bits(sheenLogAlbedoNode(i, j)) == bits(expected)) continue;
            ++differing;
            UNSCOPED_INFO("node (" << i << ", " << j << "): table " << sheenLogAlbedoNode(i, j) << ", quadrature " << expected);
        }
    CHECK(differing == 0);

    // sheenAlbedo at a node is exp of the node's entry: exactly where the node's coordinates are
    // exact in float (mu node 0 and 1, the roughness ends), else up to the interpolation weight's
    // rounding (a few float ulps of x or y times the step of ln E to the neighbour).
    for (int i : {0, 1, 17, 30, 46, 47})
        for (int j : {0, 1, 23, 40, 46, 47}) {
            const float e = sheenAlbedo(float(tableMu(i)), float(tableRoughness(j)));
            const float node = std::exp(sheenLogAlbedoNode(i, j));
            INFO("node (" << i << ", " << j << "): sheenAlbedo " << e << ", exp(table) " << node);
            if ((i == 0 || i == kTableMu - 1) && (j == 0 || j == kTableRoughness - 1)) CHECK(bits(e) == bits(node));
            else CHECK(e == Approx(node).epsilon(1e-5));
        }
}

TEST_CASE("Sheen: sample() realises pdf() (chi-square, sheens over every kind of base and under a coat)",
          "[bsdf][sheen][chi2]") {
    const std::vector<Case> cases = allCases();
    REQUIRE(int(cases.size()) * 4 == kChi2Tests);
    int performed = 0;
    for (const Case& c : cases) {
        const Bsdf b(c.p, c.ns(), kNg);
        for (float theta : kWoTheta) {
            const Vec3 wo = woAtAngle(c.ns(), theta);
            const bool front = glm::dot(wo, kNg) > 0.f;
            DirectionBinning bins;
            if (c.p.clearcoat > 0.f) {  // the coat's narrow lobe: log bins about its mirror direction
                const Vec3 n = front ? c.ns() : -c.ns();
                bins.frame = Frame(glm::normalize(2.f * glm::dot(wo, n) * n - wo));
                bins.theta = ThetaBinning::LogOneMinusCos;
                bins.thetaBins = 14;
                bins.minOneMinusCos = 1e-5;
            } else {
                bins.frame = Frame(front ? c.ns() : -c.ns());
                bins.thetaBins = 12;
            }
            bins.phiBins = 16;
            const Chi2Result r = bsdfSamplingChi2(b, wo, bins, 9876, 200000);
            INFO(c.name << ", wo theta " << theta << ": " << r.report);
            REQUIRE(r.pValue > kChi2Alpha);
            ++performed;
        }
    }
    CHECK(performed == kChi2Tests);
}

TEST_CASE("Sheen: sample() reports f() and pdf(), and f() is the extension's lobe and albedo scaling", "[bsdf][sheen]") {
    for (const Case& c : allCases()) {
        const Bsdf b(c.p, c.ns(), kNg);
        long sampled = 0, lobeSeen = 0;
        for (float theta : kWoTheta) {
            const Vec3 wo = woAtAngle(c.ns(), theta);
            for (int i = 0; i < 3000; ++i) {
                TestRng rng(82, uint64_t(i));
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
                if (c.p.clearcoat > 0.f) continue;  // the transcription is of the sheen layer alone
                const Vec3 wi = squareToUniformSphere(rng.uniform2D());
                const Rgb f = b.f(wo, wi, TransportMode::Radiance), ref = referenceF(c, wo, wi);
                REQUIRE_QUIET(closeRgb(f, ref, 2e-4f, 1e-6f), where << ": f " << str(f) << ", reference " << str(ref));
                lobeSeen += !isBlack(f - baseOf(c).f(wo, wi, TransportMode::Radiance));
            }
        }
        INFO(c.name);
        CHECK(sampled > 0);
        if (c.p.clearcoat == 0.f) CHECK(lobeSeen > 100);
    }
}

TEST_CASE("Sheen: reciprocal in Radiance mode, and Importance is Radiance times the adjoint factor", "[bsdf][sheen]") {
    for (const Case& c : allCases()) {
        if (c.p.transmission > 0.f || c.p.clearcoat > 0.f) continue;  // refraction and the coat: their own tests
        const Bsdf b(c.p, c.ns(), kNg);
        long nonZero = 0;
        for (int i = 0; i < 4000; ++i) {
            TestRng rng(92, uint64_t(i));
            const Vec3 wo = squareToUniformSphere(rng.uniform2D());
            Vec3 wi = squareToUniformSphere(rng.uniform2D());
            if (glm::dot(wo, kNg) * glm::dot(wi, kNg) < 0.f) wi = wi - 2.f * glm::dot(wi, kNg) * kNg;
            const Rgb a = b.f(wo, wi, TransportMode::Radiance), r = b.f(wi, wo, TransportMode::Radiance);
            REQUIRE_QUIET(closeRgb(a, r, 2e-5f, 1e-7f), c.name << ": " << str(a) << " vs " << str(r));
            const Rgb imp = b.f(wo, wi, TransportMode::Importance);
            REQUIRE_QUIET(closeRgb(imp, a * float(adjointFactorOf(wo, wi, c.ns(), kNg)), 2e-5f, 1e-7f), c.name);
            nonZero += !isBlack(a);
        }
        INFO(c.name);
        CHECK(nonZero > 1000);
    }
}

namespace {
void albedo(const Bsdf& b, const Vec3& wo, int n, double* mean, double* se) {
    double s = 0.0, s2 = 0.0;
    for (int i = 0; i < n; ++i) {
        TestRng rng(19, uint64_t(i));
        const float uLobe = rng.uniform();
        const Vec2 u = rng.uniform2D();
        BsdfSample bs;
        if (!b.sample(wo, uLobe, u, TransportMode::Radiance, &bs)) continue;
        const double w = double(bs.f.g) * absDot(bs.wi, b.shadingNormal()) / double(bs.pdf);
        s += w;
        s2 += w * w;
    }
    *mean = s / n;
    *se = std::sqrt(std::max(0.0, s2 / n - *mean * *mean) / n);
}
}  // namespace

TEST_CASE("Sheen: furnaces: over a black base the lobe albedo, white over white Lambert at most 1",
          "[bsdf][sheen][furnace]") {
    for (float theta : {0.f, 50.f, 78.f}) {
        const Vec3 wo = woAtAngle(kNg, theta);
        const double mu = std::cos(double(theta) * kPiD / 180.0);
        for (float r : {0.3f, 0.8f}) {
            MaterialParams black = sheened(Rgb(0.f), 0.f, 1.f, Rgb(1.f), r);
            black.specular = 0.f;
            double m, se;
            albedo(Bsdf(black, kNg, kNg), wo, 200000, &m, &se);
            const double ref = albedoReference(mu, r);
            INFO("theta " << theta << ", roughness " << r << ": " << m << " +- " << se << ", quadrature " << ref);
            CHECK(std::abs(m - ref) <= 5.0 * se);
            MaterialParams white = black;
            white.baseColor = Rgb(1.f);
            albedo(Bsdf(white, kNg, kNg), wo, 200000, &m, &se);
            INFO("white over white: " << m << " +- " << se);
            // At most 1 up to the table's error (bounded by 0.01 in the table test) and 5 sigma.
            CHECK(m <= 1.0 + 0.01 + 5.0 * se);
            CHECK(m >= ref);  // the base adds to the sheen
        }
    }
}
