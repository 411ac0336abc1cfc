// Operations on PathVertex shared by subpath generation, connection, the production MIS walk and
// the wavefront stages: the BSDF at a vertex, densities between vertices and their conversion to
// area measure. Formulas: docs/mis.md ("Vertex densities").
#pragma once

#include "bdptref/bdpt.h"
#include "bdptref/bsdf.h"
#include "bdptref/path_vertex.h"
#include "bdptref/scene.h"

#include <cmath>
#include <vector>

namespace bdptref {

// The BSDF of a surface vertex. The subpath code builds it once per vertex, when the vertex is
// written (walkAddVertex), into a side array next to the PathVertex records (PathVertex itself
// holds no pointers: docs/contracts.md, contract 1); every later density, f and connectability question about
// the vertex reads that copy. Built from the same inputs, it has the same bits as a fresh one.
Bsdf vertexBsdf(const Scene& scene, const PathVertex& v);
// The SubpathBsdfs that evaluateConnection and misWeight read (the entries of the two connection
// endpoints, lightPath[s - 1] and cameraPath[t - 1], when they are surfaces): the caller's side
// arrays, or, for callers without them (tests, the trace tool), those two entries built here.
// The hot path allocates nothing (a std::optional<Bsdf> here used to cost a 92-byte clear per call).
class EndpointBsdfs {
public:
    EndpointBsdfs(const Scene& scene, const PathVertex* lightPath, int s, const PathVertex* cameraPath, int t,
                  const SubpathBsdfs& given)
        : view_(given) {
        if (!view_.light || !view_.camera) build(scene, lightPath, s, cameraPath, t);
    }
    const SubpathBsdfs& get() const { return view_; }

private:
    void build(const Scene& scene, const PathVertex* lightPath, int s, const PathVertex* cameraPath, int t);
    std::vector<Bsdf> light_, camera_;
    SubpathBsdfs view_;
};
const Light& vertexLight(const Scene& scene, const PathVertex& v);

// Unit direction from `from` towards `to` (for an infinite-light `to`, its stored direction); the
// zero vector when the two coincide (or are not finite), never NaN.
// Inline: ~200 000 calls per 4 096 BDPT samples (the MIS densities), where the call was a fifth of the cost.
inline Vec3 directionTo(const PathVertex& from, const PathVertex& to) {
    if (to.infinite) return to.ng;
    if (from.infinite) return -from.ng;
    // Coincident vertices (or a difference too small to square in float) have no direction:
    // normalize would divide 0 by 0 and hand a NaN on. The BSDFs and lights give the zero vector
    // value and density 0 (docs/hard-cases.md, "NaN-safe lookups").
    const Vec3 d = to.p - from.p;
    const float len2 = glm::dot(d, d);
    if (!(len2 > 0.f) || !std::isfinite(len2)) return Vec3(0.f);
    return glm::normalize(d);
}

// Solid-angle density at `from` of choosing the direction to `to`, converted to `to`'s measure:
// area (times |cos| at `to` over distance^2) for finite vertices, unchanged for infinite lights.
inline double convertDensity(double pdf, const PathVertex& from, const PathVertex& to) {
    if (to.infinite) return pdf;
    if (from.infinite) return pdf;  // parallel rays: the caller already has an area density
    const DVec3 d = DVec3(to.p) - DVec3(from.p);
    const double dist2 = glm::dot(d, d);
    if (!(dist2 > 0.0)) return 0.0;
    double out = pdf / dist2;
    if (to.isOnSurface()) out *= std::abs(glm::dot(DVec3(to.ng), d)) / std::sqrt(dist2);
    return out;
}

// Can a deterministic connection reach this vertex? (A BSDF with a non-delta lobe, a light that is
// not delta in direction, the pinhole.)
bool isConnectible(const Scene& scene, const PathVertex& v);
// The same with v's BSDF already built (only read for surface vertices).
bool isConnectible(const Scene& scene, const PathVertex& v, const Bsdf& bsdf);
// The light vertex of next-event sample `ls` on light `li` (strategy s = 1's fresh endpoint): type,
// light, position, normal (for infinite lights the direction towards the light), triangle and
// barycentrics (where an emissive texture is evaluated). beta and pdfFwd are the caller's.
void setLightSampleVertex(const Scene& scene, int li, const LightLiSample& ls, PathVertex* v);

// Is this the endpoint of a delta light (point, spot, directional)?
bool isDeltaLightVertex(const Scene& scene, const PathVertex& v);


// Density (in `next`'s measure) with which vertex v, reached from `prev` (null at an endpoint),
// samples `next`: BSDF sampling at surfaces, the camera's direction density at the camera, the
// light's emission density at a light (or at a surface lying on an area light).
double vertexPdf(const Scene& scene, const PathVertex& v, const PathVertex* prev, const PathVertex& next);
// The same with v's BSDF already built (vertexBsdf(scene, v); only read for surface vertices), for
// callers that ask one vertex for several densities.
double vertexPdf(const Scene& scene, const PathVertex& v, const Bsdf& bsdf, const PathVertex* prev, const PathVertex& next);
// Density of `next` when v is treated as a light emitting towards it (area: cos/pi, point:
// 1/4pi, ...; infinite lights: disk density times |cos| at `next`).
double pdfLightToVertex(const Scene& scene, const PathVertex& v, const PathVertex& next);
// The same before the conversion to `next`'s measure: the emission's solid-angle density towards
// `next`, or for an infinite light (whose rays are parallel) the disk density times |cos| at
// `next`, which is already an area density. pdfLightToVertex = convertDensity of it (finite lights).
double emissionDensityTowards(const Scene& scene, const PathVertex& v, const PathVertex& next);
// Density of choosing v as the origin of a light subpath (or as a next-event sample with the power
// sampler): pmf(light) * (1/area | 1 for delta positions and directions | the map's solid-angle
// density for the environment), pmf = the power sampler's.
double lightOriginDensity(const Scene& scene, const PathVertex& v);
// The same with the light chosen with probability `pmf` (lightOriginDensity: the power pmf).
double lightOriginDensity(const Scene& scene, const PathVertex& v, double pmf);
// Density of light vertex v as next-event estimation from `shading` samples it with sampler `kind`
// (the s = 1 strategy; docs/mis.md, "Light tree in BDPT"): lightChoicePmf at (shading.p,
// shading.ng) times v's position density. Power: lightOriginDensity(scene, v), the same bits.
double nextEventOriginDensity(const Scene& scene, LightSamplerKind kind, const PathVertex& shading, const PathVertex& v);
// pmf_kind(shading, light) / pmf_power(light): the factor by which the s' = 1 density of the light
// endpoint differs from the light subpath's origin density (0 when the power pmf is 0). Power: 1.
double nextEventPmfRatio(const Scene& scene, LightSamplerKind kind, const PathVertex& shading, int light);

// generateLightSubpath without its last step (fillSubpathDensities): for light tracing, whose
// single strategy per vertex is unweighted, so the densities and dVCM/dVC would go unread.
int traceLightSubpath(const Scene& scene, const PixelSampler& sampler, const BdptSettings& settings, PathVertex* path,
                      Bsdf* bsdfs);

// What the evaluation of one strategy (s, t) reads: shared by the evaluation itself
// (bdpt_connect.cpp, ConnectionEvaluation) and by trace's diagnosis of it (src/verify/trace.cpp,
// ConnectionDiagnosis), which mirrors its checks.
struct StrategyInputs {
    const Scene& scene;
    const PathVertex* lightPath;
    int s;
    const PathVertex* cameraPath;
    int t;
    const PixelSampler& sampler;
    LightSamplerKind lightSampler;  // s = 1's light choice
    bool weighted;  // BDPT: f at an endpoint with both MIS densities (connectionIncoming); light tracing: f alone
};

// The direction towards the previous vertex that a connection evaluates f at its endpoint v from:
// BDPT (`weighted`) the one its MIS densities use, between the stored positions (toPrev: one BSDF
// query answers f and both densities, docs/mis.md "One BSDF query per connection endpoint"); light
// tracing, whose subpaths carry no densities and no toPrev, the reverse of the ray that found v (wo).
inline const Vec3& connectionIncoming(const PathVertex& v, bool weighted) { return weighted ? v.toPrev : v.wo; }

// connectStrategy for light tracing: the unoccluded contribution with weight 1 and no MIS densities
// (evaluateConnectionUnweighted; the wavefront's finish stage writes the same Connection for light
// tracing). `sampledOut` receives the camera endpoint (t = 1).
bool connectUnweighted(const Scene& scene, const PathVertex* lightPath, int s, const PathVertex* cameraPath, int t,
                       const PixelSampler& sampler, Connection* out, const SubpathBsdfs& bsdfs,
                       PathVertex* sampledOut = nullptr);

// Radiance emitted by the endpoint v of a camera subpath towards its previous vertex (s = 0).
Rgb emittedTowardsPrevious(const Scene& scene, const PathVertex& v);

}  // namespace bdptref
