// The glTF normalTexture perturbation of the shading normal (docs/materials.md, "Normal maps").
// Called by Scene::intersect only, so the path tracer, BDPT and the wavefront mode all see the
// same shading normal.
#pragma once

#include "bdptref/math.h"

namespace bdptref {

// n: unit interpolated shading normal (on ng's side), ng: unit geometric normal, tangent: the
// interpolated vertex tangent (need not be unit or orthogonal to n), sign: the bitangent sign
// (TANGENT.w), texel: the normal texture's linear RGB, scale: normalTexture.scale.
// Returns normalize(T x + B y + N z) with (x, y, z) = normalize((2 texel - 1) * (scale, scale, 1)),
// T = tangent orthogonalised against n, B = sign * cross(n, T); returns n itself (bit-exactly)
// when x = y = 0, and n when the result is degenerate or not strictly above ng's plane.
Vec3 applyNormalMap(const Vec3& n, const Vec3& ng, const Vec3& tangent, float sign, const Vec3& texel, float scale);

}  // namespace bdptref
