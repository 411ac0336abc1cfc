// KHR_materials_sheen: the "Charlie" sheen lobe (Estevez & Kulla 2017) layered over the base with
// the extension's albedo scaling,
//   f = sheenColor D(h) V(wo, wi) + f_base(wo, wi) min(1 - max3(sheenColor) E(|wo.n|), 1 - max3(sheenColor) E(|wi.n|)).
// Derivations, the albedo table and the deviations: docs/materials.md, "Sheen". The layering is
// reciprocal, so Importance mode is Radiance mode times the adjoint shading-normal factor.
#pragma once

#include "bsdf_terms.h"
#include "sheen_quadrature.h"  // kMinSheenRoughness, charlieD, charlieLambda, the table's nodes

namespace bdptref {
namespace bsdf_detail {

// The sheen BRDF without its colour: D(h) / ((1 + Lambda(v) + Lambda(l)) 4 (n.v)(n.l)) for local
// unit directions with v.z, l.z > 0.
double sheenBrdf(const glm::dvec3& lv, const glm::dvec3& ll, double alpha);
// E(mu, roughness): the directional albedo of sheenBrdf (the integral of sheenBrdf (n.l) over l) for
// n.v = mu, interpolated bilinearly in ln E between the nodes of the table (sheen_quadrature.h,
// generated at build time; docs/materials.md). NaN-safe: a NaN argument gives 0, +-Inf the edge.
float sheenAlbedo(float mu, float roughness);
// The table's ln E at node (tableMu(i), tableRoughness(j)), 0 <= i < kTableMu, 0 <= j < kTableRoughness.
float sheenLogAlbedoNode(int i, int j);

using Sheen = SheenLayer;  // bsdf.h

// min(1 - max3(sheenColor) E(|a.n_s|), 1 - max3(sheenColor) E(|b.n_s|)): the base's scale.
float sheenBaseScale(const Sheen& s, const Vec3& ns, const Vec3& a, const Vec3& b);
// Probability of choosing the sheen lobe when sampling from wo: w / (w + (1 - w) baseAlbedo) with
// w = max3(sheenColor) E(|wo.n_s|).
float sheenSelectionProbability(const Sheen& s, const Vec3& ns, const Vec3& wo);
// The sheen lobe (Radiance mode; reciprocal): sheenColor sheenBrdf on reflection pairs (one side of
// n_g, above n_s), else 0.
Rgb sheenF(const Sheen& s, const Vec3& ns, const Vec3& ng, const Vec3& wo, const Vec3& wi);
// The sheen lobe's sampling density without its selection probability: cosine-weighted about n_s
// on wo's side, (wi.n_s)/pi on the valid pairs of sheenF.
double sheenPdf(const Vec3& ns, const Vec3& ng, const Vec3& wo, const Vec3& wi);
bool sampleSheenDirection(const Vec3& ns, const Vec3& ng, const Vec3& wo, Vec2 u, Vec3* wi);

}  // namespace bsdf_detail
}  // namespace bdptref
