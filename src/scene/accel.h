// Embree 3 wrapper: one static triangle mesh, closest-hit and occlusion queries for single rays.
#pragma once

#include "bdptref/math.h"

#include <embree3/rtcore.h>

#include <vector>

namespace bdptref {

struct EmbreeHit {
    float t = 0.f, u = 0.f, v = 0.f;  // u, v: barycentrics of vertices 1 and 2
    uint32_t triangle = 0;
};

class Accel {
public:
    Accel(const std::vector<Vec3>& positions, const std::vector<glm::uvec3>& indices);
    ~Accel();
    Accel(const Accel&) = delete;
    Accel& operator=(const Accel&) = delete;

    bool intersect(const Ray& ray, EmbreeHit* hit) const;
    // True if anything lies on origin + t*dir for t in (0, tMax).
    bool occluded(const Vec3& origin, const Vec3& dir, float tMax) const;

private:
    RTCDevice device_ = nullptr;
    RTCScene scene_ = nullptr;
};

// Embree asks every tracing thread to flush denormals to zero (FTZ/DAZ).
void setFlushDenormals();

}  // namespace bdptref
