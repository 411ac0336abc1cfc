// The sheen lobe of KHR_materials_sheen (docs/materials.md, "Sheen"); the layering with the base
// is in Bsdf (src/scene/bsdf.cpp).
#include "bsdf_sheen.h"

#include "bdptref/sampling.h"

#include <algorithm>
#include <cmath>

namespace bdptref {
namespace bsdf_detail {

double sheenBrdf(const glm::dvec3& lv, const glm::dvec3& ll, double alpha) {
    const glm::dvec3 h = glm::normalize(lv + ll);
    const double vis = 1.0 / ((1.0 + charlieLambda(lv.z, alpha) + charlieLambda(ll.z, alpha)) * 4.0 * lv.z * ll.z);
    return charlieD(h.z, alpha) * vis;
}

namespace {
// ln E at the nodes of sheen_quadrature.h, written at build time by bdptref_sheen_table_gen
// (tools/sheen_table_gen.cpp) instead of on each process's first sheen material (about half a
// CPU-second). E falls by orders of magnitude across mu for narrow lobes, and is close to
// exponential there, so it is interpolated in the logarithm.
constexpr float kLogAlbedo[] = {
#include "sheen_albedo_table.inc"
};
static_assert(sizeof(kLogAlbedo) / sizeof(kLogAlbedo[0]) == size_t(kTableMu * kTableRoughness),
              "the generated table does not have the nodes of sheen_quadrature.h");
}  // namespace

float sheenLogAlbedoNode(int i, int j) { return kLogAlbedo[size_t(j * kTableMu + i)]; }

float sheenAlbedo(float mu, float roughness) {
    // A NaN cosine comes from a NaN direction (e.g. between two coincident path vertices): it has
    // no albedo. Without this, std::clamp passes the NaN through and int(NaN) indexes far outside
    // the table (undefined behaviour; a crash in practice). +-Inf clamp to the table's edges.
    if (std::isnan(mu) || std::isnan(roughness)) return 0.f;
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
    auto at = [](int i, int j) { return sheenLogAlbedoNode(i, j); };
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
