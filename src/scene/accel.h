// Embree 3 wrapper: closest-hit and occlusion queries for single rays on the scene's triangles.
// Triangles flagged as alpha-tested (glTF alphaMode MASK / BLEND) live in a second Embree geometry
// with intersection and occlusion filter functions that ask a CoverageTest whether the ray finds
// the surface at the candidate hit; the others stay in one plain geometry, so a scene without
// alpha-tested triangles is built and traced exactly as without this feature.
#pragma once

#include "bdptref/math.h"

#include <embree3/rtcore.h>

#include <cstdint>
#include <vector>

namespace bdptref {

struct EmbreeHit {
    float t = 0.f, u = 0.f, v = 0.f;  // u, v: barycentrics of vertices 1 and 2
    uint32_t triangle = 0;
};

// Asked at every candidate hit on an alpha-tested triangle (from inside Embree, possibly more
// than once for the same triangle and ray: it must be a pure function of its arguments).
// origin and dir are the ray's, exactly as passed to intersect/occluded.
struct CoverageTest {
    const void* user = nullptr;
    bool (*covers)(const void* user, uint32_t triangle, Vec2 barycentrics, const Vec3& origin, const Vec3& dir) = nullptr;
};

class Accel {
public:
    // alphaTested: empty, or one flag per triangle (non-zero: the triangle gets the coverage test).
    Accel(const std::vector<Vec3>& positions, const std::vector<glm::uvec3>& indices,
          const std::vector<uint8_t>& alphaTested = {});
    ~Accel();
    Accel(const Accel&) = delete;
    Accel& operator=(const Accel&) = delete;

    // `coverage` is needed when there are alpha-tested triangles (ignored otherwise).
    bool intersect(const Ray& ray, EmbreeHit* hit, const CoverageTest& coverage = {}) const;
    // intersect() of n <= kStreamMax rays in one call of Embree's stream API (rtcIntersect1M): the
    // same hits as n intersect() calls; found[i] says whether rays[i] hit.
    static constexpr uint32_t kStreamMax = 64;
    void intersectStream(const Ray* const* rays, uint32_t n, EmbreeHit* hits, bool* found,
                         const CoverageTest& coverage = {}) const;
    // True if anything lies on origin + t*dir for t in (0, tMax). Inline: it runs for every
    // shadow ray, and its body is the ray's set-up around one rtcOccluded1.
    bool occluded(const Vec3& origin, const Vec3& dir, float tMax, const CoverageTest& coverage = {}) const;

    // occluded() of n <= kStreamMax rays through rtcOccluded1M.
    void occludedStream(const Ray* rays, uint32_t n, bool* occluded, const CoverageTest& coverage = {}) const;

private:
    bool hitOf(const RTCRayHit& rh, EmbreeHit* hit) const;
    RTCDevice device_ = nullptr;
    RTCScene scene_ = nullptr;
    // Embree geometry id -> the scene's triangle index of each primitive (empty: the identity).
    std::vector<std::vector<uint32_t>> triangleOf_;
};

// The intersect context Embree hands to the filter functions, extended with what the coverage
// test needs (Embree's documented way to pass per-ray data to filters: the context pointer is
// ours). The filter reads each ray's origin and direction from the ray Embree hands it, so one
// context serves a whole stream of rays.
struct CoverageContext {
    RTCIntersectContext base;
    const CoverageTest* test;
};

// The ray Embree traces for origin + t dir, t in (0, tMax): every query's set-up.
inline void setUpRay(const Vec3& origin, const Vec3& dir, float tMax, RTCRay* r) {
    r->org_x = origin.x;
    r->org_y = origin.y;
    r->org_z = origin.z;
    r->dir_x = dir.x;
    r->dir_y = dir.y;
    r->dir_z = dir.z;
    r->tnear = 0.f;
    r->tfar = tMax;
    r->time = 0.f;
    r->mask = 0xFFFFFFFFu;
    r->id = 0;
    r->flags = 0;
}

inline bool Accel::occluded(const Vec3& origin, const Vec3& dir, float tMax, const CoverageTest& coverage) const {
    CoverageContext context;
    rtcInitIntersectContext(&context.base);
    context.test = &coverage;
    RTCRay r;
    setUpRay(origin, dir, tMax, &r);
    rtcOccluded1(scene_, &context.base, &r);
    return r.tfar < 0.f;  // Embree sets tfar to -inf on a hit
}

// Embree asks every tracing thread to flush denormals to zero (FTZ/DAZ).
void setFlushDenormals();

}  // namespace bdptref
