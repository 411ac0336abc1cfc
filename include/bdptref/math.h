// Small math vocabulary shared by every module: vectors, rays, orthonormal frames.
#pragma once

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace bdptref {

using Vec2 = glm::vec2;
using Vec3 = glm::vec3;
using Vec4 = glm::vec4;
using DVec3 = glm::dvec3;
using Mat4 = glm::mat4;
using DMat4 = glm::dmat4;
// RGB triple in linear Rec.709 primaries (radiance, importance, throughput, albedo).
using Rgb = glm::vec3;

constexpr float kPi = 3.14159265358979323846f;
constexpr float kInvPi = 0.31830988618379067154f;
constexpr float kInv4Pi = 0.07957747154594766788f;
constexpr float kInfinity = std::numeric_limits<float>::infinity();

inline float luminance(const Rgb& c) { return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b; }
inline float maxComponent(const Rgb& c) { return std::max(c.r, std::max(c.g, c.b)); }
inline bool isBlack(const Rgb& c) { return c.r == 0.f && c.g == 0.f && c.b == 0.f; }
inline bool isFinite(const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
inline float sqr(float x) { return x * x; }
inline float safeSqrt(float x) { return std::sqrt(std::max(0.f, x)); }
inline float absDot(const Vec3& a, const Vec3& b) { return std::abs(glm::dot(a, b)); }

struct Ray {
    Vec3 origin;
    Vec3 dir;  // not necessarily normalised for shadow rays (see accel.h)
    float tMax = kInfinity;
};

// Orthonormal basis around a unit normal; local z is the normal.
// Construction from Duff et al., "Building an Orthonormal Basis, Revisited" (JCGT 2017).
struct Frame {
    Vec3 s, t, n;

    Frame() : s(1, 0, 0), t(0, 1, 0), n(0, 0, 1) {}
    explicit Frame(const Vec3& normal) : n(normal) {
        const float sign = std::copysign(1.0f, n.z);
        const float a = -1.0f / (sign + n.z);
        const float b = n.x * n.y * a;
        s = Vec3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
        t = Vec3(b, sign + n.y * n.y * a, -n.y);
    }
    Vec3 toLocal(const Vec3& v) const { return Vec3(glm::dot(v, s), glm::dot(v, t), glm::dot(v, n)); }
    Vec3 toWorld(const Vec3& v) const { return s * v.x + t * v.y + n * v.z; }
};

// Offsets a surface point along its geometric normal so a ray leaving it cannot re-hit the same
// surface: by 2^-16 of the point's largest coordinate (scale-invariant); see
// docs/self-intersection.md. `n` must point to the side the ray leaves towards.
Vec3 offsetRayOrigin(const Vec3& p, const Vec3& n);

}  // namespace bdptref
