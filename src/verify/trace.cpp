// Replay of one BDPT pixel sample with everything recorded, and the MIS weight formula on explicit
// densities (docs/trace-and-mis.md). The contributions come from the library's own
// generateCameraSubpath / generateLightSubpath / connectStrategy, called in the BDPT integrator's
// order; the only code here that looks at light transport is the *diagnosis* of a connection that
// contributed nothing (which condition of connectStrategy failed), and it never changes a value.
#include "bdptref/trace.h"
#include "verify/trace_path.h"
#include "verify/transmission_diagnosis.h"

#include "bdptref/errors.h"
#include "bdptref/light.h"
#include "bdptref/renderer.h"
#include "bdptref/scene.h"
#include "render/bdpt_vertex.h"
#include "render/light_choice.h"
#include "scene/accel.h"

#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <utility>

namespace bdptref {

namespace {


std::string xname(int i) { return "x" + std::to_string(i); }
std::string cam(int i) { return "camera[" + std::to_string(i) + "]"; }
std::string lig(int i) { return "light[" + std::to_string(i) + "]"; }

// ---- diagnosis of a connection that contributed nothing --------------------------------------
// Mirrors the order of the checks in connectStrategy (src/render/bdpt_connect.cpp) with the same
// library functions, to say WHICH one failed. Values are never taken from here.

struct Diagnosis {
    ConnectionStatus status = ConnectionStatus::Unexplained;
    std::string reason;
};

Diagnosis because(ConnectionStatus s, std::string reason) { return Diagnosis{s, std::move(reason)}; }

std::string materialName(const Scene& scene, uint32_t m) {
    return "material " + std::to_string(m) + " '" + scene.materials[m].name + "'";
}

// "The BSDF at `an` towards `bn` is zero", with the cause when it is across the surface: worded
// after the material (no transmission lobe, a delta one, or what zeroes a rough one).
Diagnosis zeroBsdf(const Scene& scene, const PathVertex& a, const std::string& an, const PathVertex& b, const std::string& bn,
                   TransportMode mode) {
    std::string why = "the BSDF at " + an + " towards " + bn + " is zero";
    const Vec3 wi = directionTo(a, b);
    const float sideOut = glm::dot(a.ng, wi), sideIn = glm::dot(a.ng, a.wo);
    if (sideOut * sideIn < 0.f)
        why += " (" + bn + " is on the other side of the surface: " +
               zeroTransmissionCause(scene.materialParams(a.material, a.triangle, a.bary), materialName(scene, a.material), a.ns,
                                     a.ng, a.wo, wi, mode) +
               ")";
    return because(ConnectionStatus::ZeroContribution, why);
}

Diagnosis notConnectible(const Scene& scene, const PathVertex& v, const std::string& name) {
    if (v.type == VertexType::Surface)
        return because(ConnectionStatus::DeltaVertex, name + " has only delta lobes (" + materialName(scene, v.material) +
                                                          "): a deterministic connection cannot reach it");
    if (v.type == VertexType::Light && v.light >= 0 && isDeltaDirection(vertexLight(scene, v)))
        return because(ConnectionStatus::DeltaVertex, name + " is a directional light (a delta direction): it cannot be connected");
    return because(ConnectionStatus::NotConnectible, name + " is not a surface vertex");
}

Diagnosis geometryDiagnosis(const Scene& scene, const PathVertex& a, const std::string& an, const PathVertex& b,
                            const std::string& bn) {
    const DVec3 d = DVec3(b.p) - DVec3(a.p);
    const double dist2 = glm::dot(d, d);
    if (!(dist2 > 0.0)) return because(ConnectionStatus::ZeroGeometry, an + " and " + bn + " coincide (distance 0)");
    const DVec3 w = d / std::sqrt(dist2);
    if (a.isOnSurface() && glm::dot(DVec3(a.ns), w) == 0.0)
        return because(ConnectionStatus::ZeroGeometry, "the connection is tangent to " + an + " (cosine 0)");
    if (b.isOnSurface() && glm::dot(DVec3(b.ns), w) == 0.0)
        return because(ConnectionStatus::ZeroGeometry, "the connection is tangent to " + bn + " (cosine 0)");
    if (!scene.visible(a.p, a.isOnSurface() ? a.ng : Vec3(0.f), b.p, b.isOnSurface() ? b.ng : Vec3(0.f)))
        return because(ConnectionStatus::Occluded, "the shadow ray between " + an + " and " + bn + " is blocked");
    return because(ConnectionStatus::NonFinite, "the geometry term between " + an + " and " + bn + " is not finite");
}

// Which condition of the strategy's evaluation failed (src/render/bdpt_connect.cpp,
// ConnectionEvaluation), one step per kind of strategy, in the same order of checks.
struct ConnectionDiagnosis : StrategyInputs {
    // f at an endpoint as the connection evaluates it.
    Rgb endpointF(const PathVertex& v, const PathVertex& other, TransportMode mode) const {
        return vertexBsdf(scene, v).f(connectionIncoming(v, weighted), directionTo(v, other), mode);
    }
    Diagnosis emitterHit() const;
    Diagnosis splatToCamera() const;
    Diagnosis nextEvent() const;
    Diagnosis connectSubpaths() const;
    Diagnosis run() const {
        return s == 0 ? emitterHit() : t == 1 ? splatToCamera() : s == 1 ? nextEvent() : connectSubpaths();
    }
};

Diagnosis ConnectionDiagnosis::emitterHit() const {
    const PathVertex& pt = cameraPath[t - 1];
    if (pt.light < 0) return because(ConnectionStatus::NotOnEmitter, cam(t - 1) + " is not on a light");
    const Light& l = vertexLight(scene, pt);
    if (isBlack(emittedTowardsPrevious(scene, pt)))
        return because(ConnectionStatus::NotOnEmitter,
                       cam(t - 1) + " lies on light " + std::to_string(pt.light) + " (" + lightTypeName(l.type) +
                           ") but it emits nothing towards " + cam(t - 2) + " (the back of a one-sided emitter)");
    if (isBlack(pt.beta)) return because(ConnectionStatus::ZeroContribution, "the throughput of " + cam(t - 1) + " is zero");
    return because(ConnectionStatus::NonFinite, "the contribution is not finite");
}

Diagnosis ConnectionDiagnosis::splatToCamera() const {
    const PathVertex& qs = lightPath[s - 1];
    if (!isConnectible(scene, qs)) return notConnectible(scene, qs, lig(s - 1));
    // The camera vertex: the pinhole, or (orthographic) the film point the vertex projects onto.
    const std::string cameraPoint = scene.camera.isOrthographic() ? "the film point" : "the pinhole";
    if (qs.infinite)
        return because(ConnectionStatus::NotConnectible,
                       lig(s - 1) + " is an infinite light (a direction): it cannot be connected to " + cameraPoint);
    CameraImportanceSample cs;
    if (!scene.camera.sampleWi(qs.p, &cs) || !(cs.pdf > 0.f))
        return because(ConnectionStatus::OutsideImage, lig(s - 1) + " projects outside the image (or the crop window)");
    if (qs.type == VertexType::Surface) {
        PathVertex c{};
        c.type = VertexType::Camera;
        c.p = cs.pCamera;
        c.ng = c.ns = scene.camera.forward();
        if (isBlack(qs.beta)) return because(ConnectionStatus::ZeroContribution, "the throughput of " + lig(s - 1) + " is zero");
        if (isBlack(endpointF(qs, c, TransportMode::Importance)))
            return zeroBsdf(scene, qs, lig(s - 1), c, cameraPoint, TransportMode::Importance);
        if (absDot(cs.wi, qs.ns) == 0.f)
            return because(ConnectionStatus::ZeroGeometry, "the direction to " + cameraPoint + " is tangent to " + lig(s - 1));
    } else if (isBlack(lightEmission(vertexLight(scene, qs), scene, qs.bary, cs.wi))) {
        return because(ConnectionStatus::ZeroContribution,
                       "light " + std::to_string(qs.light) + " emits nothing towards " + cameraPoint + " (back side or outside the cone)");
    }
    if (!scene.visible(qs.p, qs.isOnSurface() ? qs.ng : Vec3(0.f), cs.pCamera, Vec3(0.f)))
        return because(ConnectionStatus::Occluded, "the shadow ray from " + lig(s - 1) + " to " + cameraPoint + " is blocked");
    return because(ConnectionStatus::NonFinite, "the contribution is zero or not finite after all factors");
}

Diagnosis ConnectionDiagnosis::nextEvent() const {
    const PathVertex& pt = cameraPath[t - 1];
    if (!isConnectible(scene, pt)) return notConnectible(scene, pt, cam(t - 1));
    if (pt.type != VertexType::Surface)
        return because(ConnectionStatus::NotConnectible, cam(t - 1) + " is not a surface (the ray escaped)");
    const uint32_t bounce = uint32_t(t - 2);
    float pmf = 0.f;
    const int li = chooseLight(scene, lightSampler, pt.p, pt.ng,
                               sampler.get1D(RngStream::Camera, dim::vertex(bounce, dim::kNeeLight)), &pmf);
    if (li < 0 || !(pmf > 0.f)) return because(ConnectionStatus::LightSampleFailed, "no light could be chosen");
    const Light& light = scene.lights[size_t(li)];
    LightLiSample ls;
    if (!sampleLi(light, scene, pt.p, sampler.get2D(RngStream::Camera, dim::vertex(bounce, dim::kNeePosition)), &ls) ||
        !(ls.pdf > 0.f) || isBlack(ls.Li))
        return because(ConnectionStatus::LightSampleFailed,
                       "the sample on light " + std::to_string(li) + " (" + lightTypeName(light.type) + ") has no density or no radiance at " +
                           cam(t - 1) + " (behind a one-sided emitter, outside a spot cone)");
    PathVertex lv{};
    setLightSampleVertex(scene, li, ls, &lv);
    if (isBlack(pt.beta)) return because(ConnectionStatus::ZeroContribution, "the throughput of " + cam(t - 1) + " is zero");
    if (isBlack(endpointF(pt, lv, TransportMode::Radiance)))
        return zeroBsdf(scene, pt, cam(t - 1), lv, "the light sample", TransportMode::Radiance);
    if (absDot(ls.wi, pt.ns) == 0.f)
        return because(ConnectionStatus::ZeroGeometry, "the direction to the light sample is tangent to " + cam(t - 1));
    const bool unoccluded = lv.infinite ? scene.visibleToInfinity(pt.p, pt.ng, ls.wi) : scene.visible(pt.p, pt.ng, ls.pLight, ls.nLight);
    if (!unoccluded)
        return because(ConnectionStatus::Occluded, "the shadow ray from " + cam(t - 1) + " to the light sample is blocked");
    return because(ConnectionStatus::NonFinite, "the contribution is zero or not finite after all factors");
}

Diagnosis ConnectionDiagnosis::connectSubpaths() const {
    const PathVertex& pt = cameraPath[t - 1];
    const PathVertex& qs = lightPath[s - 1];
    if (!isConnectible(scene, qs)) return notConnectible(scene, qs, lig(s - 1));
    if (!isConnectible(scene, pt)) return notConnectible(scene, pt, cam(t - 1));
    if (qs.type != VertexType::Surface) return because(ConnectionStatus::NotConnectible, lig(s - 1) + " is not a surface");
    if (pt.type != VertexType::Surface)
        return because(ConnectionStatus::NotConnectible, cam(t - 1) + " is not a surface (the ray escaped)");
    if (isBlack(qs.beta)) return because(ConnectionStatus::ZeroContribution, "the throughput of " + lig(s - 1) + " is zero");
    if (isBlack(pt.beta)) return because(ConnectionStatus::ZeroContribution, "the throughput of " + cam(t - 1) + " is zero");
    if (isBlack(endpointF(qs, pt, TransportMode::Importance)))
        return zeroBsdf(scene, qs, lig(s - 1), pt, cam(t - 1), TransportMode::Importance);
    if (isBlack(endpointF(pt, qs, TransportMode::Radiance)))
        return zeroBsdf(scene, pt, cam(t - 1), qs, lig(s - 1), TransportMode::Radiance);
    return geometryDiagnosis(scene, qs, lig(s - 1), pt, cam(t - 1));
}

Diagnosis diagnose(const Scene& scene, const PathVertex* lightPath, int s, const PathVertex* cameraPath, int t,
                   const PixelSampler& sampler, LightSamplerKind lightSampler, bool weighted) {
    return ConnectionDiagnosis{{scene, lightPath, s, cameraPath, t, sampler, lightSampler, weighted}}.run();
}

VertexRandom vertexRandom(const PixelSampler& sampler, RngStream stream, uint32_t bounce) {
    VertexRandom r;
    r.bounce = bounce;
    r.dimensionBase = dim::vertex(bounce, dim::kBsdfLobe);
    r.bsdfLobe = sampler.get1D(stream, dim::vertex(bounce, dim::kBsdfLobe));
    r.bsdfDirection = sampler.get2D(stream, dim::vertex(bounce, dim::kBsdfDirection));
    r.roulette = sampler.get1D(stream, dim::vertex(bounce, dim::kRoulette));
    if (stream == RngStream::Camera) {
        r.neeLight = sampler.get1D(stream, dim::vertex(bounce, dim::kNeeLight));
        r.neePosition = sampler.get2D(stream, dim::vertex(bounce, dim::kNeePosition));
    }
    return r;
}

void checkDensity(double v, const std::string& what) {
    if (std::isnan(v) || v < 0.0) {
        std::ostringstream o;
        o << what << " is " << v << ": densities must be >= 0 (0: the strategy cannot sample the vertex)";
        throw InputError(o.str());
    }
}

}  // namespace

// ---- MIS from densities ------------------------------------------------------------------------

std::vector<StrategyVerdict> analyseMisDensities(const PathDensities& d, const MisSettings& mis) {
    const int n = int(d.vertices.size());
    if (n < 2)
        throw InputError("a full path needs at least 2 vertices (the camera and a point on a light), got " + std::to_string(n));
    for (int i = 0; i < n; ++i) {
        checkDensity(d.vertices[size_t(i)].camera, "camera-side density of " + xname(i));
        if (i > 0) checkDensity(d.vertices[size_t(i)].light, "light-side density of " + xname(i));
    }
    checkDensity(d.lightNextEvent, "next-event density of the light endpoint " + xname(n - 1));

    auto interiorDelta = [&](int i) { return i > 0 && i < n - 1 && d.vertices[size_t(i)].delta; };
    // Dirac factors of densities sampled through a delta vertex are 1 (docs/mis.md, "Delta vertices").
    auto camFactor = [&](int i) { return i >= 2 && interiorDelta(i - 1) ? 1.0 : d.vertices[size_t(i)].camera; };
    auto lightFactor = [&](int k) { return k <= n - 3 && interiorDelta(k + 1) ? 1.0 : d.vertices[size_t(k)].light; };

    using LD = long double;
    const LD minusInf = -std::numeric_limits<LD>::infinity();
    std::vector<StrategyVerdict> v(static_cast<size_t>(n));
    std::vector<LD> logP(static_cast<size_t>(n), minusInf);
    for (int s = 0; s < n; ++s) {
        StrategyVerdict& r = v[size_t(s)];
        const int t = n - s;
        r.s = s;
        r.t = t;
        r.logDensity = -std::numeric_limits<double>::infinity();
        if (s == 0 && d.deltaLight) {
            r.reason = "s = 0: the camera subpath cannot hit a delta light (point, spot or directional)";
            continue;
        }
        if (s >= 1 && n == 2) {
            r.reason = "depth 0 (a light seen directly) is rendered by s = 0 alone: (1,1) is not a BDPT strategy";
            continue;
        }
        if (s >= 1 && interiorDelta(t - 1)) {
            r.reason = "the connection " + xname(t - 1) + "-" + xname(t) + " touches " + xname(t - 1) + ", a delta (specular) vertex";
            continue;
        }
        if (s >= 2 && interiorDelta(t)) {
            r.reason = "the connection " + xname(t - 1) + "-" + xname(t) + " touches " + xname(t) + ", a delta (specular) vertex";
            continue;
        }
        LD logp = 0;
        bool zero = false;
        auto factor = [&](double f, const std::string& what) {
            if (zero) return;
            if (!(f > 0.0)) {
                zero = true;
                r.reason = "a density factor is 0: " + what;
                return;
            }
            logp += std::log(LD(f));
        };
        for (int i = 0; i < t; ++i) factor(camFactor(i), "the camera-side density of " + xname(i));
        if (s == 1) factor(d.lightNextEvent, "the next-event density of the light endpoint " + xname(n - 1));
        if (s >= 2) factor(d.vertices[size_t(n - 1)].light, "the emission (origin) density of the light endpoint " + xname(n - 1));
        for (int k = t; k < n - 1; ++k) factor(lightFactor(k), "the light-side density of " + xname(k));
        if (zero) continue;
        r.valid = true;
        r.logDensity = double(logp);
        logP[size_t(s)] = logp;
    }

    // w_s = exp(b (log p_s - m)) / sum_j exp(b (log p_j - m)), m = max finite log p (as the definition).
    LD m = minusInf;
    int count = 0, infinite = 0;
    for (int s = 0; s < n; ++s)
        if (v[size_t(s)].valid) {
            ++count;
            if (std::isinf(logP[size_t(s)])) ++infinite;
            else m = std::max(m, logP[size_t(s)]);
        }
    if (count == 0) return v;
    const LD b = LD(mis.exponent());
    std::vector<LD> terms(static_cast<size_t>(n), 0);
    LD sum = 0;
    for (int s = 0; s < n; ++s) {
        if (!v[size_t(s)].valid) continue;
        LD term;
        if (b == 0) term = 1;
        else if (infinite > 0) term = std::isinf(logP[size_t(s)]) ? 1 : 0;
        else term = std::exp(b * (logP[size_t(s)] - m));
        terms[size_t(s)] = term;
        sum += term;
    }
    for (int s = 0; s < n; ++s) v[size_t(s)].weight = double(terms[size_t(s)] / sum);
    return v;
}

std::vector<double> misWeightsFromDensities(const PathDensities& path, const MisSettings& mis) {
    const std::vector<StrategyVerdict> v = analyseMisDensities(path, mis);
    std::vector<double> w(v.size());
    for (size_t i = 0; i < v.size(); ++i) w[i] = v[i].weight;
    return w;
}

void validateScenePath(const Scene& scene, const std::vector<PathVertex>& x) {
    const int n = int(x.size());
    if (n < 2)
        throw InputError("a full path needs at least 2 vertices (the camera and a point on a light), got " + std::to_string(n));
    for (int i = 0; i < n; ++i) {
        const PathVertex& v = x[size_t(i)];
        const std::string name = "vertex " + std::to_string(i);
        if (!isFinite(v.p) || !isFinite(v.ng) || !isFinite(v.ns)) throw InputError(name + ": position and normals must be finite");
        if (i == 0 && v.type != VertexType::Camera) throw InputError(name + " must be the camera (type \"camera\")");
        if (i > 0 && v.type == VertexType::Camera) throw InputError(name + ": only vertex 0 can be the camera");
        if (i > 0 && i < n - 1 && v.type != VertexType::Surface) throw InputError(name + ": interior vertices must be surfaces");
        if (v.type == VertexType::Surface && v.material >= scene.materials.size())
            throw InputError(name + ": material " + std::to_string(v.material) + " does not exist (the scene has " +
                             std::to_string(scene.materials.size()) + ")");
        if (v.light < -1 || (v.light >= 0 && size_t(v.light) >= scene.lights.size()))
            throw InputError(name + ": light " + std::to_string(v.light) + " does not exist (the scene has " +
                             std::to_string(scene.lights.size()) + ")");
    }
    const PathVertex& e = x.back();
    if (e.light < 0) throw InputError("vertex " + std::to_string(n - 1) + " (the last) must lie on a light (\"light\": index)");
    const Light& l = scene.lights[size_t(e.light)];
    if (e.infinite != isInfinite(l))
        throw InputError("vertex " + std::to_string(n - 1) + ": \"infinite\" must be " + (isInfinite(l) ? "true" : "false") +
                         " for light " + std::to_string(e.light) + " (" + lightTypeName(l.type) + ")");
    if (e.infinite && glm::dot(e.ng, e.ng) == 0.f)
        throw InputError("vertex " + std::to_string(n - 1) + ": an infinite-light vertex needs its direction in \"ng\"");
}

PathDensities pathDensitiesFromScene(const Scene& scene, const std::vector<PathVertex>& x, LightSamplerKind nextEventSampler) {
    validateScenePath(scene, x);
    const int n = int(x.size());
    auto interiorDelta = [&](int i) { return i > 0 && i < n - 1 && x[size_t(i)].delta; };
    PathDensities d;
    d.vertices.resize(size_t(n));
    for (int i = 0; i < n; ++i) d.vertices[size_t(i)].delta = interiorDelta(i);
    // Camera side: the pinhole, the camera's direction density, then BSDF sampling (0 = a Dirac
    // factor through a delta vertex, as the production subpaths store it).
    d.vertices[0].camera = 1.0;
    for (int i = 1; i < n; ++i)
        d.vertices[size_t(i)].camera =
            interiorDelta(i - 1) ? 0.0 : vertexPdf(scene, x[size_t(i - 1)], i >= 2 ? &x[size_t(i - 2)] : nullptr, x[size_t(i)]);
    // Light side: emission towards x_{n-2}, then BSDF sampling towards the camera.
    const PathVertex& e = x[size_t(n - 1)];
    const Light& l = vertexLight(scene, e);
    if (n >= 3) d.vertices[size_t(n - 2)].light = pdfLightToVertex(scene, e, x[size_t(n - 2)]);
    for (int k = n - 3; k >= 1; --k)
        d.vertices[size_t(k)].light = interiorDelta(k + 1) ? 0.0 : vertexPdf(scene, x[size_t(k + 1)], &x[size_t(k + 2)], x[size_t(k)]);
    d.vertices[0].light = 0.0;  // never used: the pinhole is always sampled by the camera
    // The light endpoint: origin density (s >= 2) and next-event density (s = 1).
    d.vertices[size_t(n - 1)].light = lightOriginDensity(scene, e);
    const PathVertex& r = x[size_t(n - 2)];
    const double pmf = double(lightChoicePmf(scene, nextEventSampler, r.p, r.ng, e.light));  // s = 1 chooses at r
    switch (l.type) {
    case LightType::Area:
        d.lightNextEvent = pmf * convertDensity(double(pdfLi(l, r.p, e.p, l.normal)), r, e);
        break;
    case LightType::Environment: d.lightNextEvent = pmf * double(pdfLi(l, scene, r.p, e.p, e.ng)); break;
    case LightType::Point:
    case LightType::Directional: d.lightNextEvent = pmf; break;
    case LightType::Spot: {
        // A delta position, but nothing is emitted (or sampled) outside the outer cone.
        const bool inCone = pdfLightToVertex(scene, e, r) > 0.0;
        d.lightNextEvent = inCone ? pmf : 0.0;
        if (!inCone) d.vertices[size_t(n - 1)].light = 0.0;
        break;
    }
    }
    d.deltaLight = isDeltaPosition(l) || isDeltaDirection(l);
    return d;
}

namespace {
// Verdicts of the densities form (rules + zero factors, with reasons) carrying the definition's weights.
std::vector<StrategyVerdict> withDefinitionWeights(std::vector<StrategyVerdict> v, const std::vector<double>& w,
                                                   const MisSettings& mis) {
    for (size_t s = 0; s < v.size() && s < w.size(); ++s) {
        v[s].weight = w[s];
        if (!v[s].valid && w[s] > 0.0)
            v[s].reason += " (but the definition gives it a non-zero weight: the two density evaluations disagree)";
        if (v[s].valid && w[s] == 0.0 && mis.exponent() == 0.0) {  // uniform: a valid strategy never has weight 0
            v[s].valid = false;
            v[s].reason = "the definition finds a density factor of 0 (the production density functions do not)";
        }
    }
    return v;
}
}  // namespace

std::vector<StrategyVerdict> analyseMisScene(const Scene& scene, const std::vector<PathVertex>& path, const MisSettings& mis) {
    return withDefinitionWeights(analyseMisDensities(pathDensitiesFromScene(scene, path, mis.lightSampler), mis),
                                 misWeightsDefinition(scene, path, mis), mis);
}

std::vector<PathVertex> assembleFullPath(const PathVertex* cameraPath, int t, const PathVertex* lightPath, int s,
                                         const PathVertex& sampled) {
    std::vector<PathVertex> path;
    path.reserve(size_t(s + t));
    for (int i = 0; i < t; ++i) path.push_back(t == 1 ? sampled : cameraPath[i]);
    // (1, 1), light tracing's depth 0: the fresh endpoint is the camera, light[0] is kept.
    for (int j = s - 1; j >= 0; --j) path.push_back(s == 1 && t != 1 ? sampled : lightPath[j]);
    if (t >= 1) path[size_t(t - 1)].delta = false;
    if (s > 0) path[size_t(t)].delta = false;
    return path;
}

// ---- the replay --------------------------------------------------------------------------------

const char* connectionStatusName(ConnectionStatus s) {
    switch (s) {
    case ConnectionStatus::Contributed: return "contributed";
    case ConnectionStatus::DepthLimit: return "depth-limit";
    case ConnectionStatus::DepthZeroRule: return "depth-0-rule";
    case ConnectionStatus::NotOnEmitter: return "not-on-emitter";
    case ConnectionStatus::DeltaVertex: return "delta-vertex";
    case ConnectionStatus::NotConnectible: return "not-connectible";
    case ConnectionStatus::OutsideImage: return "outside-image";
    case ConnectionStatus::LightSampleFailed: return "light-sample-failed";
    case ConnectionStatus::ZeroContribution: return "zero-contribution";
    case ConnectionStatus::ZeroGeometry: return "zero-geometry";
    case ConnectionStatus::Occluded: return "occluded";
    case ConnectionStatus::NonFinite: return "non-finite";
    case ConnectionStatus::Unexplained: return "unexplained";
    }
    return "?";
}

namespace {

void checkTraceArguments(const Scene& scene, const TraceSettings& settings, int px, int py) {
    checkTracedPixel(scene.camera, px, py);
    if (settings.bdpt.maxDepth < 0) throw InputError("the maximum depth must be >= 0");
    if (settings.integrator != "bdpt" && settings.integrator != "lt")
        throw InputError("--integrator: trace replays 'bdpt' or 'lt' samples, got '" + settings.integrator + "'");
}

}  // namespace

TracedSample traceFromSubpaths(const Scene& scene, const TraceSettings& settings, int px, int py, uint64_t sample,
                               std::vector<PathVertex> cameraPath, std::vector<PathVertex> lightPath,
                               const StrategyOutcome& outcome) {
    checkTraceArguments(scene, settings, px, py);
    setFlushDenormals();  // as every rendering thread (renderer.cpp): same float results

    TracedSample out;
    out.x = px;
    out.y = py;
    out.sample = sample;
    out.settings = settings;
    out.pixelIndex = pixelIndex(px, py, scene.camera.width());
    const BdptSettings& bs = settings.bdpt;
    const bool lightOnly = settings.integrator == "lt";
    const PixelSampler sampler(settings.seed, out.pixelIndex, sample);
    const int nCamera = int(cameraPath.size()), nLight = int(lightPath.size());
    out.cameraPath = std::move(cameraPath);
    out.lightPath = std::move(lightPath);
    // The connection functions index the subpaths; an empty one (lt: no camera subpath) is never read.
    const PathVertex none{};
    const PathVertex* camera = nCamera > 0 ? out.cameraPath.data() : &none;
    const PathVertex* light = nLight > 0 ? out.lightPath.data() : &none;

    out.raster = Vec2(float(px), float(py)) + sampler.get2D(RngStream::Camera, dim::kFilm);
    out.lightChoice = sampler.get1D(RngStream::Light, dim::kLightChoice);
    out.emitPosition = sampler.get2D(RngStream::Light, dim::kEmitPosition);
    out.emitDirection = sampler.get2D(RngStream::Light, dim::kEmitDirection);
    out.cameraRandom.resize(size_t(nCamera));
    out.lightRandom.resize(size_t(nLight));
    for (int i = 1; i < nCamera; ++i) out.cameraRandom[size_t(i)] = vertexRandom(sampler, RngStream::Camera, uint32_t(i - 1));
    for (int j = 1; j < nLight; ++j) out.lightRandom[size_t(j)] = vertexRandom(sampler, RngStream::Light, uint32_t(j - 1));

    // The integrator's loop (src/render/bdpt_integrator.cpp); lt keeps t = 1, s >= 1, weight 1.
    const int tEnd = lightOnly ? 1 : nCamera;
    for (int t = 1; t <= tEnd; ++t)
        for (int s = lightOnly ? 1 : 0; s <= lastLightStrategy(nLight, t); ++s) {
            const int depth = s + t - 2;
            const StrategyStatus verdict = strategyStatus(s, t, bs.maxDepth, lightOnly);
            if (verdict == StrategyStatus::NotAPath) continue;
            TracedConnection tc;
            tc.s = s;
            tc.t = t;
            tc.depth = depth;
            tc.splat = t == 1;
            if (verdict == StrategyStatus::DepthLimit) {
                tc.status = ConnectionStatus::DepthLimit;
                tc.reason = "depth " + std::to_string(depth) + " > --max-depth " + std::to_string(bs.maxDepth) + ": not evaluated";
                out.connections.push_back(std::move(tc));
                continue;
            }
            if (verdict == StrategyStatus::DepthZeroRule) {
                tc.status = ConnectionStatus::DepthZeroRule;
                tc.reason = "depth 0 is strategy (0,2) alone: (1,1) is not a BDPT strategy (docs/mis.md)";
                out.connections.push_back(std::move(tc));
                continue;
            }
            Connection c;
            PathVertex sampled{};
            if (!outcome(s, t, &c, &sampled)) {
                const Diagnosis dg = diagnose(scene, light, s, camera, t, sampler, bs.mis.lightSampler, !lightOnly);
                tc.status = dg.status;
                tc.reason = dg.status == ConnectionStatus::Unexplained || dg.reason.empty()
                                ? "connectStrategy returned no contribution (the diagnosis found no failing condition)"
                                : dg.reason;
                out.connections.push_back(std::move(tc));
                continue;
            }
            tc.status = ConnectionStatus::Contributed;
            tc.unweighted = c.unweighted;
            tc.weight = lightOnly ? 1.0 : c.weight;  // light tracing is unweighted
            const Rgb weighted = c.unweighted * float(tc.weight);  // exactly as the integrator
            tc.weighted = weighted;
            tc.splat = c.splat;
            tc.raster = c.raster;
            tc.hasSampled = s == 1 || t == 1;
            if (tc.hasSampled) tc.sampled = sampled;
            if (c.splat) out.splats.push_back(Splat{c.raster, weighted});
            else out.L += weighted;
            if (settings.fullPaths) {
                tc.path = assembleFullPath(camera, t, light, s, sampled);
                tc.densities = pathDensitiesFromScene(scene, tc.path, bs.mis.lightSampler);
                tc.definitionWeights = misWeightsDefinition(scene, tc.path, bs.mis);
                tc.strategies = withDefinitionWeights(analyseMisDensities(tc.densities, bs.mis), tc.definitionWeights, bs.mis);
            }
            out.connections.push_back(std::move(tc));
        }
    return out;
}

TracedSample traceSample(const Scene& scene, const TraceSettings& settings, int px, int py, uint64_t sample) {
    checkTraceArguments(scene, settings, px, py);
    setFlushDenormals();
    const BdptSettings& bs = settings.bdpt;
    const bool lightOnly = settings.integrator == "lt";
    const PixelSampler sampler(settings.seed, pixelIndex(px, py, scene.camera.width()), sample);
    // As BdptIntegrator::samplePixel (src/render/bdpt_integrator.cpp).
    std::vector<PathVertex> cameraBuf(size_t(std::max(bs.maxCameraVertices(), 1))), lightBuf(size_t(std::max(bs.maxLightVertices(), 1)));
    const Vec2 raster = Vec2(float(px), float(py)) + sampler.get2D(RngStream::Camera, dim::kFilm);
    const int nCamera = lightOnly ? 0 : generateCameraSubpath(scene, sampler, raster, bs, cameraBuf.data());
    const int nLight = generateLightSubpath(scene, sampler, bs, lightBuf.data());
    // lt: the light tracer's own evaluation (no MIS densities: f from wo), as BdptIntegrator's.
    const StrategyOutcome connect = [&](int s, int t, Connection* c, PathVertex* sampled) {
        return lightOnly ? connectUnweighted(scene, lightBuf.data(), s, cameraBuf.data(), t, sampler, c, {}, sampled)
                         : connectStrategy(scene, lightBuf.data(), s, cameraBuf.data(), t, sampler, bs, c, sampled);
    };
    return traceFromSubpaths(scene, settings, px, py, sample,
                             std::vector<PathVertex>(cameraBuf.begin(), cameraBuf.begin() + nCamera),
                             std::vector<PathVertex>(lightBuf.begin(), lightBuf.begin() + nLight), connect);
}

int firstDivergentVertex(const std::vector<PathVertex>& a, const std::vector<PathVertex>& b, float tolerance) {
    const size_t n = std::min(a.size(), b.size());
    auto far = [tolerance](const Vec3& p, const Vec3& q) {
        const float scale = std::max(1.f, std::max(std::abs(p.x), std::max(std::abs(p.y), std::abs(p.z))));
        return !(glm::length(p - q) <= tolerance * scale);
    };
    for (size_t i = 0; i < n; ++i) {
        const PathVertex &u = a[i], &v = b[i];
        if (u.type != v.type || u.delta != v.delta || u.infinite != v.infinite || u.light != v.light) return int(i);
        if (u.type == VertexType::Surface && u.material != v.material) return int(i);
        if (far(u.p, v.p) || far(u.ng, v.ng)) return int(i);
    }
    return a.size() == b.size() ? -1 : int(n);
}

void applyCropWindow(Scene& scene, const std::string& crop) {
    if (crop.empty()) return;
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    char c1 = 0, c2 = 0, c3 = 0;
    std::stringstream ss(crop);
    std::string rest;
    if (!(ss >> x0 >> c1 >> y0 >> c2 >> x1 >> c3 >> y1) || c1 != ',' || c2 != ',' || c3 != ',' || (ss >> rest) || x0 < 0 ||
        y0 < 0 || x1 > scene.camera.width() || y1 > scene.camera.height() || x0 >= x1 || y0 >= y1)
        throw InputError("--crop: expected x0,y0,x1,y1 with 0 <= x0 < x1 <= width and 0 <= y0 < y1 <= height, got '" + crop + "'");
    scene.camera = scene.camera.withCrop(x0, y0, x1, y1);
}

}  // namespace bdptref
