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

namespace {
// Intersection and occlusion filter of the alpha-tested geometry: rejects a candidate hit where
// the surface is absent, so Embree goes on to the next surface along the same ray (the ray passes
// straight through: no new ray, no offset). geometryUserPtr maps the geometry's primitive ids to
// the scene's triangle indices.
void coverageFilter(const RTCFilterFunctionNArguments* args) {
    const auto* ctx = reinterpret_cast<const CoverageContext*>(args->context);
    if (!ctx->test || !ctx->test->covers) return;
    const auto* triangleOf = static_cast<const uint32_t*>(args->geometryUserPtr);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] == 0) continue;
        const uint32_t prim = RTCHitN_primID(args->hit, args->N, i);
        const Vec2 b(RTCHitN_u(args->hit, args->N, i), RTCHitN_v(args->hit, args->N, i));
        const Vec3 origin(RTCRayN_org_x(args->ray, args->N, i), RTCRayN_org_y(args->ray, args->N, i),
                          RTCRayN_org_z(args->ray, args->N, i));
        const Vec3 dir(RTCRayN_dir_x(args->ray, args->N, i), RTCRayN_dir_y(args->ray, args->N, i),
                       RTCRayN_dir_z(args->ray, args->N, i));
        if (!ctx->test->covers(ctx->test->user, triangleOf[prim], b, origin, dir)) args->valid[i] = 0;
    }
}
}  // namespace

Accel::Accel(const std::vector<Vec3>& positions, const std::vector<glm::uvec3>& indices, const std::vector<uint8_t>& alphaTested) {
    setFlushDenormals();
    device_ = rtcNewDevice(nullptr);
    if (!device_) throw std::runtime_error("could not create an Embree device");
    rtcSetDeviceErrorFunction(device_, embreeError, nullptr);
    scene_ = rtcNewScene(device_);
    rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_MEDIUM);

    // Split the triangles into the plain set and the alpha-tested set (each keeps the scene order).
    std::vector<uint32_t> alphaList;
    for (size_t i = 0; i < alphaTested.size() && i < indices.size(); ++i)
        if (alphaTested[i]) alphaList.push_back(uint32_t(i));
    if (!alphaList.empty() && !rtcGetDeviceProperty(device_, RTC_DEVICE_PROPERTY_FILTER_FUNCTION_SUPPORTED))
        throw std::runtime_error("this Embree library was built without filter functions, which alpha-tested (MASK/BLEND) "
                                 "materials need");
    std::vector<glm::uvec3> plain, tested;
    std::vector<uint32_t> plainList;
    if (alphaList.empty()) {
        plain = indices;  // no alpha: one geometry in the scene's order, exactly as without alpha support
    } else {
        std::vector<uint8_t> isAlpha(indices.size(), 0);
        for (uint32_t t : alphaList) isAlpha[t] = 1;
        for (size_t i = 0; i < indices.size(); ++i) {
            if (isAlpha[i]) continue;
            plain.push_back(indices[i]);
            plainList.push_back(uint32_t(i));
        }
        for (uint32_t t : alphaList) tested.push_back(indices[t]);
    }

    auto add = [&](const std::vector<glm::uvec3>& tris, std::vector<uint32_t> triangleOf, bool filtered) {
        if (tris.empty()) return;
        RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
        // Each geometry gets its own copy of the vertices (only scenes with alpha have two).
        auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                              3 * sizeof(float), positions.size()));
        std::memcpy(v, positions.data(), positions.size() * sizeof(Vec3));
        auto* idx = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                   3 * sizeof(uint32_t), tris.size()));
        std::memcpy(idx, tris.data(), tris.size() * sizeof(glm::uvec3));
        const unsigned id = rtcAttachGeometry(scene_, geom);
        if (triangleOf_.size() <= id) triangleOf_.resize(id + 1);
        triangleOf_[id] = std::move(triangleOf);
        if (filtered) {
            rtcSetGeometryUserData(geom, triangleOf_[id].data());
            rtcSetGeometryIntersectFilterFunction(geom, coverageFilter);
            rtcSetGeometryOccludedFilterFunction(geom, coverageFilter);
        }
        rtcCommitGeometry(geom);
        rtcReleaseGeometry(geom);
    };
    triangleOf_.reserve(2);  // the user-data pointers above must stay valid: no reallocation
    add(plain, plainList, false);
    add(tested, alphaList, true);
    rtcCommitScene(scene_);
    const RTCError err = rtcGetDeviceError(device_);
    if (err != RTC_ERROR_NONE) throw std::runtime_error("Embree could not build the scene (error " + std::to_string(int(err)) + ")");
}

Accel::~Accel() {
    if (scene_) rtcReleaseScene(scene_);
    if (device_) rtcReleaseDevice(device_);
}

namespace {
void setUpRayHit(const Ray& ray, RTCRayHit* rh) {
    setUpRay(ray.origin, ray.dir, ray.tMax, &rh->ray);
    rh->hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh->hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
}
}  // namespace

// The hit of a traced RTCRayHit in the scene's triangle numbering; false when it found nothing.
bool Accel::hitOf(const RTCRayHit& rh, EmbreeHit* hit) const {
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
    hit->t = rh.ray.tfar;
    hit->u = rh.hit.u;
    hit->v = rh.hit.v;
    const std::vector<uint32_t>& triangleOf = triangleOf_[rh.hit.geomID];
    hit->triangle = triangleOf.empty() ? rh.hit.primID : triangleOf[rh.hit.primID];
    return true;
}

bool Accel::intersect(const Ray& ray, EmbreeHit* hit, const CoverageTest& coverage) const {
    CoverageContext context;
    rtcInitIntersectContext(&context.base);
    context.test = &coverage;
    RTCRayHit rh;
    setUpRayHit(ray, &rh);
    rtcIntersect1(scene_, &context.base, &rh);
    return hitOf(rh, hit);
}

void Accel::intersectStream(const Ray* const* rays, uint32_t n, EmbreeHit* hits, bool* found,
                            const CoverageTest& coverage) const {
    CoverageContext context;
    rtcInitIntersectContext(&context.base);
    context.test = &coverage;
    RTCRayHit rh[kStreamMax];
    for (uint32_t i = 0; i < n; ++i) setUpRayHit(*rays[i], &rh[i]);
    rtcIntersect1M(scene_, &context.base, rh, n, sizeof(RTCRayHit));
    for (uint32_t i = 0; i < n; ++i) found[i] = hitOf(rh[i], &hits[i]);
}

void Accel::occludedStream(const Ray* rays, uint32_t n, bool* occluded, const CoverageTest& coverage) const {
    CoverageContext context;
    rtcInitIntersectContext(&context.base);
    context.test = &coverage;
    RTCRay r[kStreamMax];
    for (uint32_t i = 0; i < n; ++i) setUpRay(rays[i].origin, rays[i].dir, rays[i].tMax, &r[i]);
    rtcOccluded1M(scene_, &context.base, r, n, sizeof(RTCRay));
    for (uint32_t i = 0; i < n; ++i) occluded[i] = r[i].tfar < 0.f;  // Embree sets tfar to -inf on a hit
}

}  // namespace bdptref
