// The (s, t) connection strategies of BDPT (docs/mis.md, "Strategies").
#include "bdptref/bdpt.h"
#include "render/bdpt_vertex.h"
#include "render/light_choice.h"
#include "render/segment_transmittance.h"

#include <algorithm>

namespace bdptref {

namespace {

// Geometry term between two vertices without visibility: |cos| at each end that lies on a surface
// (shading normals: the BSDF's cosine convention) over distance^2 (none for infinite lights).
// `shadow` receives the visibility query that completes it.
double unoccludedGeometryTerm(const PathVertex& a, const PathVertex& b, ShadowRay* shadow) {
    if (b.infinite || a.infinite) {
        const PathVertex& fin = a.infinite ? b : a;
        const PathVertex& inf = a.infinite ? a : b;
        shadow->set(fin.p, fin.isOnSurface() ? fin.ng : Vec3(0.f), inf.ng, Vec3(0.f), true);
        return fin.isOnSurface() ? std::abs(glm::dot(fin.ns, inf.ng)) : 1.0;
    }
    const DVec3 d = DVec3(b.p) - DVec3(a.p);
    const double dist2 = glm::dot(d, d);
    if (!(dist2 > 0.0)) return 0.0;  // coincident vertices: no finite contribution (docs/mis.md)
    const DVec3 w = d / std::sqrt(dist2);
    double g = 1.0 / dist2;
    if (a.isOnSurface()) g *= std::abs(glm::dot(DVec3(a.ns), w));
    if (b.isOnSurface()) g *= std::abs(glm::dot(DVec3(b.ns), w));
    if (g == 0.0 || !std::isfinite(g)) return 0.0;
    shadow->set(a.p, a.isOnSurface() ? a.ng : Vec3(0.f), b.p, b.isOnSurface() ? b.ng : Vec3(0.f), false);
    return g;
}

}  // namespace

bool traceShadowRay(const Scene& scene, const ShadowRay& r) {
    return r.toInfinity ? scene.visibleToInfinity(r.p0, r.n0, r.p1) : scene.visible(r.p0, r.n0, r.p1, r.n1);
}

void traceShadowRays(const Scene& scene, const ShadowRay* const* rays, uint32_t n, bool* unoccluded) {
    constexpr uint32_t kBatch = 64;
    Ray queries[kBatch];
    for (uint32_t begin = 0; begin < n; begin += kBatch) {
        const uint32_t m = std::min(n - begin, kBatch);
        for (uint32_t i = 0; i < m; ++i) {
            const ShadowRay& r = *rays[begin + i];
            queries[i] = r.toInfinity ? Scene::infinityRay(r.p0, r.n0, r.p1) : Scene::segmentRay(r.p0, r.n0, r.p1, r.n1);
        }
        scene.occludedStream(queries, m, unoccluded + begin);
        for (uint32_t i = 0; i < m; ++i) unoccluded[begin + i] = !unoccluded[begin + i];
    }
}

namespace {

// One strategy's evaluation: its inputs, and the PendingConnection (already in its default state:
// the megakernel's fresh local one; clearing its ~200 bytes twice per connection was ~1% of BDPT)
// that its steps fill. Each step returns the unoccluded contribution, black when there is none.
struct ConnectionEvaluation : StrategyInputs {
    PendingConnection* out;
    EndpointBsdfs endpoints;

    const Bsdf& bsdfQs() const { return endpoints.get().light[s - 1]; }
    const Bsdf& bsdfPt() const { return endpoints.get().camera[t - 1]; }

    Rgb endpointF(const Bsdf& bsdf, const PathVertex& v, const Vec3& w, TransportMode mode, EndpointDensities* d) const {
        const Vec3& wPrev = connectionIncoming(v, weighted);
        if (!weighted) return bsdf.f(wPrev, w, mode);
        return bsdf.evaluateBothWays(wPrev, w, mode, &d->towardsOther, &d->towardsPrev);
    }

    Rgb emitterHit() const;
    Rgb splatToCamera() const;
    Rgb nextEvent() const;
    Rgb connectSubpaths() const;
    Rgb transmittance() const;
    bool evaluate() const;
};

// s = 0: the camera subpath found an emitter.
Rgb ConnectionEvaluation::emitterHit() const {
    const PathVertex& pt = cameraPath[t - 1];
    return pt.beta * emittedTowardsPrevious(scene, pt);
}

// t = 1: connect a light-subpath vertex to the camera (the pinhole, or the film point it projects
// onto for an orthographic camera: docs/camera.md) and splat it.
Rgb ConnectionEvaluation::splatToCamera() const {
    const PathVertex& qs = lightPath[s - 1];
    PathVertex& sampled = out->sampled;
    const Bsdf* fQs = qs.type == VertexType::Surface ? &bsdfQs() : nullptr;
    if (!(fQs ? fQs->hasNonDelta() : isConnectible(scene, qs)) || qs.infinite) return Rgb(0.f);
    CameraImportanceSample cs;
    if (!scene.camera.sampleWi(qs.p, &cs) || !(cs.pdf > 0.f)) return Rgb(0.f);
    sampled.type = VertexType::Camera;
    sampled.p = cs.pCamera;
    sampled.ng = sampled.ns = scene.camera.forward();
    sampled.beta = Rgb(cs.We / cs.pdf);
    sampled.pdfFwd = 1.0;
    Rgb L;
    if (fQs) {
        const Rgb f = endpointF(*fQs, qs, directionTo(qs, sampled), TransportMode::Importance, &out->lightEnd);
        L = qs.beta * f * sampled.beta * absDot(cs.wi, qs.ns);
    } else {  // the light vertex itself (light tracing of emitters seen directly)
        const Light& light = vertexLight(scene, qs);
        const float cosLight = light.type == LightType::Area ? absDot(cs.wi, light.normal) : 1.f;
        L = lightEmission(light, scene, qs.bary, cs.wi) * float(double(cosLight) / lightOriginDensity(scene, qs)) * sampled.beta;
    }
    if (isBlack(L)) return L;
    out->shadow.set(qs.p, qs.isOnSurface() ? qs.ng : Vec3(0.f), sampled.p, Vec3(0.f), false);
    out->needsShadowRay = true;
    out->splat = true;
    out->raster = cs.raster;
    return L;
}

// s = 1, next-event estimation: a fresh light sample for camera vertex t-1, its light chosen at
// (pt.p, pt.ng) by `lightSampler` (power: the light subpaths' choice).
Rgb ConnectionEvaluation::nextEvent() const {
    const PathVertex& pt = cameraPath[t - 1];
    PathVertex& sampled = out->sampled;
    if (pt.type != VertexType::Surface) return Rgb(0.f);
    const Bsdf& fPt = bsdfPt();
    if (!fPt.hasNonDelta()) return Rgb(0.f);
    const uint32_t bounce = uint32_t(t - 2);
    float pmf = 0.f;
    const int li = chooseLight(scene, lightSampler, pt.p, pt.ng,
                               sampler.get1D(RngStream::Camera, dim::vertex(bounce, dim::kNeeLight)), &pmf);
    if (li < 0 || !(pmf > 0.f)) return Rgb(0.f);
    const Light& light = scene.lights[size_t(li)];
    LightLiSample ls;
    if (!sampleLi(light, scene, pt.p, sampler.get2D(RngStream::Camera, dim::vertex(bounce, dim::kNeePosition)), &ls) ||
        !(ls.pdf > 0.f) || isBlack(ls.Li))
        return Rgb(0.f);
    setLightSampleVertex(scene, li, ls, &sampled);
    sampled.beta = ls.Li / (pmf * ls.pdf);
    // The density this sampler realised (the tree's pmf is the one sample returned, bit for bit).
    sampled.pdfFwd = lightSampler == LightSamplerKind::Power ? lightOriginDensity(scene, sampled)
                                                              : lightOriginDensity(scene, sampled, pmf);
    const Rgb f = endpointF(fPt, pt, directionTo(pt, sampled), TransportMode::Radiance, &out->cameraEnd);
    const Rgb L = pt.beta * f * sampled.beta * absDot(ls.wi, pt.ns);
    if (isBlack(L)) return L;
    if (sampled.infinite) out->shadow.set(pt.p, pt.ng, ls.wi, Vec3(0.f), true);
    else out->shadow.set(pt.p, pt.ng, ls.pLight, ls.nLight, false);
    out->needsShadowRay = true;
    return L;
}

// s >= 2, t >= 2: both subpaths contribute a vertex: connect them with a shadow ray.
Rgb ConnectionEvaluation::connectSubpaths() const {
    const PathVertex& qs = lightPath[s - 1];
    const PathVertex& pt = cameraPath[t - 1];
    if (qs.type != VertexType::Surface || pt.type != VertexType::Surface) return Rgb(0.f);
    const Bsdf& fQs = bsdfQs();
    const Bsdf& fPt = bsdfPt();
    if (!fQs.hasNonDelta() || !fPt.hasNonDelta()) return Rgb(0.f);
    // The direction normalised once (directionTo(pt, qs) = -directionTo(qs, pt) exactly).
    const Vec3 qsToPt = directionTo(qs, pt);
    if (qsToPt == Vec3(0.f)) return Rgb(0.f);  // coincident endpoints: no direction, no contribution
    Rgb L = qs.beta * endpointF(fQs, qs, qsToPt, TransportMode::Importance, &out->lightEnd) *
            endpointF(fPt, pt, -qsToPt, TransportMode::Radiance, &out->cameraEnd) * pt.beta;
    if (isBlack(L)) return L;
    const double g = unoccludedGeometryTerm(qs, pt, &out->shadow);
    if (g == 0.0) return Rgb(0.f);
    out->needsShadowRay = true;
    return L * float(g);
}

// Volume absorption along the connection segment (docs/materials.md, "Volume absorption"); s >= 1.
Rgb ConnectionEvaluation::transmittance() const {
    const PathVertex& lightEnd = s == 1 && t > 1 ? out->sampled : lightPath[s - 1];
    const PathVertex& cameraEnd = t == 1 ? out->sampled : cameraPath[t - 1];
    return segmentTransmittance(scene, vertexEnd(scene, lightEnd), vertexEnd(scene, cameraEnd));
}

bool ConnectionEvaluation::evaluate() const {
    if (t < 1) return false;
    Rgb L = s == 0 ? emitterHit() : t == 1 ? splatToCamera() : s == 1 ? nextEvent() : connectSubpaths();
    if (isBlack(L)) return false;
    if (s >= 1 && !scene.absorptionFree()) L *= transmittance();
    if (isBlack(L) || !isFinite(L)) return false;
    out->unweighted = L;
    return true;
}

bool evaluateIntoCleared(const Scene& scene, const PathVertex* lightPath, int s, const PathVertex* cameraPath, int t,
                         const PixelSampler& sampler, PendingConnection* out, LightSamplerKind lightSampler,
                         const SubpathBsdfs& bsdfs, bool withDensities) {
    // The endpoints' BSDFs (surface endpoints only): the side arrays' copies, or built once.
    const ConnectionEvaluation e{{scene, lightPath, s, cameraPath, t, sampler, lightSampler, withDensities},
                                 out,
                                 EndpointBsdfs(scene, lightPath, s, cameraPath, t, bsdfs)};
    return e.evaluate();
}

}  // namespace

bool evaluateConnection(const Scene& scene, const PathVertex* lightPath, int s, const PathVertex* cameraPath, int t,
                        const PixelSampler& sampler, PendingConnection* out, LightSamplerKind lightSampler,
                        const SubpathBsdfs& bsdfs) {
    *out = PendingConnection{};
    return evaluateIntoCleared(scene, lightPath, s, cameraPath, t, sampler, out, lightSampler, bsdfs, true);
}

bool evaluateConnectionUnweighted(const Scene& scene, const PathVertex* lightPath, int s, const PathVertex* cameraPath,
                                  int t, const PixelSampler& sampler, PendingConnection* out, const SubpathBsdfs& bsdfs) {
    *out = PendingConnection{};
    // Light tracing has only t = 1 (no next-event sample): the power sampler is never asked.
    return evaluateIntoCleared(scene, lightPath, s, cameraPath, t, sampler, out, LightSamplerKind::Power, bsdfs, false);
}

void finishConnection(const Scene& scene, const PathVertex* lightPath, int s, const PathVertex* cameraPath, int t,
                      const PendingConnection& pending, const BdptSettings& settings, Connection* out) {
    *out = Connection{};
    out->unweighted = pending.unweighted;
    out->splat = pending.splat;
    out->raster = pending.raster;
    // The recursive form (docs/mis.md): O(1) from the endpoints' dVCM/dVC and the four densities
    // that depend on the connection. The BSDF ones came with the endpoints' f (evaluateConnection);
    // the light's and the camera's are evaluated here, for the unoccluded connections only.
    const ConnectionDensities densities = connectionDensities(scene, lightPath, s, cameraPath, t, pending.sampled, settings.mis,
                                                              pending.cameraEnd, pending.lightEnd);
    out->weight = misWeightRecursive(scene, lightPath, s, cameraPath, t, pending.sampled, densities, settings.mis);
}

bool connectStrategy(const Scene& scene, const PathVertex* lightPath, int s, const PathVertex* cameraPath, int t,
                     const PixelSampler& sampler, const BdptSettings& settings, Connection* out, PathVertex* sampledOut,
                     const SubpathBsdfs& bsdfs) {
    *out = Connection{};
    PendingConnection pending;  // default state: evaluateConnection's clear is not repeated
    if (!evaluateIntoCleared(scene, lightPath, s, cameraPath, t, sampler, &pending, settings.mis.lightSampler, bsdfs, true))
        return false;
    if (pending.needsShadowRay && !traceShadowRay(scene, pending.shadow)) return false;
    finishConnection(scene, lightPath, s, cameraPath, t, pending, settings, out);
    if (sampledOut) *sampledOut = pending.sampled;
    return true;
}

bool connectUnweighted(const Scene& scene, const PathVertex* lightPath, int s, const PathVertex* cameraPath, int t,
                       const PixelSampler& sampler, Connection* out, const SubpathBsdfs& bsdfs, PathVertex* sampledOut) {
    PendingConnection pending;  // default state: evaluateConnection's clear is not repeated
    // Light tracing has only t = 1 (no next-event sample): the power sampler is never asked.
    if (!evaluateIntoCleared(scene, lightPath, s, cameraPath, t, sampler, &pending, LightSamplerKind::Power, bsdfs,
                             false))
        return false;
    if (pending.needsShadowRay && !traceShadowRay(scene, pending.shadow)) return false;
    *out = Connection{pending.unweighted, 1.0, pending.splat, pending.raster};
    if (sampledOut) *sampledOut = pending.sampled;
    return true;
}

}  // namespace bdptref
