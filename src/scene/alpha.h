// Alpha coverage (glTF alphaMode MASK and BLEND): whether a ray that reaches a point of an
// alpha-tested triangle finds the surface there or passes straight through. The model, why it is
// unbiased under MIS, and the random decision of BLEND: docs/materials.md ("Alpha"), docs/rng.md
// ("Alpha coverage"). The decision is made inside the intersection layer (src/scene/accel.cpp), so
// every ray kind of every estimator sees the same surfaces.
#pragma once

#include "bdptref/material.h"
#include "bdptref/math.h"

#include <cstdint>

namespace bdptref {

class Scene;

// False when the material's surface is present wherever a ray reaches it, so its triangles need
// no alpha test (opaque; or a constant alpha that always covers: no texture and alpha 1 for BLEND,
// alpha >= cutoff for MASK). Such triangles cost nothing extra. `colors`: the mesh has COLOR_0,
// whose alpha multiplies the coverage.
bool needsAlphaTest(const Material& m, bool colors);

// The coverage alpha at barycentrics (b1, b2) of the triangle (b1, b2: weights of its vertices 1
// and 2, as Embree reports them): baseColorFactor alpha x baseColorTexture alpha x COLOR_0 alpha
// at that point. The one place that knows where alpha comes from.
float surfaceCoverage(const Scene& scene, uint32_t triangle, Vec2 barycentrics);

// The BLEND decision number in [0, 1) of a ray (origin, direction, exactly as traced) crossing a
// triangle: a hash of their bits (docs/rng.md, "Alpha coverage"). The surface is hit iff u < alpha.
float blendDecisionNumber(const Vec3& origin, const Vec3& dir, uint32_t triangle);

// Whether the ray (origin, dir) finds the surface of `triangle` at the given barycentrics:
// MASK alpha >= cutoff; BLEND blendDecisionNumber < alpha; opaque: always.
bool surfaceCovers(const Scene& scene, uint32_t triangle, Vec2 barycentrics, const Vec3& origin, const Vec3& dir);

}  // namespace bdptref
