#include "scene/normal_map.h"

#include <cmath>

namespace bdptref {

Vec3 applyNormalMap(const Vec3& n, const Vec3& ng, const Vec3& tangent, float sign, const Vec3& texel, float scale) {
    using dvec3 = glm::dvec3;
    // glTF 2.0, "normalTexture": scaledNormal = normalize((2 sample - 1) * (scale, scale, 1)).
    const double x = (2.0 * double(texel.x) - 1.0) * double(scale);
    const double y = (2.0 * double(texel.y) - 1.0) * double(scale);
    const double z = 2.0 * double(texel.z) - 1.0;
    // The map's +z: no perturbation. Returning n itself (not normalize(n)) makes a flat map render
    // bit-identically to no map.
    if (x == 0.0 && y == 0.0 && z > 0.0) return n;
    const dvec3 N(n);
    const dvec3 Tp = dvec3(tangent) - N * glm::dot(N, dvec3(tangent));
    const double tl = glm::length(Tp);
    if (!(tl > 1e-12) || !std::isfinite(tl)) return n;  // no tangent direction: leave ns as it is
    const dvec3 T = Tp / tl;
    const dvec3 B = (sign < 0.f ? -1.0 : 1.0) * glm::cross(N, T);
    const dvec3 m = T * x + B * y + N * z;  // normalising (x, y, z) first changes only the length
    const double ml = glm::length(m);
    if (!(ml > 0.0) || !std::isfinite(ml)) return n;
    const Vec3 out(m / ml);
    // A mapped normal at or below the geometric plane would put the shading hemisphere mostly
    // under the surface; keep the interpolated normal there (the convention is derived in
    // docs/materials.md, "Normal maps").
    if (!(glm::dot(out, ng) > 0.f) || !isFinite(out)) return n;
    return out;
}

}  // namespace bdptref
