// Definition MIS weights (docs/contracts.md, contract 3): the slow, obviously-right oracle that the production
// ratio walk (mis_production.cpp) is tested against. Derivation and conventions: docs/mis.md,
// "The definition implementation".
//
// For a full path x0 (pinhole) ... x_{n-1} (on a light), given camera-first, strategy s (t = n - s)
// samples x0..x_{t-1} with the camera subpath and x_{n-1}..x_t with the light subpath. Its density
//
//   p_s = prod_{i < t} pCam(i) * pLight_s(n - 1) * prod_{t <= k < n - 1} pLight(k)
//
// is built here factor by factor from the vertices' positions, normals, materials and lights with
// the scene's own sampling densities (Camera::pdfWe, Bsdf::pdf, pdfLe, pdfLi, LightSampler::pmf, and
// for s = 1 the pmf of MisSettings::lightSampler at x_{n-2}: docs/mis.md, "Light tree in BDPT");
// the stored pdfFwd/pdfRev are never read. Every factor is a density in the measure of the vertex it
// samples: area, or solid angle for an infinite-light vertex. The weights are
// w_s = p_s^b / sum_j p_j^b over the strategies j that can sample the path, b = mis.exponent(),
// evaluated from log p_s in long double so that products of hundreds of factors neither
// overflow nor underflow.
#include "bdptref/bdpt.h"
#include "bdptref/bsdf.h"
#include "bdptref/light.h"
#include "bdptref/scene.h"
#include "render/light_choice.h"

#include <cmath>
#include <limits>
#include <vector>

namespace bdptref {

namespace {

class DefinitionPath {
public:
    DefinitionPath(const Scene& scene, const std::vector<PathVertex>& x, LightSamplerKind nextEventSampler)
        : scene_(scene), x_(x), n_(int(x.size())), nextEventSampler_(nextEventSampler) {}

    // The light the path ends on (x_{n-1}), or null when x_{n-1} names no light.
    const Light* endLight() const {
        const int li = x_[size_t(n_ - 1)].light;
        return li >= 0 && size_t(li) < scene_.lights.size() ? &scene_.lights[size_t(li)] : nullptr;
    }

    // An interior vertex scattered by a delta lobe (a mirror, smooth glass). The endpoints x0 and
    // x_{n-1} never count: their delta-ness is that of the camera / the light, handled by the rules
    // in strategyIsValid().
    bool specular(int i) const { return i > 0 && i < n_ - 1 && x_[size_t(i)].delta; }

    // Density with which the CAMERA subpath samples x_i.
    double pCam(int i) const {
        if (i == 0) return 1.0;  // the pinhole: a delta position (pdfPos = 1); orthographic: a delta direction
        if (i == 1 && scene_.camera.isOrthographic())  // uniform film point projected onto x1 (docs/camera.md)
            return scene_.camera.pdfOrthographicVertex(x_[1].p, cosAt(1, DVec3(scene_.camera.forward())), x_[1].infinite);
        if (i == 1) {            // the camera's direction density, converted
            float pdfPos = 0.f, pdfDir = 0.f;
            scene_.camera.pdfWe(Vec3(direction(0, 1)), &pdfPos, &pdfDir);
            return toMeasureOf(1, 0, double(pdfDir));
        }
        // BSDF sampling at x_{i-1}, arriving from x_{i-2}. A delta lobe's density is a Dirac
        // distribution; its factor is 1 (docs/mis.md, "Delta vertices").
        if (specular(i - 1)) return 1.0;
        return toMeasureOf(i, i - 1, bsdfPdf(i - 1, i - 2, i));
    }

    // Density with which the LIGHT subpath samples x_k for k < n - 1 (x_{n-1}: pLightEndpoint()).
    double pLight(int k) const {
        const int e = n_ - 1;
        if (k == e - 1) {  // emission from the light towards x_{n-2}
            const Light& l = *endLight();
            float pdfPos = 0.f, pdfDir = 0.f;
            if (isInfinite(l)) {
                // Parallel rays through a disk of the scene's bounding radius: the disk's area
                // density projected onto x_{n-2} (no 1/d^2).
                pdfLe(l, scene_, x_[size_t(e)].p, -x_[size_t(e)].ng, -x_[size_t(e)].ng, &pdfPos, &pdfDir);
                return double(pdfPos) * cosAt(k, -infiniteDirection(e));
            }
            pdfLe(l, scene_, l.type == LightType::Area ? x_[size_t(e)].p : l.position, Vec3(direction(e, k)), l.normal, &pdfPos, &pdfDir);
            return toMeasureOf(k, e, double(pdfDir));
        }
        // BSDF sampling at x_{k+1}, arriving from x_{k+2} (light transport runs towards x0).
        if (specular(k + 1)) return 1.0;
        return toMeasureOf(k, k + 1, bsdfPdf(k + 1, k + 2, k));
    }

    // Density of the light endpoint x_{n-1}: chosen by the light subpath (s >= 2: the power
    // sampler's light choice times the emission's position density) or by next-event estimation
    // from x_{n-2} (s = 1: the next-event sampler's choice at x_{n-2} times pdfLi, converted).
    // Infinite lights: solid angle of the direction.
    double pLightEndpoint(bool nextEvent) const {
        const int e = n_ - 1;
        const Light& l = *endLight();
        const int li = x_[size_t(e)].light;
        const PathVertex& shading = x_[size_t(e - 1)];
        const double pmf = nextEvent ? double(lightChoicePmf(scene_, nextEventSampler_, shading.p, shading.ng, li))
                                     : double(scene_.lightSampler().pmf(li));
        switch (l.type) {
        case LightType::Point:
            return pmf;  // delta position: the same Dirac factor for every strategy s >= 1
        case LightType::Spot: {
            // Delta position too, but nothing is emitted (nor sampled) outside the outer cone.
            float pdfPos = 0.f, pdfDir = 0.f;
            pdfLe(l, scene_, l.position, Vec3(direction(e, e - 1)), l.normal, &pdfPos, &pdfDir);
            return pdfDir > 0.f ? pmf : 0.0;
        }
        case LightType::Directional:
            return pmf;  // delta direction: the same Dirac factor for every strategy s >= 1
        case LightType::Environment: {
            // The stored direction (ng, towards the map) exactly, as production evaluates it.
            if (nextEvent) return pmf * double(pdfLi(l, scene_, x_[size_t(e - 1)].p, x_[size_t(e)].p, x_[size_t(e)].ng));
            float pdfPos = 0.f, pdfDir = 0.f;
            pdfLe(l, scene_, x_[size_t(e)].p, -x_[size_t(e)].ng, -x_[size_t(e)].ng, &pdfPos, &pdfDir);
            return pmf * double(pdfDir);
        }
        case LightType::Area: {
            if (nextEvent)  // solid angle at x_{n-2} back to the area of the light
                return pmf * toMeasureOf(e, e - 1, double(pdfLi(l, x_[size_t(e - 1)].p, x_[size_t(e)].p, l.normal)));
            float pdfPos = 0.f, pdfDir = 0.f;
            pdfLe(l, scene_, x_[size_t(e)].p, Vec3(direction(e, e - 1)), l.normal, &pdfPos, &pdfDir);
            return pmf * double(pdfPos);
        }
        }
        return 0.0;
    }

    // Can strategy s (t = n - s) produce this path at all? (Densities aside.)
    bool strategyIsValid(int s) const {
        const int t = n_ - s;
        const Light* l = endLight();
        if (!l || t < 1) return false;
        if (s == 0) {
            // The camera subpath must hit the emitter: impossible for a delta position (point,
            // spot) or a delta direction (directional).
            return l->type == LightType::Area || l->type == LightType::Environment;
        }
        // Depth 0 (n = 2) is rendered by s = 0 alone: BDPT does not use (s, t) = (1, 1)
        // (docs/mis.md, "Which strategies count").
        if (n_ == 2) return false;
        // The connection joins x_{t-1} and x_t; neither may be a delta-scattering vertex. The
        // pinhole (t = 1) and the light endpoint (s = 1) are connectible.
        if (specular(t - 1)) return false;
        if (s >= 2 && specular(t)) return false;
        return true;
    }

private:
    // Unit direction at x_i towards x_j, in double.
    DVec3 direction(int i, int j) const {
        const PathVertex& a = x_[size_t(i)];
        const PathVertex& b = x_[size_t(j)];
        if (b.infinite) return glm::normalize(DVec3(b.ng));
        if (a.infinite) return -glm::normalize(DVec3(a.ng));
        return glm::normalize(DVec3(b.p) - DVec3(a.p));
    }
    // Direction from the scene towards an infinite-light vertex.
    DVec3 infiniteDirection(int i) const { return glm::normalize(DVec3(x_[size_t(i)].ng)); }

    // |cos| at x_k with direction w (x_k's geometric normal; 1 where the vertex has no surface).
    double cosAt(int k, const DVec3& w) const {
        const PathVertex& v = x_[size_t(k)];
        if (v.type == VertexType::Camera || v.infinite || v.ng == Vec3(0.f)) return 1.0;
        return std::abs(glm::dot(glm::normalize(DVec3(v.ng)), w));
    }

    // A solid-angle density at x_from of the direction towards x_to, in x_to's measure: area
    // (times |cos at x_to| / distance^2) or, for an infinite-light x_to, unchanged.
    double toMeasureOf(int to, int from, double pdfSolidAngle) const {
        if (x_[size_t(to)].infinite) return pdfSolidAngle;
        const DVec3 d = DVec3(x_[size_t(to)].p) - DVec3(x_[size_t(from)].p);
        const double dist2 = glm::dot(d, d);
        if (!(dist2 > 0.0)) return std::numeric_limits<double>::infinity();
        return pdfSolidAngle * cosAt(to, d / std::sqrt(dist2)) / dist2;
    }

    // Solid-angle density of BSDF sampling at x_at towards x_to, given arrival from x_from.
    double bsdfPdf(int at, int from, int to) const {
        const PathVertex& v = x_[size_t(at)];
        const Bsdf bsdf(scene_.materialParams(v.material, v.triangle, v.bary), v.ns, v.ng);
        return double(bsdf.pdf(Vec3(direction(at, from)), Vec3(direction(at, to))));
    }

    const Scene& scene_;
    const std::vector<PathVertex>& x_;
    int n_;
    LightSamplerKind nextEventSampler_;
};

}  // namespace

std::vector<double> misWeightsDefinition(const Scene& scene, const std::vector<PathVertex>& cameraFirstPath,
                                         const MisSettings& mis) {
    const int n = int(cameraFirstPath.size());
    std::vector<double> weights(size_t(std::max(n, 0)), 0.0);
    if (n < 2) return weights;
    const DefinitionPath path(scene, cameraFirstPath, mis.lightSampler);
    if (!path.endLight()) return weights;

    // Every factor once: camera-side densities of x0..x_{n-1}, light-side densities of
    // x1..x_{n-2}, and the two densities of the light endpoint.
    std::vector<double> cam(static_cast<size_t>(n), 0.0), light(static_cast<size_t>(n), 0.0);
    for (int i = 0; i < n; ++i) cam[size_t(i)] = path.pCam(i);
    for (int k = 1; k < n - 1; ++k) light[size_t(k)] = path.pLight(k);
    const double endpointEmitted = path.pLightEndpoint(false), endpointNextEvent = path.pLightEndpoint(true);

    // log p_s for the valid strategies, in long double (~19 digits; no overflow for any path
    // length). A zero (or NaN) factor means the strategy cannot produce the path.
    using LD = long double;
    const LD minusInf = -std::numeric_limits<LD>::infinity();
    auto logOf = [](double f) { return f > 0.0 ? std::log(LD(f)) : std::numeric_limits<LD>::quiet_NaN(); };
    std::vector<LD> logCam(static_cast<size_t>(n)), logLight(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) {
        logCam[size_t(i)] = logOf(cam[size_t(i)]);
        logLight[size_t(i)] = logOf(light[size_t(i)]);
    }
    const LD logEndpointEmitted = logOf(endpointEmitted), logEndpointNextEvent = logOf(endpointNextEvent);
    std::vector<LD> logP(static_cast<size_t>(n), minusInf);
    std::vector<bool> valid(static_cast<size_t>(n), false);
    for (int s = 0; s < n; ++s) {
        if (!path.strategyIsValid(s)) continue;
        const int t = n - s;
        LD logp = 0;
        for (int i = 0; i < t; ++i) logp += logCam[size_t(i)];  // x0 .. x_{t-1} by the camera subpath
        if (s >= 1) logp += s == 1 ? logEndpointNextEvent : logEndpointEmitted;  // x_{n-1}
        for (int k = t; k < n - 1; ++k) logp += logLight[size_t(k)];  // x_t .. x_{n-2} by the light subpath
        if (std::isnan(logp)) continue;
        valid[size_t(s)] = true;
        logP[size_t(s)] = logp;
    }

    // w_s = p_s^b / sum_j p_j^b = exp(b (log p_s - m)) / sum_j exp(b (log p_j - m)), m = max log p.
    LD m = minusInf;
    int count = 0, infinite = 0;
    for (int s = 0; s < n; ++s)
        if (valid[size_t(s)]) {
            ++count;
            if (std::isinf(logP[size_t(s)])) ++infinite;  // +inf: a coincident-vertex singularity
            else m = std::max(m, logP[size_t(s)]);
        }
    if (count == 0) return weights;
    const LD b = LD(mis.exponent());
    std::vector<LD> terms(size_t(n), 0);
    LD sum = 0;
    for (int s = 0; s < n; ++s) {
        if (!valid[size_t(s)]) continue;
        LD term;
        if (b == 0) term = 1;  // uniform: every valid strategy alike
        else if (infinite > 0) term = std::isinf(logP[size_t(s)]) ? 1 : 0;  // the limit as those densities grow
        else term = std::exp(b * (logP[size_t(s)] - m));
        terms[size_t(s)] = term;
        sum += term;
    }
    for (int s = 0; s < n; ++s) weights[size_t(s)] = double(terms[size_t(s)] / sum);
    return weights;
}

}  // namespace bdptref
