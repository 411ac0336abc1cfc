// Beer-Lambert absorption along a path segment (docs/materials.md, "Volume absorption").
#include "render/segment_transmittance.h"

#include "bdptref/scene.h"

namespace bdptref {

SegmentEnd surfaceEnd(const SurfaceHit& hit) { return SegmentEnd{hit.p, hit.ng, hit.material, false}; }

SegmentEnd lightEnd(const Scene& scene, int light, const Vec3& pLight, const Vec3& dirToLight) {
    const Light& l = scene.lights[size_t(light)];
    if (isInfinite(l)) return infiniteEnd(dirToLight);
    // A point on an area light lies on its triangle: the winding normal and the triangle's
    // material (not the emitting side a two-sided light may report).
    if (l.type == LightType::Area) return SegmentEnd{pLight, l.normal, scene.mesh.triangleMaterial[l.triangle], false};
    return pointEnd(pLight);
}

SegmentEnd vertexEnd(const Scene& scene, const PathVertex& v) {
    if (v.type == VertexType::Surface) return SegmentEnd{v.p, v.ng, v.material, false};
    if (v.infinite) return infiniteEnd(v.ng);  // ng: the direction from the scene towards the light
    if (v.type == VertexType::Light && v.light >= 0 && size_t(v.light) < scene.lights.size())
        return lightEnd(scene, v.light, v.p, Vec3(0.f));
    return pointEnd(v.p);
}

namespace {
// Does the segment leave (or meet) end e's surface on its back side? `away` points from e into
// the segment.
bool backFacing(const SegmentEnd& e, const Vec3& away) {
    return e.ng != Vec3(0.f) && !e.infinite && glm::dot(e.ng, away) < 0.f;
}
}  // namespace

int segmentMedium(const Scene& scene, const SegmentEnd& a, const SegmentEnd& b) {
    // Directions from each end into the segment. An infinite end stores the direction from the
    // finite end towards it.
    const Vec3 fromA = b.infinite ? b.p : a.infinite ? -a.p : b.p - a.p;
    const bool inA = backFacing(a, fromA), inB = backFacing(b, -fromA);
    int medium = -1;
    if (inA) medium = int(a.material);
    if (inB && (medium < 0 || int(b.material) < medium)) medium = int(b.material);
    if (medium >= 0 && size_t(medium) >= scene.materials.size()) return -1;  // hand-built paths with bad ids
    return medium;
}

Rgb beerLambert(const Rgb& sigma, double length) {
    Rgb T(1.f);
    for (int c = 0; c < 3; ++c) {
        if (!(sigma[c] > 0.f) || !(length > 0.0)) continue;  // no absorption, or a zero-length segment
        T[c] = float(std::exp(-double(sigma[c]) * length));   // inf * positive -> exp(-inf) = 0
    }
    return T;
}

Rgb segmentTransmittance(const Scene& scene, const SegmentEnd& a, const SegmentEnd& b) {
    if (scene.absorptionFree()) return Rgb(1.f);  // the answer of every branch below (no sigma is non-black)
    const int medium = segmentMedium(scene, a, b);
    if (medium < 0) return Rgb(1.f);
    const Rgb& sigma = scene.materials[size_t(medium)].absorption;
    if (isBlack(sigma)) return Rgb(1.f);
    const double length = a.infinite || b.infinite ? double(kInfinity) : glm::length(DVec3(b.p) - DVec3(a.p));
    return beerLambert(sigma, length);
}

}  // namespace bdptref
