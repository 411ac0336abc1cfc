// Terms shared by the BSDF's lobes (src/scene/bsdf.cpp: diffuse, GGX reflection, delta lobes;
// src/scene/bsdf_rough_dielectric.cpp: the rough dielectric): Fresnel, GGX D / Smith G1 / VNDF
// sampling, the double-precision local frame and the two-sided set-up. Formulas: docs/materials.md.
#pragma once

#include "bdptref/bsdf.h"

#include <algorithm>
#include <cmath>

namespace bdptref {
namespace bsdf_detail {

// Smallest GGX alpha used for roughness > 0 (roughness ~0.01). Keeps D, the VNDF warp and the
// pdf finite and float-resolvable (the lobe stays ~1e-4 rad wide, >1000x the float direction
// quantum). Roughness exactly 0 is never clamped: it selects the exact delta lobes.
constexpr float kMinAlpha = 1e-4f;
// Floor on the selection weight of an active non-delta lobe, so that a lobe whose f can be
// non-zero is never given selection probability 0 (which would make pdf 0 where f > 0).
constexpr float kMinLobeWeight = 1e-3f;

constexpr double kPiD = 3.14159265358979323846;

inline float clamp01(float x) { return x > 0.f ? (x < 1.f ? x : 1.f) : 0.f; }  // NaN -> 0
inline float nonNegative(float x) { return x > 0.f ? x : 0.f; }                 // NaN -> 0
inline Rgb clampColor01(const Rgb& c) { return Rgb(clamp01(c.r), clamp01(c.g), clamp01(c.b)); }
inline Rgb clampColorNonNegative(const Rgb& c) { return Rgb(nonNegative(c.r), nonNegative(c.g), nonNegative(c.b)); }

// (1 - c)^5 with c clamped to [0,1]: the Schlick weight.
inline float schlickWeight(float c) {
    const float m = clamp01(1.f - c);
    const float m2 = m * m;
    return m2 * m2 * m;
}

// KHR_materials_ior: F0 of the interface between the outside (IOR 1) and the material.
inline float iorF0(float ior) { return sqr((ior - 1.f) / (ior + 1.f)); }

// KHR_materials_specular: dielectric_f0 = min(iorF0 * specularColor, 1) * specular.
inline Rgb dielectricF0(const MaterialParams& p) {
    return glm::min(iorF0(p.ior) * p.specularColor, Rgb(1.f)) * p.specular;
}

// Spec: dielectric Fresnel F_d(c) = f0 + (f90 - f0)(1 - c)^5 with f90 = specular.
inline Rgb fresnelDielectricSchlick(const MaterialParams& p, float c) {
    const Rgb f0 = dielectricF0(p);
    return f0 + (Rgb(p.specular) - f0) * schlickWeight(c);
}

// Spec: conductor Fresnel F_m(c) = baseColor + (1 - baseColor)(1 - c)^5.
inline Rgb fresnelMetal(const MaterialParams& p, float c) {
    return p.baseColor + (Rgb(1.f) - p.baseColor) * schlickWeight(c);
}

// Exact unpolarised Fresnel reflectance of a smooth dielectric interface (Born & Wolf).
// cosI in (0,1] on the incident side, eta = eta_transmitted / eta_incident. Returns 1 under total
// internal reflection; *cosT receives the cosine of the refracted direction (0 under TIR).
inline float fresnelDielectricExact(float cosI, float eta, float* cosT) {
    const double ci = std::min(1.0, double(cosI));
    const double e = double(eta);
    const double sin2T = (1.0 - ci * ci) / (e * e);
    if (sin2T >= 1.0) {
        *cosT = 0.f;
        return 1.f;
    }
    const double ct = std::sqrt(1.0 - sin2T);
    const double rs = (ci - e * ct) / (ci + e * ct);
    const double rp = (e * ci - ct) / (e * ci + ct);
    *cosT = float(ct);
    return float(0.5 * (rs * rs + rp * rp));
}

// Fresnel of the delta reflection/refraction pair of a transmissive material: the spec's
// f0/f90 interpolation with the exact Fresnel curve in place of Schlick's (1 - c)^5,
//   F_t = f0 + (f90 - f0) * (F_exact - iorF0) / (1 - iorF0),
// which equals F_exact for specular = 1, specularColor = 1, gives f0 at normal incidence and
// f90 at grazing incidence and under total internal reflection.
inline Rgb fresnelTransmissive(const MaterialParams& p, float fExact) {
    const float F0 = iorF0(p.ior);
    const float w = F0 < 1.f ? clamp01((fExact - F0) / (1.f - F0)) : 1.f;
    const Rgb f0 = dielectricF0(p);
    return f0 + (Rgb(p.specular) - f0) * w;
}

// --- GGX (Trowbridge-Reitz) with separable Smith shadowing, in the local shading frame --------

// GGX alpha of a perceptual roughness: roughness^2, at least kMinAlpha; 0 selects delta lobes.
inline float ggxAlpha(float roughness) { return roughness > 0.f ? std::max(roughness * roughness, kMinAlpha) : 0.f; }

// D(h) = a^2 / (pi ((n.h)^2 (a^2 - 1) + 1)^2), written as a^2 / (pi (hx^2 + hy^2 + a^2 hz^2)^2)
// for a unit h (the same value without the cancellation in 1 - (n.h)^2).
inline double ggxD(const glm::dvec3& h, double alpha) {
    if (h.z <= 0.0) return 0.0;
    const double a2 = alpha * alpha;
    const double d = h.x * h.x + h.y * h.y + a2 * h.z * h.z;
    return a2 / (kPiD * d * d);
}

// G1(v) = 2 |n.v| / (|n.v| + sqrt(a^2 + (1 - a^2)(n.v)^2)); (1-a^2)(n.v)^2 + a^2 is evaluated as
// vz^2 + a^2 (vx^2 + vy^2) for a unit v.
inline double smithG1(const glm::dvec3& v, double alpha) {
    const double z = std::abs(v.z);
    if (z == 0.0) return 0.0;
    const double r = std::sqrt(z * z + alpha * alpha * (v.x * v.x + v.y * v.y));
    return 2.0 * z / (z + r);
}

// Visible-normal sampling (Heitz 2018, "Sampling the GGX Distribution of Visible Normals",
// JCGT 7(4)); v is the local outgoing direction with v.z > 0. Density of the returned h:
// G1(v) max(0, v.h) D(h) / v.z. u is clamped into [0, 1] (NaN to 0) as the warps of
// core/sampling.cpp are, so that any u gives a unit h (u in [0, 1) is unchanged).
inline glm::dvec3 sampleGgxVndf(const glm::dvec3& v, double alpha, double u1, double u2) {
    u1 = u1 > 0.0 ? std::min(u1, 1.0) : 0.0;
    u2 = u2 > 0.0 ? std::min(u2, 1.0) : 0.0;
    const glm::dvec3 vh = glm::normalize(glm::dvec3(alpha * v.x, alpha * v.y, v.z));
    const double lensq = vh.x * vh.x + vh.y * vh.y;
    const glm::dvec3 t1 = lensq > 0.0 ? glm::dvec3(-vh.y, vh.x, 0.0) / std::sqrt(lensq) : glm::dvec3(1.0, 0.0, 0.0);
    const glm::dvec3 t2 = glm::cross(vh, t1);
    const double r = std::sqrt(u1);
    const double phi = 2.0 * kPiD * u2;
    const double p1 = r * std::cos(phi);
    double p2 = r * std::sin(phi);
    const double s = 0.5 * (1.0 + vh.z);
    p2 = (1.0 - s) * std::sqrt(std::max(0.0, 1.0 - p1 * p1)) + s * p2;
    const glm::dvec3 nh = p1 * t1 + p2 * t2 + std::sqrt(std::max(0.0, 1.0 - p1 * p1 - p2 * p2)) * vh;
    return glm::normalize(glm::dvec3(alpha * nh.x, alpha * nh.y, std::max(0.0, nh.z)));
}

// --- Per-wo set-up shared by f(), pdf() and sample() -----------------------------------------

// Orthonormal basis about a normal in double (Duff et al. 2017, as Frame in math.h): the
// local coordinates of float directions then carry no error beyond the inputs' own, which matters
// for D(h) of narrow lobes (its relative error is ~ (direction error) / alpha).
struct FrameD {
    glm::dvec3 s, t, n;
    FrameD() = default;
    explicit FrameD(const glm::dvec3& normal) : n(glm::normalize(normal)) {
        const double sign = std::copysign(1.0, n.z);
        const double a = -1.0 / (sign + n.z);
        const double b = n.x * n.y * a;
        s = glm::dvec3(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        t = glm::dvec3(b, sign + n.y * n.y * a, -n.y);
    }
    glm::dvec3 toLocal(const glm::dvec3& v) const { return glm::dvec3(glm::dot(v, s), glm::dot(v, t), glm::dot(v, n)); }
    glm::dvec3 toWorld(const glm::dvec3& v) const { return s * v.x + t * v.y + n * v.z; }
};

// Two-sided shading: both normals are flipped to the side of wo given by the geometric normal.
struct Side {
    Vec3 n;        // shading normal on wo's side
    Vec3 g;        // geometric normal on wo's side
    FrameD frame;  // local frame about n
    glm::dvec3 lo; // wo in that frame (unit); lo.z = cos(wo, n) > 0
    bool outside;  // wo on the front face of ng (outside a transmissive object)
};

inline bool setUpSide(const Vec3& wo, const Vec3& ns, const Vec3& ng, Side* s) {
    const float dg = glm::dot(wo, ng);
    if (!(dg != 0.f) || !std::isfinite(dg)) return false;  // wo in the geometric plane (or NaN)
    s->outside = dg > 0.f;
    s->n = s->outside ? ns : -ns;
    s->g = s->outside ? ng : -ng;
    s->frame = FrameD(glm::dvec3(s->n));
    s->lo = s->frame.toLocal(glm::dvec3(wo));
    const double len = glm::length(s->lo);
    if (!(len > 0.0) || !std::isfinite(len)) return false;
    s->lo /= len;
    return s->lo.z > 0.0;  // wo below the shading hemisphere: nothing is reflected
}

inline bool diffuseActive(const MaterialParams& p) {
    return (1.f - p.metallic) * (1.f - p.transmission) > 0.f && maxComponent(p.baseColor) > 0.f;
}
inline bool specularActive(const MaterialParams& p) {
    return p.metallic > 0.f || ((1.f - p.metallic) > 0.f && p.specular > 0.f);
}
inline bool transmissionActive(const MaterialParams& p) {
    return (1.f - p.metallic) * p.transmission > 0.f && maxComponent(p.baseColor) > 0.f;
}

// The diffuse lobe (fresnel_mix with KHR_materials_specular: base weighted by 1 - max_value(F_d)).
inline Rgb diffuseTerm(const MaterialParams& p, float vDotH) {
    const Rgb fd = fresnelDielectricSchlick(p, vDotH);
    const float kd = (1.f - p.metallic) * (1.f - p.transmission) * (1.f - maxComponent(fd));
    return p.baseColor * (kd * kInvPi);
}

// Veach's adjoint shading-normal factor |wo.ns||wi.ng| / (|wo.ng||wi.ns|) (Importance only).
inline float adjointFactor(const Vec3& wo, const Vec3& wi, const Vec3& ns, const Vec3& ng) {
    const float num = absDot(wo, ns) * absDot(wi, ng);
    const float den = absDot(wo, ng) * absDot(wi, ns);
    const float r = num / den;
    return den > 0.f && std::isfinite(r) ? r : 0.f;  // 0 for no direction (Inf / Inf), not NaN
}

// li in the local frame of s, normalised; false unless wi is a valid reflection direction
// (same geometric side as wo and above the shading hemisphere).
inline bool reflectionLocal(const Side& s, const Vec3& wi, glm::dvec3* li) {
    if (!(glm::dot(wi, s.g) > 0.f)) return false;
    *li = s.frame.toLocal(glm::dvec3(wi));
    const double len = glm::length(*li);
    if (!(len > 0.0) || !std::isfinite(len)) return false;
    *li /= len;
    return li->z > 0.0;
}

// li for a refraction direction: wi on the other geometric side and below the shading hemisphere.
inline bool transmissionLocal(const Side& s, const Vec3& wi, glm::dvec3* li) {
    if (!(glm::dot(wi, s.g) < 0.f)) return false;
    *li = s.frame.toLocal(glm::dvec3(wi));
    const double len = glm::length(*li);
    if (!(len > 0.0) || !std::isfinite(len)) return false;
    *li /= len;
    return li->z < 0.0;
}

// The parameters as the BSDF uses them (bsdf.cpp): clamped to their ranges, ior 0 and
// near-delta rough transmission resolved. Also what trace's diagnosis reads (src/verify).
MaterialParams sanitizedParams(const MaterialParams& params);

}  // namespace bsdf_detail
}  // namespace bdptref
