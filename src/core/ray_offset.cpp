#include "core/ray_offset.h"

namespace bdptref {

Vec3 offsetRayOrigin(const Vec3& p, const Vec3& n) { return offsetRayOriginInline(p, n); }

}  // namespace bdptref
