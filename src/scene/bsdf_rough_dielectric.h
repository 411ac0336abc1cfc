// The rough dielectric lobe of a transmissive material with roughness > 0: GGX microfacet
// reflection + refraction (Walter, Marschner, Li, Torrance 2007, "Microfacet models for refraction
// through rough surfaces"), sampled by visible normals (Heitz 2018) with a Fresnel-weighted choice
// between reflection and refraction per sampled microfacet. Derivations: docs/materials.md,
// "Rough transmission".
//
// Everything here works in the local frame of the side of wo (Side in bsdf_terms.h): lo.z > 0;
// li.z > 0 is reflection, li.z < 0 refraction. The values are the IMPORTANCE form of the BTDF (no
// eta^2 factor, no adjoint shading-normal factor); Bsdf applies (eta_o/eta_i)^2 in Radiance mode
// and the adjoint factor in Importance mode.
#pragma once

#include "bsdf_terms.h"

namespace bdptref {
namespace bsdf_detail {

// A transmissive material is rough (this lobe) when roughness > 0 and the refracted lobe,
// about alpha * |1 - 1/ior| radians wide, is at least this wide; otherwise all of its specular
// lobes are the smooth delta lobes (docs/materials.md, "Near-delta roughness").
constexpr float kMinRefractedLobeWidth = 1e-5f;

// IORs on wo's side (o) and on the refracted side (i) of the interface, from wo's side.
struct Etas {
    double o = 1.0, i = 1.0;
};
inline Etas interfaceEtas(const MaterialParams& p, bool outside) {
    return outside ? Etas{1.0, double(p.ior)} : Etas{double(p.ior), 1.0};
}

// Reflectance and transmittance of one microfacet seen at cos(wo, h) = cosOH, and the probability
// of choosing reflection after sampling h (the luminance share of the reflectance).
struct MicrofacetSplit {
    Rgb reflect{0.f};   // (1 - m) F_t + m F_m
    Rgb transmit{0.f};  // (1 - m) t (1 - max_value(F_t)) c; 0 under total internal reflection
    double pReflect = 1.0;
};
MicrofacetSplit microfacetSplit(const MaterialParams& p, bool outside, double cosOH);

// Selection weight of the whole lobe (reflection + refraction), from the macro-surface cos_o.
float roughDielectricSelectionWeight(const MaterialParams& p, bool outside, float cosO);

// Generalised half vector of a refraction pair, h = normalize(eta_o lo + eta_i li) oriented to
// h.z > 0; false unless lo.h > 0 > li.h (the pair refracts through a microfacet facing wo).
bool refractionHalfVector(const glm::dvec3& lo, const glm::dvec3& li, const Etas& eta, glm::dvec3* h);

// f (importance form) and the solid-angle density of the lobe (without its selection
// probability) for a local pair; both 0 for an impossible pair.
struct RoughDielectricValue {
    Rgb f{0.f};
    double pdf = 0.0;
};
RoughDielectricValue evalRoughDielectric(const MaterialParams& p, double alpha, bool outside, const glm::dvec3& lo,
                                         const glm::dvec3& li);

// Samples li: h by visible normals from u, then reflection if uChoice < pReflect(h), refraction
// otherwise. False when the direction does not exist (numerically degenerate h).
bool sampleRoughDielectric(const MaterialParams& p, double alpha, bool outside, const glm::dvec3& lo, double uChoice,
                           Vec2 u, glm::dvec3* li);

// The Bsdf of a transmissive material with roughness > 0 (alpha > 0): the diffuse base (t < 1)
// and the rough dielectric lobe, with Bsdf's conventions (bsdf.h): f in the given mode, pdf with
// the lobe selection, sample() reporting f(wo, wi) and pdf(wo, wi) of the sampled direction.
Rgb roughTransmissiveF(const MaterialParams& p, float alpha, const Vec3& ns, const Vec3& ng, const Vec3& wo,
                       const Vec3& wi, TransportMode mode);
float roughTransmissivePdf(const MaterialParams& p, float alpha, const Vec3& ns, const Vec3& ng, const Vec3& wo,
                           const Vec3& wi);
bool roughTransmissiveSample(const MaterialParams& p, float alpha, const Vec3& ns, const Vec3& ng, const Vec3& wo,
                             float uLobe, Vec2 u, TransportMode mode, BsdfSample* out);

}  // namespace bsdf_detail
}  // namespace bdptref
