#include "bdptref/math.h"

#include <cstring>

namespace bdptref {

namespace {
inline int32_t floatAsInt(float f) { int32_t i; std::memcpy(&i, &f, 4); return i; }
inline float intAsFloat(int32_t i) { float f; std::memcpy(&f, &i, 4); return f; }
}  // namespace

Vec3 offsetRayOrigin(const Vec3& p, const Vec3& n) {
    // Wächter & Binder, "A Fast and Robust Method for Avoiding Self-Intersection" (Ray Tracing
    // Gems, 2019): move by a fixed number of ULPs away from the surface, which scales with the
    // magnitude of the coordinates; near the origin, where ULPs vanish, use a small absolute step.
    constexpr float kOrigin = 1.f / 32.f;
    constexpr float kFloatScale = 1.f / 65536.f;
    constexpr float kIntScale = 256.f;
    Vec3 out;
    for (int a = 0; a < 3; ++a) {
        const int32_t ofs = int32_t(kIntScale * n[a]);
        const float pi = intAsFloat(floatAsInt(p[a]) + (p[a] < 0.f ? -ofs : ofs));
        out[a] = std::abs(p[a]) < kOrigin ? p[a] + kFloatScale * n[a] : pi;
    }
    return out;
}

}  // namespace bdptref
