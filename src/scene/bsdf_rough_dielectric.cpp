// The rough dielectric lobe (GGX reflection + refraction, Walter et al. 2007) of a transmissive
// material with roughness > 0, and the Bsdf entry points of such a material (its lobes are the
// diffuse base, if t < 1, and this lobe). Formulas and their derivation: docs/materials.md,
// "Rough transmission"; the names below are the ones used there.
#include "bsdf_rough_dielectric.h"

#include "bdptref/sampling.h"

#include <algorithm>
#include <cmath>

namespace bdptref {
namespace bsdf_detail {

MicrofacetSplit microfacetSplit(const MaterialParams& p, bool outside, double cosOH) {
    const Etas eta = interfaceEtas(p, outside);
    const float c = float(std::min(1.0, std::max(0.0, cosOH)));
    float cosT = 0.f;
    const float fExact = fresnelDielectricExact(c, float(eta.i / eta.o), &cosT);
    const Rgb ft = fresnelTransmissive(p, fExact);
    const float m = p.metallic;
    MicrofacetSplit split;
    split.reflect = (1.f - m) * ft + m * fresnelMetal(p, c);
    if (cosT > 0.f) split.transmit = (1.f - m) * p.transmission * (1.f - maxComponent(ft)) * p.baseColor;
    const double wR = luminance(split.reflect), wT = luminance(split.transmit);
    split.pReflect = wT > 0.0 ? wR / (wR + wT) : 1.0;
    return split;
}

float roughDielectricSelectionWeight(const MaterialParams& p, bool outside, float cosO) {
    if (!specularActive(p) && !transmissionActive(p)) return 0.f;
    const MicrofacetSplit split = microfacetSplit(p, outside, cosO);
    return std::max(luminance(split.reflect) + luminance(split.transmit), kMinLobeWeight);
}

bool refractionHalfVector(const glm::dvec3& lo, const glm::dvec3& li, const Etas& eta, glm::dvec3* h) {
    glm::dvec3 v = eta.o * lo + eta.i * li;
    const double len = glm::length(v);
    if (!(len > 0.0) || !std::isfinite(len)) return false;
    v /= len;
    if (v.z < 0.0) v = -v;
    *h = v;
    return glm::dot(lo, v) > 0.0 && glm::dot(li, v) < 0.0;
}

RoughDielectricValue evalRoughDielectric(const MaterialParams& p, double alpha, bool outside, const glm::dvec3& lo,
                                         const glm::dvec3& li) {
    RoughDielectricValue r;
    if (li.z > 0.0) {  // reflection: f = F D G1(wo) G1(wi) / (4 cos_o cos_i), pdf = P_R G1(wo) D / (4 cos_o)
        const glm::dvec3 h = glm::normalize(lo + li);
        const double cosOH = glm::dot(lo, h);
        if (!(cosOH > 0.0)) return r;
        const MicrofacetSplit split = microfacetSplit(p, outside, cosOH);
        const double d = ggxD(h, alpha), g1o = smithG1(lo, alpha);
        r.f = split.reflect * float(d * g1o * smithG1(li, alpha) / (4.0 * lo.z * li.z));
        r.pdf = split.pReflect * g1o * d / (4.0 * lo.z);
        return r;
    }
    if (!(li.z < 0.0)) return r;
    const Etas eta = interfaceEtas(p, outside);
    glm::dvec3 h;
    if (!refractionHalfVector(lo, li, eta, &h)) return r;
    const double cosOH = glm::dot(lo, h), cosIH = glm::dot(li, h);  // cosOH > 0 > cosIH
    const MicrofacetSplit split = microfacetSplit(p, outside, cosOH);
    const double d = ggxD(h, alpha), g1o = smithG1(lo, alpha);
    const double den = eta.o * cosOH + eta.i * cosIH;
    // Jacobian of h -> wi: d(omega_h)/d(omega_i) = eta_i^2 |wi.h| / (eta_o wo.h + eta_i wi.h)^2.
    const double jacobian = eta.i * eta.i * std::abs(cosIH) / (den * den);
    // Importance form: |wo.h||wi.h| / (|cos_o||cos_i|) * eta_i^2 D G1 G1 / den^2 * T(h).
    const double fScalar = cosOH * jacobian * d * g1o * smithG1(li, alpha) / (lo.z * std::abs(li.z));
    if (!std::isfinite(fScalar) || !std::isfinite(jacobian)) return r;
    r.f = split.transmit * float(fScalar);
    r.pdf = (1.0 - split.pReflect) * g1o * d * cosOH / lo.z * jacobian;
    return r;
}

bool sampleRoughDielectric(const MaterialParams& p, double alpha, bool outside, const glm::dvec3& lo, double uChoice,
                           Vec2 u, glm::dvec3* li) {
    const glm::dvec3 h = sampleGgxVndf(lo, alpha, u.x, u.y);
    const double cosOH = glm::dot(lo, h);
    if (!(cosOH > 0.0)) return false;
    const MicrofacetSplit split = microfacetSplit(p, outside, cosOH);
    if (uChoice < split.pReflect) {
        *li = 2.0 * cosOH * h - lo;
        return li->z > 0.0;  // below the horizon: lost (pdf() counts it as neither lobe)
    }
    // Snell about h: wi = -lo / e + (cosOH / e - cosT) h with e = eta_i / eta_o.
    const Etas eta = interfaceEtas(p, outside);
    const double e = eta.i / eta.o;
    const double sin2T = (1.0 - cosOH * cosOH) / (e * e);
    if (sin2T >= 1.0) return false;  // unreachable: pReflect is 1 under total internal reflection
    const double cosT = std::sqrt(1.0 - sin2T);
    *li = -lo / e + (cosOH / e - cosT) * h;
    return li->z < 0.0;  // above the horizon: lost
}

namespace {

struct RoughLobes {
    double pDiffuse = 0.0, pDielectric = 0.0;
};

// Selection probabilities from wo: the diffuse base weighted as in computeLobes (bsdf.cpp) and
// this lobe by its reflectance + transmittance at cos_o.
RoughLobes roughLobes(const MaterialParams& p, const Side& s) {
    const float cosO = float(s.lo.z);
    float wD = 0.f;
    if (diffuseActive(p)) {
        const Rgb fd = fresnelDielectricSchlick(p, cosO);
        wD = std::max(luminance((1.f - p.metallic) * (1.f - p.transmission) * p.baseColor) * (1.f - maxComponent(fd)),
                      kMinLobeWeight);
    }
    const float wG = roughDielectricSelectionWeight(p, s.outside, cosO);
    RoughLobes L;
    const double total = double(wD) + double(wG);
    if (total > 0.0) {
        L.pDiffuse = wD / total;
        L.pDielectric = wG / total;
    }
    return L;
}

// f and pdf of the material at a valid (wo, wi): shared by f(), pdf() and sample().
struct RoughValue {
    Rgb f{0.f};
    double pdf = 0.0;
};
RoughValue roughValue(const MaterialParams& p, float alpha, const Vec3& ns, const Vec3& ng, const Vec3& wo,
                      const Vec3& wi, TransportMode mode) {
    RoughValue v;
    Side s;
    if (!setUpSide(wo, ns, ng, &s)) return v;
    const RoughLobes L = roughLobes(p, s);
    glm::dvec3 li;
    if (reflectionLocal(s, wi, &li)) {
        const RoughDielectricValue g = evalRoughDielectric(p, alpha, s.outside, s.lo, li);
        v.f = g.f;
        v.pdf = L.pDielectric * g.pdf;
        if (diffuseActive(p)) {
            v.f += diffuseTerm(p, float(std::abs(glm::dot(s.lo, glm::normalize(s.lo + li)))));
            v.pdf += L.pDiffuse * li.z / kPiD;
        }
    } else if (transmissionLocal(s, wi, &li)) {
        const RoughDielectricValue g = evalRoughDielectric(p, alpha, s.outside, s.lo, li);
        v.f = g.f;
        v.pdf = L.pDielectric * g.pdf;
        if (mode == TransportMode::Radiance) {  // radiance scales by (eta_o / eta_i)^2 across the interface
            const Etas eta = interfaceEtas(p, s.outside);
            v.f *= float((eta.o * eta.o) / (eta.i * eta.i));
        }
    } else {
        return v;
    }
    if (mode == TransportMode::Importance) v.f *= adjointFactor(wo, wi, ns, ng);
    return v;
}

}  // namespace

Rgb roughTransmissiveF(const MaterialParams& p, float alpha, const Vec3& ns, const Vec3& ng, const Vec3& wo,
                       const Vec3& wi, TransportMode mode) {
    return roughValue(p, alpha, ns, ng, wo, wi, mode).f;
}

float roughTransmissivePdf(const MaterialParams& p, float alpha, const Vec3& ns, const Vec3& ng, const Vec3& wo,
                           const Vec3& wi) {
    return float(roughValue(p, alpha, ns, ng, wo, wi, TransportMode::Radiance).pdf);
}

bool roughTransmissiveSample(const MaterialParams& p, float alpha, const Vec3& ns, const Vec3& ng, const Vec3& wo,
                             float uLobe, Vec2 u, TransportMode mode, BsdfSample* out) {
    Side s;
    if (!setUpSide(wo, ns, ng, &s)) return false;
    const RoughLobes L = roughLobes(p, s);
    glm::dvec3 liLocal;  // li.z > 0: a reflection was sampled, < 0: a refraction
    if (double(uLobe) < L.pDiffuse || !(L.pDielectric > 0.0)) {
        if (!(L.pDiffuse > 0.0)) return false;
        liLocal = glm::dvec3(squareToCosineHemisphere(u));
    } else {
        // The rest of uLobe's interval, rescaled to [0, 1), chooses reflection vs refraction.
        const double uChoice = std::min((double(uLobe) - L.pDiffuse) / L.pDielectric, 1.0 - 0x1p-53);
        if (!sampleRoughDielectric(p, alpha, s.outside, s.lo, uChoice, u, &liLocal)) return false;
    }
    const glm::dvec3 w = s.frame.toWorld(liLocal);
    const double len = glm::length(w);
    if (!(len > 0.0) || !std::isfinite(len)) return false;
    const Vec3 wi(w / len);
    // The geometric side must be the sampled one; otherwise f and pdf would be those of the other
    // kind of scattering at wi (shading normals): the sample is lost, as for the other lobes.
    if ((glm::dot(wi, s.g) > 0.f) != (liLocal.z > 0.0)) return false;
    const RoughValue v = roughValue(p, alpha, ns, ng, wo, wi, mode);
    const float pdf = float(v.pdf);
    if (!(pdf > 0.f) || !std::isfinite(pdf)) return false;
    out->wi = wi;
    out->f = v.f;
    out->pdf = pdf;
    out->delta = false;
    out->transmission = glm::dot(wi, s.g) < 0.f;
    return true;
}

}  // namespace bsdf_detail
}  // namespace bdptref
