// offsetRayOrigin (bdptref/math.h) as an inline function, for the per-ray paths inside the
// library (Scene::visible traces ~10 shadow rays per BDPT sample: the call was ~20 of the ~40
// instructions of each offset). The exported offsetRayOrigin calls this one: the same bits.
#pragma once

#include "bdptref/math.h"

#include <algorithm>
#include <cmath>

namespace bdptref {

// Move off the surface along its normal by a distance proportional to the LARGEST coordinate
// of the point: a ray-triangle test's error in the normal direction grows with every
// coordinate of the triangle, not only with the one along the normal. (Wächter & Binder's
// per-coordinate ULP offset fails for a wall through x = 0 at y, z ~ 500: its x offset is a
// fixed 1.5e-5 while Embree's error there is ~1e-4, and grazing rays re-hit the wall.)
// 2^-16 relative is ~500 float ULPs; below |p| = 2^-8 the step stops shrinking. See
// docs/self-intersection.md.
inline Vec3 offsetRayOriginInline(const Vec3& p, const Vec3& n) {
    constexpr float kRelative = 1.f / 65536.f;
    constexpr float kMinScale = 1.f / 256.f;
    const float scale = std::max(std::max(std::abs(p.x), std::abs(p.y)), std::max(std::abs(p.z), kMinScale));
    return p + n * (kRelative * scale);
}

}  // namespace bdptref
