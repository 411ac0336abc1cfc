// The glTF 2.0 metallic-roughness BSDF (spec Appendix B) with KHR_materials_specular,
// KHR_materials_ior, KHR_materials_transmission and the KHR_materials_sheen and
// KHR_materials_clearcoat layers. Every formula, convention and deviation from
// the spec is written down in docs/materials.md, with the names of the functions below.
#include "bdptref/bsdf.h"

#include "bdptref/sampling.h"
#include "bsdf_clearcoat.h"
#include "bsdf_rough_dielectric.h"
#include "bsdf_sheen.h"
#include "bsdf_terms.h"

#include <algorithm>
#include <cmath>

namespace bdptref {

using namespace bsdf_detail;

namespace {

struct Lobes {
    float pDiffuse = 0.f, pSpecular = 0.f, pTransmit = 0.f;  // selection probabilities
    // Delta lobes (alpha == 0 only): reflectance / transmittance, i.e. f * |cos(wi, ns)|.
    Rgb deltaReflect{0.f}, deltaTransmit{0.f};
    float eta = 1.f;   // IOR on wi's side / IOR on wo's side for the refraction
    float cosT = 0.f;  // cosine of the refracted direction (0 under TIR)
};

// Selection probabilities (functions of wo and the parameters only) and, for roughness 0, the
// delta lobes' weights. See docs/materials.md, "Lobe selection".
Lobes computeLobes(const MaterialParams& p, float alpha, const Side& s) {
    Lobes L;
    const float cosO = float(s.lo.z);
    const float m = p.metallic;
    const Rgb fd = fresnelDielectricSchlick(p, cosO);
    float wD = 0.f, wS = 0.f, wT = 0.f;
    if (diffuseActive(p)) {
        wD = luminance((1.f - m) * (1.f - p.transmission) * p.baseColor) * (1.f - maxComponent(fd));
        wD = std::max(wD, kMinLobeWeight);
    }
    if (alpha > 0.f) {
        if (specularActive(p)) {
            wS = std::max(luminance((1.f - m) * fd + m * fresnelMetal(p, cosO)), kMinLobeWeight);
        }
    } else {
        Rgb fDiel = fd;
        if (p.transmission > 0.f) {
            L.eta = s.outside ? p.ior : 1.f / p.ior;
            const float fExact = fresnelDielectricExact(cosO, L.eta, &L.cosT);
            fDiel = fresnelTransmissive(p, fExact);
            if (L.cosT > 0.f && transmissionActive(p)) {
                L.deltaTransmit = (1.f - m) * p.transmission * (1.f - maxComponent(fDiel)) * p.baseColor;
            }
        }
        L.deltaReflect = (1.f - m) * fDiel + m * fresnelMetal(p, cosO);
        wS = luminance(L.deltaReflect);
        wT = luminance(L.deltaTransmit);
    }
    const float total = wD + wS + wT;
    if (total > 0.f) {
        L.pDiffuse = wD / total;
        L.pSpecular = wS / total;
        L.pTransmit = wT / total;
    }
    return L;
}

// The non-delta reflection (diffuse + GGX lobe) for a pair with lo.z > 0 and li.z > 0.
Rgb evalReflection(const MaterialParams& p, float alpha, const glm::dvec3& lo, const glm::dvec3& li) {
    const glm::dvec3 h = glm::normalize(lo + li);
    const float vDotH = float(std::abs(glm::dot(lo, h)));
    Rgb result(0.f);
    if (diffuseActive(p)) result += diffuseTerm(p, vDotH);
    if (alpha > 0.f && specularActive(p)) {
        const double a = alpha;
        const double spec = ggxD(h, a) * smithG1(lo, a) * smithG1(li, a) / (4.0 * lo.z * li.z);
        const Rgb F = (1.f - p.metallic) * fresnelDielectricSchlick(p, vDotH) + p.metallic * fresnelMetal(p, vDotH);
        result += F * float(spec);
    }
    return result;
}

// Density of the non-delta lobes (solid angle), selection probabilities included.
double pdfReflection(float alpha, const Lobes& L, const glm::dvec3& lo, const glm::dvec3& li) {
    double pdf = double(L.pDiffuse) * li.z / kPiD;
    if (alpha > 0.f && L.pSpecular > 0.f) {
        const glm::dvec3 h = glm::normalize(lo + li);
        // VNDF pdf: G1(wo) D(h) max(0, wo.h) / (wo.n) / (4 wo.h) = G1(wo) D(h) / (4 wo.n).
        pdf += double(L.pSpecular) * smithG1(lo, alpha) * ggxD(h, alpha) / (4.0 * lo.z);
    }
    return pdf;
}

// Unit-length copy (in double) of a nearly unit vector; unchanged if it has no length.
Vec3 normalizedOr(const Vec3& v) {
    const glm::dvec3 d(v);
    const double len = glm::length(d);
    return len > 0.0 && std::isfinite(len) ? Vec3(d / len) : v;
}

}  // namespace

// The parameters as the BSDF uses them: clamped to their ranges, ior 0 and transmission resolved.
MaterialParams bsdf_detail::sanitizedParams(const MaterialParams& params) {
    MaterialParams p = params;
    p.baseColor = clampColor01(p.baseColor);
    p.metallic = clamp01(p.metallic);
    p.roughness = clamp01(p.roughness);
    p.transmission = clamp01(p.transmission);
    p.specular = clamp01(p.specular);
    p.specularColor = clampColorNonNegative(p.specularColor);
    if (!(p.ior >= 0.f) || !std::isfinite(p.ior)) p.ior = 1.5f;
    // ior 0 means F0 = 1 (KHR_materials_specular's specular-glossiness conversion); it has no
    // refraction direction, so such a material is not transmissive.
    if (p.ior == 0.f) p.transmission = 0.f;
    p.sheenColor = clampColor01(p.sheenColor);
    p.sheenRoughness = clamp01(p.sheenRoughness);
    p.clearcoat = clamp01(p.clearcoat);
    p.clearcoatRoughness = clamp01(p.clearcoatRoughness);
    // Near-delta rough transmission: a refracted lobe narrower than kMinRefractedLobeWidth (about
    // alpha |1 - 1/ior| radians) is the smooth delta pair, for all specular lobes of the material.
    if (p.transmission > 0.f && p.roughness > 0.f) {
        const float alpha = std::max(p.roughness * p.roughness, kMinAlpha);
        if (!(alpha * std::abs(1.f - 1.f / p.ior) >= kMinRefractedLobeWidth)) p.roughness = 0.f;
    }
    return p;
}

namespace {

float ggxAlpha(const MaterialParams& p) { return bsdf_detail::ggxAlpha(p.roughness); }

bool nonDelta(const MaterialParams& p, float alpha) {
    return diffuseActive(p) || (alpha > 0.f && (specularActive(p) || transmissionActive(p))) ||
           (p.clearcoat > 0.f && p.clearcoatRoughness > 0.f) ||  // a rough coat
           maxComponent(p.sheenColor) > 0.f;
}

// The base's albedo as the coat's lobe selection sees it (docs/materials.md, "Clearcoat"): the
// luminance of what the base reflects or transmits at normal incidence, at least kMinLobeWeight.
float baseAlbedoEstimate(const MaterialParams& p) {
    const float a = luminance(p.baseColor) + (1.f - p.metallic) * maxComponent(dielectricF0(p));
    return std::clamp(a, kMinLobeWeight, 1.f);
}

// Unit normals arrive already normalised (SurfaceHit, PathVertex); renormalising them in double
// only matters when they are not unit in float.
Vec3 unitNormal(const Vec3& v) { return glm::dot(v, v) == 1.f ? v : normalizedOr(v); }

}  // namespace

Bsdf::Bsdf(const MaterialParams& params, const Vec3& ns, const Vec3& ng)
    : p_(sanitizedParams(params)), ns_(unitNormal(ns)), ng_(unitNormal(ng)) {
    alpha_ = ggxAlpha(p_);
    hasNonDelta_ = nonDelta(p_, alpha_);
    roughDielectric_ = alpha_ > 0.f && p_.transmission > 0.f;
    pureDiffuse_ = diffuseActive(p_) && !specularActive(p_) && !transmissionActive(p_);
    if (maxComponent(p_.sheenColor) > 0.f) {
        sheened_ = true;
        sheen_.color = p_.sheenColor;
        sheen_.roughness = std::max(p_.sheenRoughness, kMinSheenRoughness);
        sheen_.baseAlbedo = baseAlbedoEstimate(p_);
    }
    if (p_.clearcoat > 0.f) {
        coated_ = true;
        coat_.weight = p_.clearcoat;
        coat_.alpha = ggxAlpha(p_.clearcoatRoughness);
        const float len2 = glm::dot(p_.clearcoatNormal, p_.clearcoatNormal);
        // The coat normal on ng's front side, like ns (a map can only tilt it within that side).
        coat_.n = len2 > 0.f && std::isfinite(len2) ? unitNormal(p_.clearcoatNormal) : ns_;
        if (glm::dot(coat_.n, ng_) < 0.f) coat_.n = -coat_.n;
        // Under the coat: the core, plus what a sheen adds at normal incidence.
        const float sheenAlbedoAtNormal = sheened_ ? luminance(p_.sheenColor) * sheenAlbedo(1.f, sheen_.roughness) : 0.f;
        coat_.baseAlbedo = std::min(1.f, baseAlbedoEstimate(p_) + sheenAlbedoAtNormal);
    }
    if (pureDiffuse_) {
        // evalReflection's diffuse term with F_d = 0 (specular 0 makes dielectric_f0 and f90 zero).
        const Rgb fd = fresnelDielectricSchlick(p_, 1.f);
        const float kd = (1.f - p_.metallic) * (1.f - p_.transmission) * (1.f - maxComponent(fd));
        diffuseF_ = p_.baseColor * (kd * kInvPi);
    }
}

Bsdf Bsdf::atNormals(const Vec3& ns, const Vec3& ng) const {
    Bsdf b = *this;
    b.ns_ = unitNormal(ns);
    b.ng_ = unitNormal(ng);
    return b;
}

bool Bsdf::hasNonDelta(const MaterialParams& params) {
    const MaterialParams p = sanitizedParams(params);
    return nonDelta(p, ggxAlpha(p));
}

namespace {
// The Lambertian lobe in single precision (issue 31: what a GPU port computes; cosines, the frame
// and the density of a cosine lobe need no more). Validity rules of setUpSide + reflectionLocal:
// wo not in the geometric plane, wi on wo's geometric side, both above the shading hemisphere
// (the shading normal turned to wo's side). Directions are unit vectors; a non-finite one fails.
// *cosI = dot(wi, n), and the density is cosI / pi.
struct LambertSide {
    Vec3 n, g;  // shading and geometric normals on wo's side
};
// Inlined into its callers (~175 000 calls per 4 096 BDPT samples of a Lambertian scene, where
// the call and the LambertSide passed through memory were a third of its cost).
[[gnu::always_inline]] inline bool lambertSide(const Vec3& wo, const Vec3& ns, const Vec3& ng, LambertSide* side) {
    const float dg = glm::dot(wo, ng);
    if (!(dg != 0.f) || !std::isfinite(dg)) return false;
    side->n = dg > 0.f ? ns : -ns;
    side->g = dg > 0.f ? ng : -ng;
    const float lo = glm::dot(wo, side->n);
    return lo > 0.f && std::isfinite(lo);
}
[[gnu::always_inline]] inline bool lambertCosineOf(const LambertSide& side, const Vec3& wi, float* cosI) {
    if (!(glm::dot(wi, side.g) > 0.f)) return false;
    const float li = glm::dot(wi, side.n);
    if (!(li > 0.f) || !std::isfinite(li)) return false;
    *cosI = li;
    return true;
}
[[gnu::always_inline]] inline bool lambertCosines(const Vec3& wo, const Vec3& wi, const Vec3& ns, const Vec3& ng, float* cosI) {
    LambertSide side;
    return lambertSide(wo, ns, ng, &side) && lambertCosineOf(side, wi, cosI);
}
inline float lambertPdf(float cos) { return cos * kInvPi; }

// lambertCosines for (wa, wb) and (wb, wa) at once: when (wa, wb) passes, wb is on wa's geometric
// side, so (wb, wa) sees the same turned normals and the two dot products swapped (the same bits as
// two lambertCosines calls). False when either fails: the caller then asks separately.
[[gnu::always_inline]] inline bool lambertCosinePair(const Vec3& wa, const Vec3& wb, const Vec3& ns, const Vec3& ng, float* cosB,
                                                   float* cosA) {
    LambertSide side;
    return lambertSide(wa, ns, ng, &side) && lambertCosineOf(side, wb, cosB) && lambertCosineOf(side, wa, cosA);
}
}  // namespace

Rgb Bsdf::evaluate(const Vec3& wo, const Vec3& wi, TransportMode mode, float* pdf) const {
    if (pureDiffuse_ && !roughDielectric_ && !sheened_ && !coated_) {  // coreF's and corePdf's Lambert branches
        float cosI;
        if (!lambertCosines(wo, wi, ns_, ng_, &cosI)) {
            *pdf = 0.f;
            return Rgb(0.f);
        }
        *pdf = lambertPdf(cosI);
        return mode == TransportMode::Importance ? diffuseF_ * adjointFactor(wo, wi, ns_, ng_) : diffuseF_;
    }
    *pdf = this->pdf(wo, wi);
    return f(wo, wi, mode);
}

void Bsdf::pdfBothWays(const Vec3& wa, const Vec3& wb, float* ab, float* ba) const {
    if (pureDiffuse_ && !roughDielectric_ && !sheened_ && !coated_) {  // pdf() is corePdf's Lambert branch
        float cosB, cosA;
        if (lambertCosinePair(wa, wb, ns_, ng_, &cosB, &cosA)) {
            *ab = lambertPdf(cosB);
            *ba = lambertPdf(cosA);
            return;
        }
    }
    *ab = pdf(wa, wb);
    *ba = pdf(wb, wa);
}

Rgb Bsdf::evaluateBothWays(const Vec3& wa, const Vec3& wb, TransportMode mode, float* ab, float* ba) const {
    const bool layered = roughDielectric_ || sheened_ || coated_;
    if (pureDiffuse_ && !layered) {  // coreF's and corePdf's Lambert branches
        float cosB, cosA;
        if (lambertCosinePair(wa, wb, ns_, ng_, &cosB, &cosA)) {
            *ab = lambertPdf(cosB);
            *ba = lambertPdf(cosA);
            return mode == TransportMode::Importance ? diffuseF_ * adjointFactor(wa, wb, ns_, ng_) : diffuseF_;
        }
    } else if (!layered) {
        Rgb value;
        if (coreReflectionBothWays(wa, wb, mode, &value, ab, ba)) return value;
    }
    pdfBothWays(wa, wb, ab, ba);
    return f(wa, wb, mode);
}

// coreF(wa, wb), corePdf(wa, wb) and corePdf(wb, wa) of a reflection pair. wb lies on wa's
// geometric side, so setUpSide(wb) would turn the normals the same way and build the same frame,
// and its lo is the li computed here (the same toLocal and division): one side serves all three.
bool Bsdf::coreReflectionBothWays(const Vec3& wa, const Vec3& wb, TransportMode mode, Rgb* f, float* ab,
                                  float* ba) const {
    Side sa;
    glm::dvec3 lb;
    if (!setUpSide(wa, ns_, ng_, &sa) || !reflectionLocal(sa, wb, &lb)) return false;
    *f = evalReflection(p_, alpha_, sa.lo, lb);
    if (mode == TransportMode::Importance) *f *= adjointFactor(wa, wb, ns_, ng_);
    *ab = float(pdfReflection(alpha_, computeLobes(p_, alpha_, sa), sa.lo, lb));
    Side sb = sa;
    sb.lo = lb;
    *ba = float(pdfReflection(alpha_, computeLobes(p_, alpha_, sb), lb, sa.lo));
    return true;
}

Rgb Bsdf::coreF(const Vec3& wo, const Vec3& wi, TransportMode mode) const {
    if (roughDielectric_) return roughTransmissiveF(p_, alpha_, ns_, ng_, wo, wi, mode);
    if (pureDiffuse_) {
        float cosI;
        if (!lambertCosines(wo, wi, ns_, ng_, &cosI)) return Rgb(0.f);
        return mode == TransportMode::Importance ? diffuseF_ * adjointFactor(wo, wi, ns_, ng_) : diffuseF_;
    }
    Side s;
    if (!setUpSide(wo, ns_, ng_, &s)) return Rgb(0.f);
    glm::dvec3 li;
    if (!reflectionLocal(s, wi, &li)) return Rgb(0.f);  // smooth transmission is delta-only
    Rgb value = evalReflection(p_, alpha_, s.lo, li);
    if (mode == TransportMode::Importance) value *= adjointFactor(wo, wi, ns_, ng_);
    return value;
}

float Bsdf::corePdf(const Vec3& wo, const Vec3& wi) const {
    if (roughDielectric_) return roughTransmissivePdf(p_, alpha_, ns_, ng_, wo, wi);
    if (pureDiffuse_) {  // the only lobe: selection probability 1
        float cosI;
        return lambertCosines(wo, wi, ns_, ng_, &cosI) ? lambertPdf(cosI) : 0.f;
    }
    Side s;
    if (!setUpSide(wo, ns_, ng_, &s)) return 0.f;
    glm::dvec3 li;
    if (!reflectionLocal(s, wi, &li)) return 0.f;
    const Lobes L = computeLobes(p_, alpha_, s);
    return float(pdfReflection(alpha_, L, s.lo, li));
}

// Lambert sampling in single precision (most surfaces of most scenes): the only lobe, selected with
// probability 1, a cosine-weighted direction about the shading normal on wo's side in a float frame
// (Frame, math.h), and the density of that direction as pdf() computes it (lambertCosines).
namespace {
bool sampleLambert(const Rgb& diffuseF, const Vec3& ns, const Vec3& ng, const Vec3& wo, Vec2 u, TransportMode mode,
                   BsdfSample* out) {
    LambertSide side;
    if (!lambertSide(wo, ns, ng, &side)) return false;
    const Vec3 local = squareToCosineHemisphere(u);
    if (!(local.z > 0.f)) return false;
    const Vec3 wi = glm::normalize(Frame(side.n).toWorld(local));
    float cosI;
    if (!lambertCosineOf(side, wi, &cosI)) return false;
    const float pdf = lambertPdf(cosI);
    if (!(pdf > 0.f)) return false;
    out->wi = wi;
    out->f = mode == TransportMode::Importance ? diffuseF * adjointFactor(wo, wi, ns, ng) : diffuseF;
    out->pdf = pdf;
    out->delta = false;
    out->transmission = false;
    return true;
}
}  // namespace

bool Bsdf::coreSample(const Vec3& wo, float uLobe, Vec2 u, TransportMode mode, BsdfSample* out) const {
    if (roughDielectric_) return roughTransmissiveSample(p_, alpha_, ns_, ng_, wo, uLobe, u, mode, out);
    if (pureDiffuse_) return sampleLambert(diffuseF_, ns_, ng_, wo, u, mode, out);
    Side s;
    if (!setUpSide(wo, ns_, ng_, &s)) return false;
    const Lobes L = computeLobes(p_, alpha_, s);

    // Lobe choice: diffuse on [0, pD), specular on [pD, pD + pS), transmission above. Rounding at
    // the top end falls back to the last lobe with non-zero probability.
    enum { kDiffuse, kSpecular, kTransmit, kNone } lobe = kNone;
    if (uLobe < L.pDiffuse) lobe = kDiffuse;
    else if (uLobe < L.pDiffuse + L.pSpecular) lobe = kSpecular;
    else if (L.pTransmit > 0.f) lobe = kTransmit;
    else if (L.pSpecular > 0.f) lobe = kSpecular;
    else if (L.pDiffuse > 0.f) lobe = kDiffuse;
    if (lobe == kNone) return false;

    const float cosO = float(s.lo.z);
    if (lobe == kDiffuse || (lobe == kSpecular && alpha_ > 0.f)) {
        glm::dvec3 liLocal;
        if (lobe == kDiffuse) {
            liLocal = glm::dvec3(squareToCosineHemisphere(u));
        } else {
            const glm::dvec3 h = sampleGgxVndf(s.lo, alpha_, u.x, u.y);
            liLocal = 2.0 * glm::dot(s.lo, h) * h - s.lo;
        }
        if (!(liLocal.z > 0.0)) return false;
        const Vec3 wi(glm::normalize(s.frame.toWorld(liLocal)));
        glm::dvec3 li;
        if (!reflectionLocal(s, wi, &li)) return false;
        const float pdf = float(pdfReflection(alpha_, L, s.lo, li));
        if (!(pdf > 0.f) || !std::isfinite(pdf)) return false;
        Rgb value = evalReflection(p_, alpha_, s.lo, li);
        if (mode == TransportMode::Importance) value *= adjointFactor(wo, wi, ns_, ng_);
        out->wi = wi;
        out->f = value;
        out->pdf = pdf;
        out->delta = false;
        out->transmission = false;
        return true;
    }

    if (lobe == kSpecular) {  // delta reflection about the shading normal
        const Vec3 wi = glm::normalize(2.f * cosO * s.n - wo);
        const float cosI = glm::dot(wi, s.n);
        if (!(glm::dot(wi, s.g) > 0.f) || !(cosI > 0.f)) return false;
        Rgb value = L.deltaReflect / cosI;
        if (mode == TransportMode::Importance) value *= adjointFactor(wo, wi, ns_, ng_);
        out->wi = wi;
        out->f = value;
        out->pdf = L.pSpecular;
        out->delta = true;
        out->transmission = false;
        return true;
    }

    // Delta refraction about the shading normal; eta = eta(wi side) / eta(wo side).
    const float invEta = 1.f / L.eta;
    const Vec3 wi = glm::normalize(-invEta * wo + (invEta * cosO - L.cosT) * s.n);
    const float cosI = -glm::dot(wi, s.n);
    if (!(glm::dot(wi, s.g) < 0.f) || !(cosI > 0.f)) return false;
    Rgb value = L.deltaTransmit / cosI;
    if (mode == TransportMode::Radiance) value *= invEta * invEta;  // (eta_o / eta_i)^2
    else value *= adjointFactor(wo, wi, ns_, ng_);
    out->wi = wi;
    out->f = value;
    out->pdf = L.pTransmit;
    out->delta = true;
    out->transmission = true;
    return true;
}

// --- The sheen layer over the core (docs/materials.md, "Sheen") -------------------------------
// Without a sheen, the base is the core, unchanged. With one (reciprocal, so Importance mode is
// the adjoint factor times Radiance mode for the sheen lobe; the core keeps its own rule):
//   f(wo, wi)   = sheenF(wo, wi) + S(wo, wi) f_core(wo, wi),  S = sheenBaseScale (symmetric),
//   pdf(wo, wi) = P_s sheenPdf(wo, wi) + (1 - P_s) pdf_core(wo, wi),  P_s = sheenSelectionProbability(wo).

Rgb Bsdf::baseF(const Vec3& wo, const Vec3& wi, TransportMode mode) const {
    if (!sheened_) return coreF(wo, wi, mode);
    Rgb sheen = sheenF(sheen_, ns_, ng_, wo, wi);
    if (mode == TransportMode::Importance && !isBlack(sheen)) sheen *= adjointFactor(wo, wi, ns_, ng_);
    return sheen + sheenBaseScale(sheen_, ns_, wo, wi) * coreF(wo, wi, mode);
}

float Bsdf::basePdf(const Vec3& wo, const Vec3& wi) const {
    if (!sheened_) return corePdf(wo, wi);
    const float pSheen = sheenSelectionProbability(sheen_, ns_, wo);
    return float(double(pSheen) * sheenPdf(ns_, ng_, wo, wi) + double(1.f - pSheen) * double(corePdf(wo, wi)));
}

bool Bsdf::baseSample(const Vec3& wo, float uLobe, Vec2 u, TransportMode mode, BsdfSample* out) const {
    if (!sheened_) return coreSample(wo, uLobe, u, mode, out);
    const float pSheen = sheenSelectionProbability(sheen_, ns_, wo);
    if (uLobe < pSheen) {
        Vec3 wi;
        if (!sampleSheenDirection(ns_, ng_, wo, u, &wi)) return false;
        out->wi = wi;
        out->transmission = false;
        out->delta = false;
        out->f = baseF(wo, wi, mode);
        out->pdf = basePdf(wo, wi);
        return out->pdf > 0.f && std::isfinite(out->pdf);
    }
    const float uCore = std::min((uLobe - pSheen) / (1.f - pSheen), 0x1.fffffep-1f);
    if (!coreSample(wo, uCore, u, mode, out)) return false;
    if (out->delta) {
        out->f *= sheenBaseScale(sheen_, ns_, wo, out->wi);
        out->pdf *= 1.f - pSheen;
        return out->pdf > 0.f;
    }
    out->f = baseF(wo, out->wi, mode);
    out->pdf = basePdf(wo, out->wi);
    return out->pdf > 0.f && std::isfinite(out->pdf);
}

// --- The clearcoat layer over the base (docs/materials.md, "Clearcoat") -----------------------
// Without a coat, f/pdf/sample are the base's, unchanged. With one:
//   f(wo, wi)   = (1 - clearcoat F_c(|V.n_c|)) f_base(wo, wi) + f_coat(wo, wi),
//   pdf(wo, wi) = P_c pdf_coat(wo, wi) + (1 - P_c) pdf_base(wo, wi),
// with V = wo (Radiance) or wi (Importance), P_c = coatSelectionProbability(wo), and f_coat in
// Importance mode the adjoint f_coat(wi, wo) * |wo.ns||wi.ng| / (|wo.ng||wi.ns|).

namespace {
float coatF(const Coat& c, const Vec3& ns, const Vec3& ng, const Vec3& wo, const Vec3& wi, TransportMode mode) {
    if (mode == TransportMode::Radiance) return coatRadianceF(c, ns, ng, wo, wi);
    return coatRadianceF(c, ns, ng, wi, wo) * adjointFactor(wo, wi, ns, ng);
}
}  // namespace

Rgb Bsdf::f(const Vec3& wo, const Vec3& wi, TransportMode mode) const {
    if (!coated_) return baseF(wo, wi, mode);
    const Vec3& v = mode == TransportMode::Radiance ? wo : wi;
    return coatBaseScale(coat_, v) * baseF(wo, wi, mode) + Rgb(coatF(coat_, ns_, ng_, wo, wi, mode));
}

float Bsdf::pdf(const Vec3& wo, const Vec3& wi) const {
    if (!coated_) return basePdf(wo, wi);
    const float pCoat = coatSelectionProbability(coat_, wo);
    return float(double(pCoat) * coatPdf(coat_, ns_, ng_, wo, wi) + double(1.f - pCoat) * double(basePdf(wo, wi)));
}

bool Bsdf::sample(const Vec3& wo, float uLobe, Vec2 u, TransportMode mode, BsdfSample* out) const {
    if (!coated_) return baseSample(wo, uLobe, u, mode, out);
    const float pCoat = coatSelectionProbability(coat_, wo);
    if (uLobe < pCoat) {
        Vec3 wi;
        if (!sampleCoatDirection(coat_, ns_, ng_, wo, u, &wi)) return false;
        out->wi = wi;
        out->transmission = false;
        if (coat_.alpha > 0.f) {  // the whole non-delta f and pdf of the direction
            out->f = f(wo, wi, mode);
            out->pdf = pdf(wo, wi);
            out->delta = false;
            return out->pdf > 0.f && std::isfinite(out->pdf);
        }
        // The mirror about n_c; stored as reflectance / |wi.ns| (bsdf.h). Importance is the
        // adjoint: the reflectance seen from V = wi, divided by |wo.ns|, times the adjoint factor.
        const float cosI = absDot(wi, ns_), cosO = absDot(wo, ns_);
        if (!(cosI > 0.f) || !(cosO > 0.f)) return false;
        out->f = mode == TransportMode::Radiance
                     ? Rgb(deltaCoatReflectance(coat_, wo) / cosI)
                     : Rgb(deltaCoatReflectance(coat_, wi) / cosO * adjointFactor(wo, wi, ns_, ng_));
        out->pdf = pCoat;
        out->delta = true;
        return true;
    }
    // The base, with the rest of uLobe rescaled to [0, 1).
    const float uBase = std::min((uLobe - pCoat) / (1.f - pCoat), 0x1.fffffep-1f);
    if (!baseSample(wo, uBase, u, mode, out)) return false;
    if (out->delta) {
        out->f *= coatBaseScale(coat_, mode == TransportMode::Radiance ? wo : out->wi);
        out->pdf *= 1.f - pCoat;
        return out->pdf > 0.f;
    }
    out->f = f(wo, out->wi, mode);
    out->pdf = pdf(wo, out->wi);
    return out->pdf > 0.f && std::isfinite(out->pdf);
}

}  // namespace bdptref
