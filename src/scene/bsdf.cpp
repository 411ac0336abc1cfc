// The glTF 2.0 metallic-roughness BSDF (spec Appendix B) with KHR_materials_specular,
// KHR_materials_ior and KHR_materials_transmission. Every formula, convention and deviation from
// the spec is written down in docs/materials.md, with the names of the functions below.
#include "bdptref/bsdf.h"

#include "bdptref/sampling.h"

#include <algorithm>
#include <cmath>

namespace bdptref {

namespace {

// Smallest GGX alpha used for roughness > 0 (roughness ~0.01). Keeps D, the VNDF warp and the
// pdf finite and float-resolvable (the lobe stays ~1e-4 rad wide, >1000x the float direction
// quantum). Roughness exactly 0 is never clamped: it selects the exact delta lobes.
constexpr float kMinAlpha = 1e-4f;
// Floor on the selection weight of an active non-delta lobe, so that a lobe whose f can be
// non-zero is never given selection probability 0 (which would make pdf 0 where f > 0).
constexpr float kMinLobeWeight = 1e-3f;

constexpr double kPiD = 3.14159265358979323846;

float clamp01(float x) { return x > 0.f ? (x < 1.f ? x : 1.f) : 0.f; }  // NaN -> 0
float nonNegative(float x) { return x > 0.f ? x : 0.f; }                 // NaN -> 0
Rgb clampColor01(const Rgb& c) { return Rgb(clamp01(c.r), clamp01(c.g), clamp01(c.b)); }
Rgb clampColorNonNegative(const Rgb& c) { return Rgb(nonNegative(c.r), nonNegative(c.g), nonNegative(c.b)); }

// (1 - c)^5 with c clamped to [0,1]: the Schlick weight.
float schlickWeight(float c) {
    const float m = clamp01(1.f - c);
    const float m2 = m * m;
    return m2 * m2 * m;
}

// KHR_materials_ior: F0 of the interface between the outside (IOR 1) and the material.
float iorF0(float ior) { return sqr((ior - 1.f) / (ior + 1.f)); }

// KHR_materials_specular: dielectric_f0 = min(iorF0 * specularColor, 1) * specular.
Rgb dielectricF0(const MaterialParams& p) {
    return glm::min(iorF0(p.ior) * p.specularColor, Rgb(1.f)) * p.specular;
}

// Spec: dielectric Fresnel F_d(c) = f0 + (f90 - f0)(1 - c)^5 with f90 = specular.
Rgb fresnelDielectricSchlick(const MaterialParams& p, float c) {
    const Rgb f0 = dielectricF0(p);
    return f0 + (Rgb(p.specular) - f0) * schlickWeight(c);
}

// Spec: conductor Fresnel F_m(c) = baseColor + (1 - baseColor)(1 - c)^5.
Rgb fresnelMetal(const MaterialParams& p, float c) {
    return p.baseColor + (Rgb(1.f) - p.baseColor) * schlickWeight(c);
}

// Exact unpolarised Fresnel reflectance of a smooth dielectric interface (Born & Wolf).
// cosI in (0,1] on the incident side, eta = eta_transmitted / eta_incident. Returns 1 under total
// internal reflection; *cosT receives the cosine of the refracted direction (0 under TIR).
float fresnelDielectricExact(float cosI, float eta, float* cosT) {
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
Rgb fresnelTransmissive(const MaterialParams& p, float fExact) {
    const float F0 = iorF0(p.ior);
    const float w = F0 < 1.f ? clamp01((fExact - F0) / (1.f - F0)) : 1.f;
    const Rgb f0 = dielectricF0(p);
    return f0 + (Rgb(p.specular) - f0) * w;
}

// --- GGX (Trowbridge-Reitz) with separable Smith shadowing, in the local shading frame --------

// D(h) = a^2 / (pi ((n.h)^2 (a^2 - 1) + 1)^2), written as a^2 / (pi (hx^2 + hy^2 + a^2 hz^2)^2)
// for a unit h (the same value without the cancellation in 1 - (n.h)^2).
double ggxD(const glm::dvec3& h, double alpha) {
    if (h.z <= 0.0) return 0.0;
    const double a2 = alpha * alpha;
    const double d = h.x * h.x + h.y * h.y + a2 * h.z * h.z;
    return a2 / (kPiD * d * d);
}

// G1(v) = 2 |n.v| / (|n.v| + sqrt(a^2 + (1 - a^2)(n.v)^2)); (1-a^2)(n.v)^2 + a^2 is evaluated as
// vz^2 + a^2 (vx^2 + vy^2) for a unit v.
double smithG1(const glm::dvec3& v, double alpha) {
    const double z = std::abs(v.z);
    if (z == 0.0) return 0.0;
    const double r = std::sqrt(z * z + alpha * alpha * (v.x * v.x + v.y * v.y));
    return 2.0 * z / (z + r);
}

// Visible-normal sampling (Heitz 2018, "Sampling the GGX Distribution of Visible Normals",
// JCGT 7(4)); v is the local outgoing direction with v.z > 0. Density of the returned h:
// G1(v) max(0, v.h) D(h) / v.z.
glm::dvec3 sampleGgxVndf(const glm::dvec3& v, double alpha, double u1, double u2) {
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

bool setUpSide(const Vec3& wo, const Vec3& ns, const Vec3& ng, Side* s) {
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

struct Lobes {
    float pDiffuse = 0.f, pSpecular = 0.f, pTransmit = 0.f;  // selection probabilities
    // Delta lobes (alpha == 0 only): reflectance / transmittance, i.e. f * |cos(wi, ns)|.
    Rgb deltaReflect{0.f}, deltaTransmit{0.f};
    float eta = 1.f;   // IOR on wi's side / IOR on wo's side for the refraction
    float cosT = 0.f;  // cosine of the refracted direction (0 under TIR)
};

bool diffuseActive(const MaterialParams& p) {
    return (1.f - p.metallic) * (1.f - p.transmission) > 0.f && maxComponent(p.baseColor) > 0.f;
}
bool specularActive(const MaterialParams& p) {
    return p.metallic > 0.f || ((1.f - p.metallic) > 0.f && p.specular > 0.f);
}
bool transmissionActive(const MaterialParams& p) {
    return (1.f - p.metallic) * p.transmission > 0.f && maxComponent(p.baseColor) > 0.f;
}

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

// Veach's adjoint shading-normal factor |wo.ns||wi.ng| / (|wo.ng||wi.ns|) (Importance only).
float adjointFactor(const Vec3& wo, const Vec3& wi, const Vec3& ns, const Vec3& ng) {
    const float num = absDot(wo, ns) * absDot(wi, ng);
    const float den = absDot(wo, ng) * absDot(wi, ns);
    return den > 0.f ? num / den : 0.f;
}

// The non-delta reflection (diffuse + GGX lobe) for a pair with lo.z > 0 and li.z > 0.
Rgb evalReflection(const MaterialParams& p, float alpha, const glm::dvec3& lo, const glm::dvec3& li) {
    const glm::dvec3 h = glm::normalize(lo + li);
    const float vDotH = float(std::abs(glm::dot(lo, h)));
    Rgb result(0.f);
    if (diffuseActive(p)) {
        // fresnel_mix with KHR_materials_specular: base weighted by 1 - max_value(F_d).
        const Rgb fd = fresnelDielectricSchlick(p, vDotH);
        const float kd = (1.f - p.metallic) * (1.f - p.transmission) * (1.f - maxComponent(fd));
        result += p.baseColor * (kd * kInvPi);
    }
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

// li in the local frame of s, normalised; false unless wi is a valid reflection direction
// (same geometric side as wo and above the shading hemisphere).
bool reflectionLocal(const Side& s, const Vec3& wi, glm::dvec3* li) {
    if (!(glm::dot(wi, s.g) > 0.f)) return false;
    *li = s.frame.toLocal(glm::dvec3(wi));
    const double len = glm::length(*li);
    if (!(len > 0.0) || !std::isfinite(len)) return false;
    *li /= len;
    return li->z > 0.0;
}

// Unit-length copy (in double) of a nearly unit vector; unchanged if it has no length.
Vec3 normalizedOr(const Vec3& v) {
    const glm::dvec3 d(v);
    const double len = glm::length(d);
    return len > 0.0 && std::isfinite(len) ? Vec3(d / len) : v;
}

}  // namespace

namespace {

// The parameters as the BSDF uses them: clamped to their ranges, ior 0 and transmission resolved.
MaterialParams sanitize(const MaterialParams& params) {
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
    // Transmission is smooth only (rough transmission is rejected by the loader): a transmissive
    // material is treated as roughness 0 for all of its specular lobes.
    if (p.transmission > 0.f) p.roughness = 0.f;
    return p;
}

float ggxAlpha(const MaterialParams& p) { return p.roughness > 0.f ? std::max(p.roughness * p.roughness, kMinAlpha) : 0.f; }

bool nonDelta(const MaterialParams& p, float alpha) { return diffuseActive(p) || (alpha > 0.f && specularActive(p)); }

// Unit normals arrive already normalised (SurfaceHit, PathVertex); renormalising them in double
// only matters when they are not unit in float.
Vec3 unitNormal(const Vec3& v) { return glm::dot(v, v) == 1.f ? v : normalizedOr(v); }

}  // namespace

Bsdf::Bsdf(const MaterialParams& params, const Vec3& ns, const Vec3& ng)
    : p_(sanitize(params)), ns_(unitNormal(ns)), ng_(unitNormal(ng)) {
    alpha_ = ggxAlpha(p_);
    hasNonDelta_ = nonDelta(p_, alpha_);
    pureDiffuse_ = diffuseActive(p_) && !specularActive(p_) && !transmissionActive(p_);
    if (pureDiffuse_) {
        // evalReflection's diffuse term with F_d = 0 (specular 0 makes dielectric_f0 and f90 zero).
        const Rgb fd = fresnelDielectricSchlick(p_, 1.f);
        const float kd = (1.f - p_.metallic) * (1.f - p_.transmission) * (1.f - maxComponent(fd));
        diffuseF_ = p_.baseColor * (kd * kInvPi);
    }
}

bool Bsdf::hasNonDelta(const MaterialParams& params) {
    const MaterialParams p = sanitize(params);
    return nonDelta(p, ggxAlpha(p));
}

namespace {
// Lambertian fast path: cosines of wo and wi against the shading normal on wo's side, with the
// same validity rules as setUpSide + reflectionLocal (wo not in the geometric plane, both on the
// same geometric side, both above the shading hemisphere). Computed in double like the frame.
bool lambertCosines(const Vec3& wo, const Vec3& wi, const Vec3& ns, const Vec3& ng, double* cosI) {
    const float dg = glm::dot(wo, ng);
    if (!(dg != 0.f) || !std::isfinite(dg)) return false;
    const bool outside = dg > 0.f;
    const Vec3 g = outside ? ng : -ng;
    if (!(glm::dot(wi, g) > 0.f)) return false;
    const glm::dvec3 n = outside ? glm::dvec3(ns) : -glm::dvec3(ns);
    const glm::dvec3 o(wo), i(wi);
    const double lo = glm::dot(o, n), li = glm::dot(i, n);
    if (!(lo > 0.0) || !(li > 0.0)) return false;
    const double len = std::sqrt(glm::dot(i, i));
    if (!(len > 0.0) || !std::isfinite(len)) return false;
    *cosI = li / len;
    return true;
}
}  // namespace

Rgb Bsdf::f(const Vec3& wo, const Vec3& wi, TransportMode mode) const {
    if (pureDiffuse_) {
        double cosI;
        if (!lambertCosines(wo, wi, ns_, ng_, &cosI)) return Rgb(0.f);
        return mode == TransportMode::Importance ? diffuseF_ * adjointFactor(wo, wi, ns_, ng_) : diffuseF_;
    }
    Side s;
    if (!setUpSide(wo, ns_, ng_, &s)) return Rgb(0.f);
    glm::dvec3 li;
    if (!reflectionLocal(s, wi, &li)) return Rgb(0.f);  // transmission is delta-only
    Rgb value = evalReflection(p_, alpha_, s.lo, li);
    if (mode == TransportMode::Importance) value *= adjointFactor(wo, wi, ns_, ng_);
    return value;
}

float Bsdf::pdf(const Vec3& wo, const Vec3& wi) const {
    if (pureDiffuse_) {  // the only lobe: selection probability 1
        double cosI;
        return lambertCosines(wo, wi, ns_, ng_, &cosI) ? float(cosI / kPiD) : 0.f;
    }
    Side s;
    if (!setUpSide(wo, ns_, ng_, &s)) return 0.f;
    glm::dvec3 li;
    if (!reflectionLocal(s, wi, &li)) return 0.f;
    const Lobes L = computeLobes(p_, alpha_, s);
    return float(pdfReflection(alpha_, L, s.lo, li));
}

bool Bsdf::sample(const Vec3& wo, float uLobe, Vec2 u, TransportMode mode, BsdfSample* out) const {
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

}  // namespace bdptref
