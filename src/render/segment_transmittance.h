// Volume absorption (KHR_materials_volume, Beer-Lambert) along one path segment: the transport
// math written once for every estimator (PT extension and next-event segments, BDPT/LT subpath
// extension and every (s, t) connection, and the wavefront stages, which call the same functions).
// Definitions and the "inside" rule: docs/materials.md, "Volume absorption".
//
// Absorption multiplies a path's throughput only; no sampling density depends on it, so the MIS
// weights (both implementations) are unchanged.
#pragma once

#include "bdptref/math.h"
#include "bdptref/path_vertex.h"

#include <cstdint>
#include <type_traits>

namespace bdptref {

class Scene;
struct SurfaceHit;

// One end of a segment as the medium rule sees it.
struct SegmentEnd {
    Vec3 p{0.f};            // position; for `infinite`, the unit direction from the segment's other end
    Vec3 ng{0.f};           // the surface's geometric normal as the winding defines it (outward for a
                            // closed, consistently wound mesh); zero: not on a surface
    uint32_t material = 0;  // the surface's material (when ng != 0)
    bool infinite = false;  // an escape / infinite light: the segment is unbounded
};
static_assert(std::is_trivially_copyable_v<SegmentEnd>, "SegmentEnd may live in wavefront buffers");

// The end at a surface hit; at a point off any surface (pinhole, punctual light); towards infinity.
SegmentEnd surfaceEnd(const SurfaceHit& hit);
inline SegmentEnd pointEnd(const Vec3& p) { return SegmentEnd{p, Vec3(0.f), 0, false}; }
inline SegmentEnd infiniteEnd(const Vec3& dir) { return SegmentEnd{dir, Vec3(0.f), 0, true}; }
// The end at a point of light `light` (index into Scene::lights): sampleLi's pLight, or for an
// infinite light the direction towards it.
SegmentEnd lightEnd(const Scene& scene, int light, const Vec3& pLight, const Vec3& dirToLight);
// The end at a path vertex: surfaces and points on area lights use their triangle's winding
// normal and material; the camera and punctual lights are points; infinite lights are infinite.
SegmentEnd vertexEnd(const Scene& scene, const PathVertex& v);

// The material whose medium the segment a-b lies in, or -1 for none (docs/materials.md): a's
// material when the segment leaves a's surface through its back side (dot(ng_a, b - a) < 0), b's
// when it meets b's surface on its back side (dot(ng_b, a - b) < 0); when both, the smaller
// material index. Symmetric: segmentMedium(a, b) == segmentMedium(b, a). At most one end may be
// infinite.
int segmentMedium(const Scene& scene, const SegmentEnd& a, const SegmentEnd& b);

// exp(-sigma_a |b - a|) per channel, sigma_a the absorption of segmentMedium(a, b) (1 when none;
// 0 in absorbing channels of an unbounded segment; 1 in channels with sigma_a = 0).
Rgb segmentTransmittance(const Scene& scene, const SegmentEnd& a, const SegmentEnd& b);
// Beer-Lambert for a known coefficient and length (length may be +inf, sigma may be +inf).
Rgb beerLambert(const Rgb& sigma, double length);

}  // namespace bdptref
