#include "render/bdpt_vertex.h"
#include "render/light_choice.h"

namespace bdptref {

Bsdf vertexBsdf(const Scene& scene, const PathVertex& v) {
    return scene.bsdfAt(v.material, v.triangle, v.bary, v.ns, v.ng);
}

void EndpointBsdfs::build(const Scene& scene, const PathVertex* lightPath, int s, const PathVertex* cameraPath, int t) {
    // Surface vertices of a subpath have index >= 1 (index 0 is the light / the camera).
    if (!view_.light && s >= 2 && lightPath[s - 1].type == VertexType::Surface) {
        light_.resize(size_t(s));
        light_[size_t(s - 1)] = vertexBsdf(scene, lightPath[s - 1]);
        view_.light = light_.data();
    }
    if (!view_.camera && t >= 2 && cameraPath[t - 1].type == VertexType::Surface) {
        camera_.resize(size_t(t));
        camera_[size_t(t - 1)] = vertexBsdf(scene, cameraPath[t - 1]);
        view_.camera = camera_.data();
    }
}

const Light& vertexLight(const Scene& scene, const PathVertex& v) { return scene.lights[size_t(v.light)]; }

bool isDeltaLightVertex(const Scene& scene, const PathVertex& v) {
    if (v.type != VertexType::Light || v.light < 0) return false;
    const Light& l = vertexLight(scene, v);
    return isDeltaPosition(l) || isDeltaDirection(l);
}

bool isConnectible(const Scene& scene, const PathVertex& v) {
    switch (v.type) {
    case VertexType::Camera: return true;
    case VertexType::Light: return !isDeltaDirection(vertexLight(scene, v));
    case VertexType::Surface: return Bsdf::hasNonDelta(scene.materialParams(v.material, v.triangle, v.bary));
    }
    return false;
}

bool isConnectible(const Scene& scene, const PathVertex& v, const Bsdf& bsdf) {
    return v.type == VertexType::Surface ? bsdf.hasNonDelta() : isConnectible(scene, v);
}

void setLightSampleVertex(const Scene& scene, int li, const LightLiSample& ls, PathVertex* v) {
    const Light& light = scene.lights[size_t(li)];
    v->type = VertexType::Light;
    v->light = li;
    v->infinite = isInfinite(light);
    v->p = ls.pLight;
    v->ng = v->ns = v->infinite ? ls.wi : ls.nLight;
    v->triangle = light.triangle;
    v->bary = ls.bary;
}

double emissionDensityTowards(const Scene& scene, const PathVertex& v, const PathVertex& next) {
    const Light& l = vertexLight(scene, v);
    const Vec3 w = directionTo(v, next);
    float pdfPos = 0.f, pdfDir = 0.f;
    pdfLe(l, scene, v.p, w, l.type == LightType::Area ? l.normal : v.ng, &pdfPos, &pdfDir);
    if (isInfinite(l)) {
        // Parallel rays from a disk: area density at `next` = disk density * |cos| at next.
        double pdf = pdfPos;
        if (next.isOnSurface()) pdf *= std::abs(glm::dot(next.ng, w));
        return pdf;
    }
    return pdfDir;
}

double pdfLightToVertex(const Scene& scene, const PathVertex& v, const PathVertex& next) {
    const double pdf = emissionDensityTowards(scene, v, next);
    return isInfinite(vertexLight(scene, v)) ? pdf : convertDensity(pdf, v, next);
}

double lightOriginDensity(const Scene& scene, const PathVertex& v) {
    return lightOriginDensity(scene, v, scene.lightSampler().pmf(v.light));
}

double nextEventOriginDensity(const Scene& scene, LightSamplerKind kind, const PathVertex& shading, const PathVertex& v) {
    if (kind == LightSamplerKind::Power) return lightOriginDensity(scene, v);
    return lightOriginDensity(scene, v, lightChoicePmf(scene, kind, shading.p, shading.ng, v.light));
}

double nextEventPmfRatio(const Scene& scene, LightSamplerKind kind, const PathVertex& shading, int light) {
    if (kind == LightSamplerKind::Power) return 1.0;
    const double power = scene.lightSampler().pmf(light);
    return power > 0.0 ? double(lightChoicePmf(scene, kind, shading.p, shading.ng, light)) / power : 0.0;
}

double lightOriginDensity(const Scene& scene, const PathVertex& v, double pmf) {
    const Light& l = vertexLight(scene, v);
    switch (l.type) {
    case LightType::Area: return pmf / double(l.area);
    case LightType::Point:
    case LightType::Spot:
    case LightType::Directional: return pmf;  // the position (direction) is determined
    case LightType::Environment: {  // the map's density of the direction (v.ng: towards the environment)
        float pdfPos = 0.f, pdfDir = 0.f;
        pdfLe(l, scene, v.p, -v.ng, -v.ng, &pdfPos, &pdfDir);
        return pmf * double(pdfDir);
    }
    }
    return 0.0;
}

namespace {
// Density of `next` seen from a camera or light vertex (no BSDF involved).
double endpointPdf(const Scene& scene, const PathVertex& v, const PathVertex& next) {
    if (v.type == VertexType::Light) return pdfLightToVertex(scene, v, next);
    if (scene.camera.isOrthographic()) {  // parallel rays from a uniform film point
        const double cosNext = next.isOnSurface() ? std::abs(double(glm::dot(next.ng, scene.camera.forward()))) : 1.0;
        return scene.camera.pdfOrthographicVertex(next.p, cosNext, next.infinite);
    }
    float pdfPos, pdfDir;
    scene.camera.pdfWe(directionTo(v, next), &pdfPos, &pdfDir);
    return convertDensity(pdfDir, v, next);
}
}  // namespace

double vertexPdf(const Scene& scene, const PathVertex& v, const PathVertex* prev, const PathVertex& next) {
    if (v.type != VertexType::Surface) return endpointPdf(scene, v, next);
    if (!prev) return 0.0;
    return vertexPdf(scene, v, vertexBsdf(scene, v), prev, next);
}

double vertexPdf(const Scene& scene, const PathVertex& v, const Bsdf& bsdf, const PathVertex* prev, const PathVertex& next) {
    if (v.type != VertexType::Surface) return endpointPdf(scene, v, next);
    if (!prev) return 0.0;
    const Vec3 wp = directionTo(v, *prev), wn = directionTo(v, next);
    return convertDensity(bsdf.pdf(wp, wn), v, next);
}

Rgb emittedTowardsPrevious(const Scene& scene, const PathVertex& v) {
    if (v.light < 0) return Rgb(0.f);
    const Light& l = vertexLight(scene, v);
    if (v.infinite) return l.type == LightType::Environment ? environmentRadiance(l, scene, v.ng) : Rgb(0.f);  // ng: towards it
    if (v.type == VertexType::Surface && l.type == LightType::Area) return emittedRadiance(l, scene.textures, v.bary, v.wo);
    return Rgb(0.f);
}

}  // namespace bdptref
