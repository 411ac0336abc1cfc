// The cause of a zero BSDF across a surface, in words (transmission_diagnosis.h).
#include "verify/transmission_diagnosis.h"

#include "scene/bsdf_rough_dielectric.h"
#include "scene/bsdf_terms.h"

#include <cstdio>

namespace bdptref {

using namespace bsdf_detail;

namespace {
std::string number(double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%.4g", v);
    return text;
}
}  // namespace

std::string zeroTransmissionCause(const MaterialParams& params, const std::string& material, const Vec3& ns, const Vec3& ng,
                                  const Vec3& wo, const Vec3& wi, TransportMode mode) {
    const MaterialParams p = sanitizedParams(params);
    if (!(p.transmission > 0.f)) return material + " has no transmission lobe";
    if (!transmissionActive(p))
        return material + " transmits nothing here (" + (p.metallic >= 1.f ? "metallic 1" : "base colour 0") +
               "): its transmission lobe is zero";
    const float alpha = ggxAlpha(p.roughness);
    if (!(alpha > 0.f))
        return material + " refracts only through its smooth (delta) lobe (" +
               (params.roughness > 0.f ? "roughness below the near-delta threshold" : "roughness 0") +
               "), which no connection reaches";
    // Rough glass: the rough dielectric lobe's transmission branch, check by check.
    const std::string rough = material + " is rough glass (roughness " + number(p.roughness) + ")";
    Side s;
    if (!setUpSide(wo, ns, ng, &s))
        return rough + ", but the direction the path arrived from lies below the shading hemisphere (the shading normal "
                       "tilts away from it), where the BSDF is zero in every direction";
    glm::dvec3 li;
    if (!transmissionLocal(s, wi, &li))
        return rough + ", but that direction is above the shading hemisphere on the other geometric side (the shading and "
                       "geometric normals disagree there)";
    const Etas eta = interfaceEtas(p, s.outside);
    glm::dvec3 h;
    if (!refractionHalfVector(s.lo, li, eta, &h))
        return rough + ", but no microfacet refracts one direction into the other: the generalized half-vector h = "
                       "normalize(eta_o wo + eta_i wi) faces away from one of them (wo.h > 0 > wi.h fails" +
               std::string(s.outside ? ")" : "; from inside, this is total internal reflection)");
    const double cosOH = glm::dot(s.lo, h);
    if (isBlack(microfacetSplit(p, s.outside, cosOH).transmit))
        return rough + ", but the microfacet h between the two directions reflects everything: total internal reflection "
                       "(cos(wo, h) = " + number(cosOH) + ")";
    if (!(ggxD(h, alpha) > 0.0) || !(smithG1(s.lo, alpha) > 0.0) || !(smithG1(li, alpha) > 0.0))
        return rough + ", but the pair has measure zero: the microfacet density D(h) or a shadowing term G1 is 0 (a direction "
                       "in the shading tangent plane)";
    if (mode == TransportMode::Importance && !(adjointFactor(wo, wi, ns, ng) > 0.f))
        return rough + ", but the adjoint shading-normal factor is 0 (a direction in the shading tangent plane)";
    return rough + ", but its transmission lobe evaluates to 0 for this pair (terms that underflow or are not finite)";
}

}  // namespace bdptref
