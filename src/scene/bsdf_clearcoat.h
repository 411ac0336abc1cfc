// KHR_materials_clearcoat: a GGX coat (IOR 1.5) layered over the base BSDF with the extension's
// fresnel_coat: coated = mix(base, coat_brdf, clearcoat * F_c(|V.n_c|)). Derivations and the
// conventions below: docs/materials.md, "Clearcoat".
//
// Conventions (those of bsdf.h): directions point away from the surface; V is the direction
// towards the camera side, i.e. wo in Radiance mode and wi in Importance mode. The layering is
// not reciprocal (F_c depends on V alone), so Importance mode is the adjoint: f*(wo, wi) =
// f(wi, wo) times the shading-normal factor; Bsdf applies that rule (src/scene/bsdf.cpp).
// The coat has its own normal n_c; the integrators' cosine is against the base's shading normal
// n_s, so the coat lobe is stored as coat_brdf |wi.n_c| / |wi.n_s| (f |wi.n_s| is what the
// extension's layering multiplies by the light).
#pragma once

#include "bsdf_terms.h"

namespace bdptref {
namespace bsdf_detail {

// F_c(c) = f0 + (1 - f0)(1 - |c|)^5 with f0 = ((1.5 - 1)/(1.5 + 1))^2 = 0.04.
constexpr float kClearcoatF0 = 0.04f;
inline float clearcoatFresnel(float cosV) {
    return kClearcoatF0 + (1.f - kClearcoatF0) * schlickWeight(std::abs(cosV));
}

using Coat = ClearcoatLayer;  // bsdf.h

// Scale of the base layer seen from V: 1 - clearcoat F_c(|V.n_c|).
inline float coatBaseScale(const Coat& c, const Vec3& v) { return 1.f - c.weight * clearcoatFresnel(glm::dot(v, c.n)); }

// Probability of choosing the coat lobe when sampling from wo (a function of wo only):
// w / (w + (1 - w) baseAlbedo) with w = clearcoat F_c(|wo.n_c|), the coat's reflectance.
float coatSelectionProbability(const Coat& c, const Vec3& wo);

// The coat lobe in Radiance mode for V = v, L = l (non-delta coat): clearcoat F_c(|v.n_c|) D G1 G1
// / (4 |v.n_c| |l.n_c|) * |l.n_c| / |l.n_s|, zero unless v and l are on one side of n_g and above
// both n_c and n_s on that side.
float coatRadianceF(const Coat& c, const Vec3& ns, const Vec3& ng, const Vec3& v, const Vec3& l);

// Solid-angle density of sampling wi from wo with the coat lobe (non-delta coat; without the
// selection probability): the visible-normal density G1(wo) D(h) / (4 |wo.n_c|) on the valid
// pairs of coatRadianceF, else 0.
double coatPdf(const Coat& c, const Vec3& ns, const Vec3& ng, const Vec3& wo, const Vec3& wi);

// A direction from the coat lobe: visible-normal sampling about n_c, or the mirror direction about
// n_c for a delta coat. False unless the direction is a valid pair with wo (as coatRadianceF).
bool sampleCoatDirection(const Coat& c, const Vec3& ns, const Vec3& ng, const Vec3& wo, Vec2 u, Vec3* wi);

// Reflectance of the delta coat for the pair (V = v): clearcoat F_c(|v.n_c|).
inline float deltaCoatReflectance(const Coat& c, const Vec3& v) { return c.weight * clearcoatFresnel(glm::dot(v, c.n)); }

}  // namespace bsdf_detail
}  // namespace bdptref
