// The clearcoat lobe of KHR_materials_clearcoat (docs/materials.md, "Clearcoat"); the layering
// with the base is in Bsdf (src/scene/bsdf.cpp).
#include "bsdf_clearcoat.h"

namespace bdptref {
namespace bsdf_detail {

namespace {

// A pair (v, l) in the coat's local frame on v's side: both on one side of n_g and above n_s and
// n_c on that side (the coat reflects only; directions below the base's shading hemisphere carry
// nothing, as for the base's lobes).
struct CoatPair {
    FrameD frame;      // about n_c on v's side
    glm::dvec3 lv, ll; // unit, z > 0
    double cosLs = 0;  // l . n_s on v's side, > 0
};

bool coatPair(const Coat& c, const Vec3& ns, const Vec3& ng, const Vec3& v, const Vec3& l, CoatPair* out) {
    const float dv = glm::dot(v, ng);
    if (!(dv != 0.f) || !std::isfinite(dv)) return false;
    const bool front = dv > 0.f;
    if (!(glm::dot(l, front ? ng : -ng) > 0.f)) return false;
    const glm::dvec3 nS = front ? glm::dvec3(ns) : -glm::dvec3(ns);
    const glm::dvec3 nC = front ? glm::dvec3(c.n) : -glm::dvec3(c.n);
    const glm::dvec3 V(v), L(l);
    const double lenV = glm::length(V), lenL = glm::length(L);
    if (!(lenV > 0.0) || !(lenL > 0.0) || !std::isfinite(lenV) || !std::isfinite(lenL)) return false;
    if (!(glm::dot(V, nS) > 0.0)) return false;
    out->cosLs = glm::dot(L, nS) / lenL;
    if (!(out->cosLs > 0.0)) return false;
    out->frame = FrameD(nC);
    out->lv = out->frame.toLocal(V) / lenV;
    out->ll = out->frame.toLocal(L) / lenL;
    return out->lv.z > 0.0 && out->ll.z > 0.0;
}

}  // namespace

float coatSelectionProbability(const Coat& c, const Vec3& wo) {
    const float w = c.weight * clearcoatFresnel(glm::dot(wo, c.n));
    const float total = w + (1.f - w) * c.baseAlbedo;
    return total > 0.f ? std::min(1.f, w / total) : 1.f;
}

float coatRadianceF(const Coat& c, const Vec3& ns, const Vec3& ng, const Vec3& v, const Vec3& l) {
    if (!(c.alpha > 0.f)) return 0.f;
    CoatPair q;
    if (!coatPair(c, ns, ng, v, l, &q)) return 0.f;
    const glm::dvec3 h = glm::normalize(q.lv + q.ll);
    const double a = c.alpha;
    // D G1(v) G1(l) / (4 (v.n_c)(l.n_c)) * (l.n_c) / (l.n_s): the l.n_c cancels.
    const double brdfCos = ggxD(h, a) * smithG1(q.lv, a) * smithG1(q.ll, a) / (4.0 * q.lv.z * q.cosLs);
    return float(double(c.weight * clearcoatFresnel(float(q.lv.z))) * brdfCos);
}

double coatPdf(const Coat& c, const Vec3& ns, const Vec3& ng, const Vec3& wo, const Vec3& wi) {
    if (!(c.alpha > 0.f)) return 0.0;
    CoatPair q;
    if (!coatPair(c, ns, ng, wo, wi, &q)) return 0.0;
    const glm::dvec3 h = glm::normalize(q.lv + q.ll);
    return smithG1(q.lv, c.alpha) * ggxD(h, c.alpha) / (4.0 * q.lv.z);
}

bool sampleCoatDirection(const Coat& c, const Vec3& ns, const Vec3& ng, const Vec3& wo, Vec2 u, Vec3* wi) {
    const float dg = glm::dot(wo, ng);
    if (!(dg != 0.f) || !std::isfinite(dg)) return false;
    const FrameD frame(dg > 0.f ? glm::dvec3(c.n) : -glm::dvec3(c.n));
    const glm::dvec3 lo = glm::normalize(frame.toLocal(glm::dvec3(wo)));
    if (!(lo.z > 0.0)) return false;
    glm::dvec3 li;
    if (c.alpha > 0.f) {
        const glm::dvec3 h = sampleGgxVndf(lo, c.alpha, u.x, u.y);
        li = 2.0 * glm::dot(lo, h) * h - lo;
    } else {
        li = glm::dvec3(-lo.x, -lo.y, lo.z);  // the mirror direction about n_c
    }
    if (!(li.z > 0.0)) return false;
    *wi = Vec3(glm::normalize(frame.toWorld(li)));
    CoatPair q;
    return coatPair(c, ns, ng, wo, *wi, &q);
}

}  // namespace bsdf_detail
}  // namespace bdptref
