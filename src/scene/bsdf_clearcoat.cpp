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
    // The base's side rules (bsdf_terms.h) with n_c as the shading normal: v's side of n_g, v
    // and l above n_c, l on v's side of n_g; then both above the base's n_s on that side.
    Side side;
    if (!setUpSide(v, c.n, ng, &side)) return false;
    if (!reflectionLocal(side, l, &out->ll)) return false;
    const glm::dvec3 nS = side.outside ? glm::dvec3(ns) : -glm::dvec3(ns);
    if (!(glm::dot(glm::dvec3(v), nS) > 0.0)) return false;
    out->cosLs = glm::dot(glm::dvec3(l), nS) / glm::length(glm::dvec3(l));
    if (!(out->cosLs > 0.0)) return false;
    out->frame = side.frame;
    out->lv = side.lo;
    return true;
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
    Side side;  // the frame about n_c on wo's side (bsdf_terms.h)
    if (!setUpSide(wo, c.n, ng, &side)) return false;
    const FrameD& frame = side.frame;
    const glm::dvec3& lo = side.lo;
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
