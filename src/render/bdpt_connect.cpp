// The (s, t) connection strategies of BDPT (docs/mis.md, "Strategies").
#include "bdptref/bdpt.h"
#include "render/bdpt_vertex.h"

namespace bdptref {

namespace {

// Geometry term between two vertices with visibility: |cos| at each end that lies on a surface
// (shading normals: the BSDF's cosine convention) over distance^2 (none for infinite lights).
double geometryTerm(const Scene& scene, const PathVertex& a, const PathVertex& b) {
    if (b.infinite || a.infinite) {
        const PathVertex& fin = a.infinite ? b : a;
        const PathVertex& inf = a.infinite ? a : b;
        if (!scene.visibleToInfinity(fin.p, fin.isOnSurface() ? fin.ng : Vec3(0.f), inf.ng)) return 0.0;
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
    if (!scene.visible(a.p, a.isOnSurface() ? a.ng : Vec3(0.f), b.p, b.isOnSurface() ? b.ng : Vec3(0.f))) return 0.0;
    return g;
}

}  // namespace

bool connectStrategy(const Scene& scene, const PathVertex* lightPath, int s, const PathVertex* cameraPath, int t,
                     const PixelSampler& sampler, const BdptSettings& settings, Connection* out, PathVertex* sampledOut) {
    *out = Connection{};
    if (t < 1) return false;
    const PathVertex& pt = cameraPath[t - 1];
    PathVertex sampled{};
    Rgb L(0.f);

    if (s == 0) {
        // The camera subpath found an emitter.
        L = pt.beta * emittedTowardsPrevious(scene, pt);
    } else if (t == 1) {
        // Connect a light-subpath vertex to the pinhole and splat it.
        const PathVertex& qs = lightPath[s - 1];
        if (!isConnectible(scene, qs) || qs.infinite) return false;
        CameraImportanceSample cs;
        if (!scene.camera.sampleWi(qs.p, &cs) || !(cs.pdf > 0.f)) return false;
        sampled.type = VertexType::Camera;
        sampled.p = scene.camera.position();
        sampled.ng = sampled.ns = scene.camera.forward();
        sampled.beta = Rgb(cs.We / cs.pdf);
        sampled.pdfFwd = 1.0;
        if (qs.type == VertexType::Surface) {
            L = qs.beta * vertexF(scene, qs, sampled, TransportMode::Importance) * sampled.beta * absDot(cs.wi, qs.ns);
        } else {  // the light vertex itself (light tracing of emitters seen directly)
            const Light& light = vertexLight(scene, qs);
            const float cosLight = light.type == LightType::Area ? absDot(cs.wi, light.normal) : 1.f;
            L = lightEmission(light, cs.wi) * float(double(cosLight) / lightOriginDensity(scene, qs)) * sampled.beta;
        }
        if (isBlack(L)) return false;
        if (!scene.visible(qs.p, qs.isOnSurface() ? qs.ng : Vec3(0.f), sampled.p, Vec3(0.f))) return false;
        out->splat = true;
        out->raster = cs.raster;
    } else if (s == 1) {
        // Next-event estimation: a fresh light sample for camera vertex t-1.
        if (!isConnectible(scene, pt) || pt.type != VertexType::Surface) return false;
        const uint32_t bounce = uint32_t(t - 2);
        float pmf = 0.f;
        const int li = scene.lightSampler().sample(sampler.get1D(RngStream::Camera, dim::vertex(bounce, dim::kNeeLight)), &pmf);
        if (li < 0 || !(pmf > 0.f)) return false;
        const Light& light = scene.lights[size_t(li)];
        LightLiSample ls;
        if (!sampleLi(light, pt.p, sampler.get2D(RngStream::Camera, dim::vertex(bounce, dim::kNeePosition)), &ls) ||
            !(ls.pdf > 0.f) || isBlack(ls.Li))
            return false;
        sampled.type = VertexType::Light;
        sampled.light = li;
        sampled.infinite = isInfinite(light);
        sampled.p = ls.pLight;
        sampled.ng = sampled.ns = sampled.infinite ? ls.wi : ls.nLight;
        sampled.triangle = light.triangle;
        sampled.beta = ls.Li / (pmf * ls.pdf);
        sampled.pdfFwd = lightOriginDensity(scene, sampled);
        L = pt.beta * vertexF(scene, pt, sampled, TransportMode::Radiance) * sampled.beta * absDot(ls.wi, pt.ns);
        if (isBlack(L)) return false;
        const bool unoccluded = sampled.infinite ? scene.visibleToInfinity(pt.p, pt.ng, ls.wi)
                                                 : scene.visible(pt.p, pt.ng, ls.pLight, ls.nLight);
        if (!unoccluded) return false;
    } else {
        // Both subpaths contribute a vertex: connect them with a shadow ray.
        const PathVertex& qs = lightPath[s - 1];
        if (!isConnectible(scene, qs) || !isConnectible(scene, pt)) return false;
        if (qs.type != VertexType::Surface || pt.type != VertexType::Surface) return false;
        L = qs.beta * vertexF(scene, qs, pt, TransportMode::Importance) * vertexF(scene, pt, qs, TransportMode::Radiance) * pt.beta;
        if (isBlack(L)) return false;
        const double g = geometryTerm(scene, qs, pt);
        if (g == 0.0) return false;
        L *= float(g);
    }
    if (isBlack(L) || !isFinite(L)) return false;
    out->unweighted = L;
    out->weight = misWeight(scene, lightPath, s, cameraPath, t, sampled, settings.mis);
    if (sampledOut) *sampledOut = sampled;
    return true;
}

}  // namespace bdptref
