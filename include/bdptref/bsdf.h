// The glTF metallic-roughness BSDF at one surface point (spec appendix B, plus
// KHR_materials_transmission/ior/specular/clearcoat/sheen). Lobes: Lambert diffuse, GGX (Trowbridge-Reitz,
// separable Smith) specular reflection, for roughness 0 exact delta reflection and (with
// transmission) delta refraction, and for rough transmission the GGX microfacet BTDF (Walter et al.
// 2007) with its reflection. Derivations and conventions: docs/materials.md.
//
// Conventions (shared by the path tracer, BDPT and the wavefront mode):
//  * All directions are world-space unit vectors pointing AWAY from the surface (wo towards the
//    previous vertex, wi towards the next one).
//  * f() and pdf() cover the non-delta lobes only. pdf() is in solid angle and already includes
//    the probability of choosing the lobe.
//  * For every sample, the throughput factor is  f * |dot(wi, ns)| / pdf ; for a delta lobe f is
//    stored divided by |dot(wi, ns)| and pdf is the discrete lobe probability, so the same formula
//    applies (pbrt's convention).
//  * Importance transport (light paths) includes the adjoint shading-normal correction
//    |wo.ns||wi.ng| / (|wo.ng||wi.ns|) (Veach 1997, ch. 5.3) in f() and sample(). Refraction
//    scales radiance by (eta_o/eta_i)^2 in Radiance mode only (eta_o: IOR on wo's side).
//  * Reflection vs transmission is decided by the GEOMETRIC normal (dot(wo,ng)*dot(wi,ng)), so
//    shading normals cannot leak light through a surface.
#pragma once

#include "bdptref/material.h"
#include "bdptref/math.h"

#include <type_traits>

namespace bdptref {

enum class TransportMode : uint8_t { Radiance, Importance };

struct BsdfSample {
    Vec3 wi;
    Rgb f{0.f};
    float pdf = 0.f;
    bool delta = false;
    bool transmission = false;
};

// The KHR_materials_clearcoat layer of a Bsdf (src/scene/bsdf_clearcoat.h).
struct ClearcoatLayer {
    float weight = 0.f;      // clearcoat in (0, 1]
    float alpha = 0.f;       // GGX alpha; 0: a delta (mirror) coat
    Vec3 n{0.f};             // the coat's unit normal, on the geometric normal's front side
    float baseAlbedo = 1.f;  // estimate of the base's albedo, for lobe selection only
};

// The KHR_materials_sheen layer of a Bsdf (src/scene/bsdf_sheen.h).
struct SheenLayer {
    Rgb color{0.f};          // sheenColor, not black
    float roughness = 0.f;   // sheenRoughness (floored where used)
    float baseAlbedo = 1.f;  // estimate of the albedo under the sheen, for lobe selection only
};

class Bsdf {
public:
    // An empty BSDF (zero normals: f, pdf and sample give nothing), so that BSDFs can live in preallocated side arrays
    // next to the PathVertex records (one per subpath vertex, built once, src/render/bdpt_vertex.h).
    Bsdf() = default;
    // ns: shading normal, ng: geometric normal (front face = counter-clockwise winding); both unit.
    Bsdf(const MaterialParams& params, const Vec3& ns, const Vec3& ng);

    Rgb f(const Vec3& wo, const Vec3& wi, TransportMode mode) const;
    float pdf(const Vec3& wo, const Vec3& wi) const;
    bool sample(const Vec3& wo, float uLobe, Vec2 u, TransportMode mode, BsdfSample* out) const;
    // f(wo, wi, mode) and *pdf = pdf(wo, wi) with the same bits as the two calls; a Lambertian
    // answers both from one cosine (next-event estimation asks for exactly this pair).
    Rgb evaluate(const Vec3& wo, const Vec3& wi, TransportMode mode, float* pdf) const;
    // Both densities of one pair of directions, *ab = pdf(wa, wb) and *ba = pdf(wb, wa), with the
    // same bits as the two pdf() calls; a Lambertian answers both from one set of cosines (the MIS
    // densities of a connection endpoint or a subpath vertex ask for exactly this pair).
    void pdfBothWays(const Vec3& wa, const Vec3& wb, float* ab, float* ba) const;
    // f(wa, wb, mode) with both densities, *ab = pdf(wa, wb) and *ba = pdf(wb, wa): the same bits
    // as the three calls, from one query (a connection endpoint asks for exactly these: its f and
    // the two MIS densities; docs/mis.md, "One BSDF query per connection endpoint"). A Lambertian
    // shares its cosines, the GGX reflection its side and local frame.
    Rgb evaluateBothWays(const Vec3& wa, const Vec3& wb, TransportMode mode, float* ab, float* ba) const;

    // This BSDF at other normals: the same bits as Bsdf(params, ns, ng) for the params that built
    // this one, when it has no clearcoat (whose normal defaults to ns; Scene::bsdfAt).
    Bsdf atNormals(const Vec3& ns, const Vec3& ng) const;

    bool hasNonDelta() const { return hasNonDelta_; }  // some lobe can be reached by a connection (f() may be non-zero)
    // The same answer for a material at a point, without building the BSDF (no normals needed).
    static bool hasNonDelta(const MaterialParams& params);
    bool isPureDelta() const { return !hasNonDelta(); }
    const Vec3& shadingNormal() const { return ns_; }
    const Vec3& geometricNormal() const { return ng_; }

private:
    MaterialParams p_{};
    Vec3 ns_{0.f}, ng_{0.f};
    float alpha_ = 0.f;  // GGX alpha = roughness^2 (0 => delta lobes)
    bool hasNonDelta_ = false;
    // Transmissive with alpha > 0: the rough dielectric lobe (src/scene/bsdf_rough_dielectric.cpp)
    // and the diffuse base replace the reflection-only lobes.
    bool roughDielectric_ = false;
    // Only the diffuse lobe is active (a Lambertian: no specular, no transmission): f and pdf
    // then need no local frame and no lobe selection: the same values as the general path up to
    // float rounding (src/scene/bsdf.cpp, lambertCosines).
    bool pureDiffuse_ = false;
    Rgb diffuseF_{0.f};  // f of that lobe: baseColor (1 - metallic)(1 - transmission) / pi
    // KHR_materials_clearcoat: the coat layered over the base lobes above (src/scene/bsdf.cpp,
    // src/scene/bsdf_clearcoat.cpp); f/pdf/sample are the base's alone when !coated_.
    // The layers, top down: the coat over the sheen over the core lobes above (base = sheen over
    // core). Each level is the one below it, unchanged, when its layer is absent.
    bool coated_ = false;
    ClearcoatLayer coat_;
    bool sheened_ = false;
    SheenLayer sheen_;
    Rgb baseF(const Vec3& wo, const Vec3& wi, TransportMode mode) const;
    float basePdf(const Vec3& wo, const Vec3& wi) const;
    bool baseSample(const Vec3& wo, float uLobe, Vec2 u, TransportMode mode, BsdfSample* out) const;
    Rgb coreF(const Vec3& wo, const Vec3& wi, TransportMode mode) const;
    float corePdf(const Vec3& wo, const Vec3& wi) const;
    // evaluateBothWays of the core reflection lobes (no layer, no rough dielectric, not a pure
    // Lambertian); false when (wa, wb) is no reflection pair (f and both densities are then 0).
    bool coreReflectionBothWays(const Vec3& wa, const Vec3& wb, TransportMode mode, Rgb* f, float* ab, float* ba) const;
    bool coreSample(const Vec3& wo, float uLobe, Vec2 u, TransportMode mode, BsdfSample* out) const;
};
static_assert(std::is_trivially_copyable_v<Bsdf>, "Bsdf side arrays live in wavefront pool buffers");

}  // namespace bdptref
