// The sheen lobe of KHR_materials_sheen (docs/materials.md, "Sheen"); the layering with the base
// is in Bsdf (src/scene/bsdf.cpp).
#include "bsdf_sheen.h"

#include "bdptref/sampling.h"

#include <array>

namespace bdptref {
namespace bsdf_detail {

double charlieD(double cosH, double alpha) {
    const double sin2 = std::max(0.0, 1.0 - cosH * cosH);
    return (2.0 + 1.0 / alpha) * std::pow(sin2, 0.5 / alpha) / (2.0 * kPiD);
}

namespace {
// The extension's fit l(x) of log Lambda, interpolated in (1 - alpha)^2.
double charlieL(double x, double alpha) {
    const double t = (1.0 - alpha) * (1.0 - alpha);
    auto mix = [t](double a, double b) { return a * (1.0 - t) + b * t; };
    const double a = mix(21.5473, 25.3245), b = mix(3.82987, 3.32435), c = mix(0.19823, 0.16801);
    const double d = mix(-1.97760, -1.27393), e = mix(-4.32054, -4.85967);
    return a / (1.0 + b * std::pow(x, c)) + d * x + e;
}
}  // namespace

double charlieLambda(double cosTheta, double alpha) {
    const double c = std::abs(cosTheta);
    return c < 0.5 ? std::exp(charlieL(c, alpha)) : std::exp(2.0 * charlieL(0.5, alpha) - charlieL(1.0 - c, alpha));
}

double sheenBrdf(const glm::dvec3& lv, const glm::dvec3& ll, double alpha) {
    const glm::dvec3 h = glm::normalize(lv + ll);
    const double vis = 1.0 / ((1.0 + charlieLambda(lv.z, alpha) + charlieLambda(ll.z, alpha)) * 4.0 * lv.z * ll.z);
    return charlieD(h.z, alpha) * vis;
}

namespace {

constexpr int kTableMu = 48, kTableRoughness = 48;
// Nodes: mu_i = i / 47 for i >= 1 and mu_0 = 1 / 94 (the albedo grows steeply only as mu -> 0),
// roughness_j = kMin + (1 - kMin) j / 47.
double tableMu(int i) { return i == 0 ? 0.5 / (kTableMu - 1) : double(i) / (kTableMu - 1); }
double tableRoughness(int j) { return kMinSheenRoughness + (1.0 - kMinSheenRoughness) * j / (kTableRoughness - 1); }

// E(mu, roughness) by the midpoint rule over l in (theta, phi), phi in [0, pi] doubled by the
// symmetry about the plane of v: 96 x 48 cells (the lobe is at least ~0.14 rad wide).
double albedoQuadrature(double mu, double roughness) {
    const double alpha = roughness * roughness;
    const glm::dvec3 v(std::sqrt(std::max(0.0, 1.0 - mu * mu)), 0.0, mu);
    const int nt = 96, np = 48;
    const double lambdaV = charlieLambda(mu, alpha);
    double sum = 0.0;
    for (int i = 0; i < nt; ++i) {
        const double theta = 0.5 * kPiD * (i + 0.5) / nt, cosT = std::cos(theta), sinT = std::sin(theta);
        const double vis = 1.0 / ((1.0 + lambdaV + charlieLambda(cosT, alpha)) * 4.0 * mu * cosT);
        for (int k = 0; k < np; ++k) {
            const double phi = kPiD * (k + 0.5) / np;
            const glm::dvec3 l(sinT * std::cos(phi), sinT * std::sin(phi), cosT);
            sum += charlieD(glm::normalize(v + l).z, alpha) * vis * cosT * sinT;
        }
    }
    return 2.0 * sum * (0.5 * kPiD / nt) * (kPiD / np);
}

// ln E at the nodes: E falls by orders of magnitude across mu for narrow lobes, and is close to
// exponential there, so it is interpolated in the logarithm.
struct AlbedoTable {
    std::array<float, kTableMu * kTableRoughness> logE{};
    AlbedoTable() {
        for (int j = 0; j < kTableRoughness; ++j)
            for (int i = 0; i < kTableMu; ++i)
                logE[size_t(j * kTableMu + i)] = float(std::log(std::max(albedoQuadrature(tableMu(i), tableRoughness(j)), 1e-30)));
    }
};

}  // namespace

float sheenAlbedo(float mu, float roughness) {
    static const AlbedoTable table;  // computed once, on the first sheen material (~0.3 s)
    // Position between the mu nodes (node 0 at 1/94, node i >= 1 at i / 47).
    const float m = std::clamp(mu, float(tableMu(0)), 1.f);
    float x;
    if (m < float(tableMu(1))) x = (m - float(tableMu(0))) / float(tableMu(1) - tableMu(0));
    else x = m * float(kTableMu - 1);
    x = std::clamp(x, 0.f, float(kTableMu - 1));
    const float y = std::clamp((std::max(roughness, kMinSheenRoughness) - kMinSheenRoughness) / (1.f - kMinSheenRoughness) *
                                   float(kTableRoughness - 1),
                               0.f, float(kTableRoughness - 1));
    const int i0 = std::min(int(x), kTableMu - 2), j0 = std::min(int(y), kTableRoughness - 2);
    const float fx = x - float(i0), fy = y - float(j0);
    auto at = [&](int i, int j) { return table.logE[size_t(j * kTableMu + i)]; };
    return std::exp((1.f - fy) * ((1.f - fx) * at(i0, j0) + fx * at(i0 + 1, j0)) +
                    fy * ((1.f - fx) * at(i0, j0 + 1) + fx * at(i0 + 1, j0 + 1)));
}

float sheenBaseScale(const Sheen& s, const Vec3& ns, const Vec3& a, const Vec3& b) {
    const float m = maxComponent(s.color);
    return std::min(1.f - m * sheenAlbedo(absDot(a, ns), s.roughness), 1.f - m * sheenAlbedo(absDot(b, ns), s.roughness));
}

float sheenSelectionProbability(const Sheen& s, const Vec3& ns, const Vec3& wo) {
    const float w = std::min(1.f, maxComponent(s.color) * sheenAlbedo(absDot(wo, ns), s.roughness));
    const float total = w + (1.f - w) * s.baseAlbedo;
    return total > 0.f ? std::min(1.f, w / total) : 1.f;
}

namespace {
// The local pair about n_s on wo's side; false unless a reflection pair above n_s.
bool sheenPair(const Vec3& ns, const Vec3& ng, const Vec3& wo, const Vec3& wi, glm::dvec3* lo, glm::dvec3* li) {
    Side side;
    if (!setUpSide(wo, ns, ng, &side)) return false;
    if (!reflectionLocal(side, wi, li)) return false;
    *lo = side.lo;
    return true;
}
}  // namespace

Rgb sheenF(const Sheen& s, const Vec3& ns, const Vec3& ng, const Vec3& wo, const Vec3& wi) {
    glm::dvec3 lo, li;
    if (!sheenPair(ns, ng, wo, wi, &lo, &li)) return Rgb(0.f);
    const double r = std::max(s.roughness, kMinSheenRoughness);
    return s.color * float(sheenBrdf(lo, li, r * r));
}

double sheenPdf(const Vec3& ns, const Vec3& ng, const Vec3& wo, const Vec3& wi) {
    glm::dvec3 lo, li;
    return sheenPair(ns, ng, wo, wi, &lo, &li) ? li.z / kPiD : 0.0;
}

bool sampleSheenDirection(const Vec3& ns, const Vec3& ng, const Vec3& wo, Vec2 u, Vec3* wi) {
    Side side;
    if (!setUpSide(wo, ns, ng, &side)) return false;
    const glm::dvec3 local(squareToCosineHemisphere(u));
    if (!(local.z > 0.0)) return false;
    *wi = Vec3(glm::normalize(side.frame.toWorld(local)));
    glm::dvec3 li;
    return reflectionLocal(side, *wi, &li);
}

}  // namespace bsdf_detail
}  // namespace bdptref
