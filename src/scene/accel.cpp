#include "scene/accel.h"

#include "bdptref/errors.h"

#include <pmmintrin.h>
#include <xmmintrin.h>

#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>

namespace bdptref {

void setFlushDenormals() {
    _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
    _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
}

namespace {
void embreeError(void* /*user*/, RTCError code, const char* message) {
    // Called from inside Embree (C code): never throw here; the build result is checked below.
    if (code == RTC_ERROR_NONE) return;
    std::fprintf(stderr, "bdptref: Embree error %d: %s\n", int(code), message ? message : "");
}
}  // namespace

Accel::Accel(const std::vector<Vec3>& positions, const std::vector<glm::uvec3>& indices) {
    setFlushDenormals();
    device_ = rtcNewDevice(nullptr);
    if (!device_) throw std::runtime_error("could not create an Embree device");
    rtcSetDeviceErrorFunction(device_, embreeError, nullptr);
    scene_ = rtcNewScene(device_);
    rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_MEDIUM);
    if (!indices.empty()) {
        RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
        auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                              3 * sizeof(float), positions.size()));
        std::memcpy(v, positions.data(), positions.size() * sizeof(Vec3));
        auto* idx = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                   3 * sizeof(uint32_t), indices.size()));
        std::memcpy(idx, indices.data(), indices.size() * sizeof(glm::uvec3));
        rtcCommitGeometry(geom);
        rtcAttachGeometry(scene_, geom);
        rtcReleaseGeometry(geom);
    }
    rtcCommitScene(scene_);
    const RTCError err = rtcGetDeviceError(device_);
    if (err != RTC_ERROR_NONE) throw std::runtime_error("Embree could not build the scene (error " + std::to_string(int(err)) + ")");
}

Accel::~Accel() {
    if (scene_) rtcReleaseScene(scene_);
    if (device_) rtcReleaseDevice(device_);
}

bool Accel::intersect(const Ray& ray, EmbreeHit* hit) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRayHit rh;
    rh.ray.org_x = ray.origin.x;
    rh.ray.org_y = ray.origin.y;
    rh.ray.org_z = ray.origin.z;
    rh.ray.dir_x = ray.dir.x;
    rh.ray.dir_y = ray.dir.y;
    rh.ray.dir_z = ray.dir.z;
    rh.ray.tnear = 0.f;
    rh.ray.tfar = ray.tMax;
    rh.ray.time = 0.f;
    rh.ray.mask = 0xFFFFFFFFu;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene_, &context, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
    hit->t = rh.ray.tfar;
    hit->u = rh.hit.u;
    hit->v = rh.hit.v;
    hit->triangle = rh.hit.primID;
    return true;
}

bool Accel::occluded(const Vec3& origin, const Vec3& dir, float tMax) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRay r;
    r.org_x = origin.x;
    r.org_y = origin.y;
    r.org_z = origin.z;
    r.dir_x = dir.x;
    r.dir_y = dir.y;
    r.dir_z = dir.z;
    r.tnear = 0.f;
    r.tfar = tMax;
    r.time = 0.f;
    r.mask = 0xFFFFFFFFu;
    r.id = 0;
    r.flags = 0;
    rtcOccluded1(scene_, &context, &r);
    return r.tfar < 0.f;  // Embree sets tfar to -inf on a hit
}

}  // namespace bdptref
