// Bidirectional path tracing with multiple importance sampling: subpath generation, the (s,t)
// connection strategies, and the MIS weights in two independent implementations (the production
// ratio walk used while rendering and the definition that builds every strategy's density from
// the vertices). Derivations and names: docs/mis.md.
//
// Vocabulary (Veach 1997; pbrt-v3): a full path of n vertices is produced by strategy (s, t),
// s + t = n, from the first s vertices of a light subpath and the first t vertices of a camera
// subpath. s = 0: the camera subpath hits an emitter (or escapes to the environment); s = 1: a
// fresh light sample is connected (next-event estimation); t = 1: a light-subpath vertex is
// connected to the camera and splatted to the pixel it lands on. The pinhole cannot be hit, so
// t >= 1. Path depth = n - 2 (docs/contracts.md, contract 5).
#pragma once

#include "bdptref/bsdf.h"
#include "bdptref/light_tree.h"
#include "bdptref/path_vertex.h"
#include "bdptref/rng.h"

#include <string>
#include <vector>

namespace bdptref {

class Scene;
struct SurfaceHit;

enum class MisHeuristic : uint8_t { Balance, Power, Uniform };

struct MisSettings {
    MisHeuristic heuristic = MisHeuristic::Balance;
    double beta = 2.0;  // exponent of the power heuristic (balance = 1, uniform = 0)
    // How the s = 1 strategy (next-event estimation from camera vertex x_{t-1}) chooses its light
    // (--light-sampler): by power, as the light subpaths do, or by the light tree's importance at
    // the shading point. Every density of s = 1 (and every MIS ratio that contains it) uses the
    // pmf of this sampler; light subpaths always start with the power sampler (docs/mis.md,
    // "Light tree in BDPT").
    LightSamplerKind lightSampler = LightSamplerKind::Power;
    double exponent() const {
        return heuristic == MisHeuristic::Balance ? 1.0 : heuristic == MisHeuristic::Power ? beta : 0.0;
    }
};
MisHeuristic parseMisHeuristic(const std::string& name);  // balance | power | uniform; InputError otherwise

struct BdptSettings {
    int maxDepth = 64;
    int rouletteStartDepth = 3;
    MisSettings mis;
    int maxCameraVertices() const { return maxDepth + 2; }
    int maxLightVertices() const { return maxDepth + 1; }
};

// Camera subpath through continuous raster position `raster`: path[0] is the camera vertex.
// Returns the number of vertices written (<= settings.maxCameraVertices()). A path that escapes
// ends with an infinite-light vertex when the scene has an environment.
// `bsdfs` (optional, as long as `path`): receives the BSDF of every surface vertex, built once,
// for the connections to reuse (SubpathBsdfs); null: every step builds the BSDFs it needs.
int generateCameraSubpath(const Scene& scene, const PixelSampler& sampler, Vec2 raster, const BdptSettings& settings,
                          PathVertex* path, Bsdf* bsdfs = nullptr);
// Light subpath: a light chosen by power, its emission sampled; path[0] is the light vertex.
int generateLightSubpath(const Scene& scene, const PixelSampler& sampler, const BdptSettings& settings,
                         PathVertex* path, Bsdf* bsdfs = nullptr);

// The BSDF side arrays of both subpaths of a sample, indexed like their PathVertex arrays (entries
// of camera and light vertices unused). PathVertex holds no pointers (docs/contracts.md, contract 1), so the
// BSDF each vertex needs for f, densities and connectability lives next to it, built once per
// vertex by walkAddVertex. A null array: the BSDFs are built where they are needed (same bits).
struct SubpathBsdfs {
    const Bsdf* light = nullptr;
    const Bsdf* camera = nullptr;
};

// ---- Stage-shaped pieces of subpath generation (one implementation, two schedulers) ----
// generateCameraSubpath / generateLightSubpath are begin + (extend, addVertex, scatter)* + densities.
// The megakernel runs that loop per sample; the wavefront mode (src/wavefront/) runs each step as
// a pass over a queue of walks. A walk is trivially copyable so it can live in a GPU-style buffer.
struct SubpathWalk {
    Ray ray{};            // the next ray to trace (valid while `active`)
    Rgb beta{0.f};        // throughput carried to the next vertex
    int32_t vertices = 0;  // vertices of the subpath written so far, the endpoint path[0] included
    int32_t maxVertices = 0;
    int32_t rouletteStart = 0;
    float rouletteScale = 1.f;  // 1 / max component of the walk's starting throughput (render/roulette.h)
    TransportMode mode = TransportMode::Radiance;
    RngStream stream = RngStream::Camera;
    bool active = false;  // `ray` must be traced and handed to walkAddVertex
};
static_assert(std::is_trivially_copyable_v<SubpathWalk>, "SubpathWalk lives in wavefront buffers");

// Write the endpoint path[0] (the pinhole / a sampled light point) and the first ray of the walk.
void beginCameraSubpath(const Scene& scene, Vec2 raster, const BdptSettings& settings, PathVertex* path,
                        SubpathWalk* walk);
void beginLightSubpath(const Scene& scene, const PixelSampler& sampler, const BdptSettings& settings, PathVertex* path,
                       SubpathWalk* walk);
// Shade, part 1: the result of tracing walk->ray (hit = null: it escaped) becomes vertex
// path[walk->vertices] (and, with `bsdfs`, its BSDF bsdfs[walk->vertices]). Returns true when the
// walk goes on to walkScatter.
bool walkAddVertex(const Scene& scene, const SurfaceHit* hit, SubpathWalk* walk, PathVertex* path,
                   Bsdf* bsdfs = nullptr);
// Shade, part 2: sample the BSDF at the last vertex (bsdfs' copy, or built when null), Russian
// roulette, next ray. Returns true (and leaves walk->active set) when the walk continues.
bool walkScatter(const Scene& scene, const PixelSampler& sampler, SubpathWalk* walk, PathVertex* path,
                 const Bsdf* bsdfs = nullptr);
// After the walk: pdfFwd/pdfRev of every vertex from the stored vertices (docs/mis.md), then
// their recursive MIS quantities dVCM/dVC for the heuristic `mis` (fillRecursiveMis).
void fillSubpathDensities(const Scene& scene, PathVertex* path, int n, const MisSettings& mis,
                          const Bsdf* bsdfs = nullptr);
// dVCM/dVC of every vertex of a subpath (camera: path[0] is the camera vertex; light: the light
// vertex) from its stored pdfFwd/pdfRev, delta flags and positions, for the heuristic `mis`
// (docs/mis.md, "The recursive form"). O(1) per vertex, in order, as the subpath grows.
void fillRecursiveMis(const Scene& scene, PathVertex* path, int n, const MisSettings& mis);

// A visibility query between two connection endpoints (Scene::visible / visibleToInfinity).
struct ShadowRay {
    Vec3 p0{0.f}, n0{0.f};
    Vec3 p1{0.f}, n1{0.f};     // p1: the other end, or the direction when `toInfinity`
    bool toInfinity = false;
    // Field by field: assigning a ShadowRay{...} temporary compiled to a 49-byte `rep movsb`, slow
    // for so few bytes (1-2% of a BDPT render: two per connection).
    void set(const Vec3& from, const Vec3& fromNormal, const Vec3& to, const Vec3& toNormal, bool infinity) {
        p0 = from;
        n0 = fromNormal;
        p1 = to;
        n1 = toNormal;
        toInfinity = infinity;
    }
};
bool traceShadowRay(const Scene& scene, const ShadowRay& ray);  // true when unoccluded
// traceShadowRay of n rays, traced together through Embree's stream API (the wavefront mode's
// shadow stages): unoccluded[i] = traceShadowRay(scene, *rays[i]).
void traceShadowRays(const Scene& scene, const ShadowRay* const* rays, uint32_t n, bool* unoccluded);

// The four densities of strategy (s, t) that depend on the connection itself (docs/mis.md, "The
// recursive form"); with the endpoints' dVCM/dVC they give the MIS weight in O(1). pt = the camera
// endpoint x_{t-1}, qs = the light endpoint (lightPath[s-1] or the fresh sample).
struct ConnectionDensities {
    double ptRev = 0.0;      // density of pt sampled from the light side (in pt's measure; s = 0: light origin)
    double ptPrevRev = 0.0;  // density at pt of the direction to x_{t-2}, arriving from qs (solid angle;
                             // s = 0: the emission density, disk density * |cos| for infinite lights)
    double qsRev = 0.0;      // density of qs sampled from the camera side (in qs's measure)
    double qsPrevRev = 0.0;  // density at qs of the direction to lightPath[s-2], arriving from pt (solid angle)
    // s = 0 only: the density of pt (the emitter the camera hit) as next-event estimation from
    // x_{t-2} samples it, the s' = 1 term; ptRev is then the light subpath's origin density (the
    // s' >= 2 terms). The same as ptRev with the power sampler (docs/mis.md, "Light tree in BDPT").
    double ptRevNextEvent = 0.0;
};
// The ConnectionDensities of strategy (s, t) (s + t >= 3) whose fresh endpoint is `sampled`, from
// the endpoints' BSDFs (src/render/mis_recursive.cpp) and the directions towards their previous
// vertices that fillSubpathDensities stored (PathVertex::toPrev).
// `mis.lightSampler` gives the s' = 1 densities (ptRevNextEvent; s = 1: ptRev).
ConnectionDensities connectionDensities(const Scene& scene, const PathVertex* lightPath, int s, const PathVertex* cameraPath,
                                        int t, const PathVertex& sampled, const MisSettings& mis,
                                        const SubpathBsdfs& bsdfs = {});

// The two BSDF densities at a surface endpoint v of a connection (solid angle), from the
// directions v.toPrev and w = directionTo(v, other endpoint): Bsdf::evaluateBothWays answers them
// with v's f (docs/mis.md, "One BSDF query per connection endpoint").
struct EndpointDensities {
    float towardsOther = 0.f;  // pdf(toPrev, w)
    float towardsPrev = 0.f;   // pdf(w, toPrev)
};
// connectionDensities with the surface endpoints' BSDF densities given (the ones evaluateConnection
// found with f; unused for an endpoint that is not a surface vertex of its subpath): the same bits.
ConnectionDensities connectionDensities(const Scene& scene, const PathVertex* lightPath, int s, const PathVertex* cameraPath,
                                        int t, const PathVertex& sampled, const MisSettings& mis,
                                        const EndpointDensities& cameraEnd, const EndpointDensities& lightEnd);

// Strategy (s, t) before visibility: the unoccluded contribution, the fresh endpoint (s == 1 or
// t == 1) and the shadow ray that decides it.
struct PendingConnection {
    Rgb unweighted{0.f};
    PathVertex sampled{};
    // The surface endpoints' densities, found with their f (BDPT; light tracing needs none).
    EndpointDensities cameraEnd{}, lightEnd{};
    ShadowRay shadow{};
    bool needsShadowRay = false;
    bool splat = false;
    Vec2 raster{0.f};
};
static_assert(std::is_trivially_copyable_v<PendingConnection>, "PendingConnection lives in wavefront buffers");

struct Connection {
    Rgb unweighted{0.f};   // the strategy's own estimate (before the MIS weight)
    double weight = 0.0;   // MIS weight (production implementation)
    bool splat = false;    // t == 1: goes to the light image at `raster`
    Vec2 raster{0.f};
};

// Which (s, t) pairs of a sample's subpaths the integrators evaluate (one rule for the megakernel,
// the wavefront and the trace). Loop: t = 1..(lightTracingOnly ? 1 : camera vertices),
// s = (lightTracingOnly ? 1 : 0)..lastLightStrategy(light vertices, t); then this verdict.
enum class StrategyStatus : uint8_t {
    Evaluated,
    NotAPath,       // s + t < 2: a single vertex
    DepthLimit,     // depth s + t - 2 > maxDepth
    DepthZeroRule,  // BDPT: depth 0 is strategy (0, 2) alone, (1, 1) is not evaluated (docs/mis.md)
};
// The last s to evaluate with t camera vertices. s = 1 with t >= 2 (next-event estimation) samples
// its own light point, so it is evaluated even when the light subpath is empty: a light subpath
// whose origin emits nothing (a black texel of an emissive texture) must not take next-event
// estimation away from the camera subpath, or BDPT loses that light's contribution wherever the
// light subpaths happened to start on black.
inline int lastLightStrategy(int lightVertices, int t) { return t >= 2 && lightVertices < 1 ? 1 : lightVertices; }
inline StrategyStatus strategyStatus(int s, int t, int maxDepth, bool lightTracingOnly) {
    const int depth = s + t - 2;
    if (depth < 0) return StrategyStatus::NotAPath;
    if (depth > maxDepth) return StrategyStatus::DepthLimit;
    if (s == 1 && t == 1 && !lightTracingOnly) return StrategyStatus::DepthZeroRule;
    return StrategyStatus::Evaluated;
}

// Evaluates strategy (s, t) of one pixel sample. Returns false when it contributes nothing
// (occluded, zero BSDF, delta endpoints, ...). `sampled` receives the fresh endpoint of s == 1
// (light sample) or t == 1 (camera) connections.
bool connectStrategy(const Scene& scene, const PathVertex* lightPath, int s, const PathVertex* cameraPath, int t,
                     const PixelSampler& sampler, const BdptSettings& settings, Connection* out,
                     PathVertex* sampled = nullptr, const SubpathBsdfs& bsdfs = {});

// connectStrategy = evaluateConnection + (traceShadowRay) + finishConnection.
// evaluateConnection returns false when the strategy contributes nothing even if unoccluded.
// `lightSampler` chooses the light of s = 1: pass the MisSettings::lightSampler of the weights that
// follow (the fresh sample's pdfFwd is that sampler's density).
bool evaluateConnection(const Scene& scene, const PathVertex* lightPath, int s, const PathVertex* cameraPath, int t,
                        const PixelSampler& sampler, PendingConnection* out, LightSamplerKind lightSampler,
                        const SubpathBsdfs& bsdfs = {});
// evaluateConnection for light tracing (t = 1, every weight 1): f at the light endpoint from
// PathVertex::wo and no densities (light tracing's subpaths carry none: no toPrev either).
bool evaluateConnectionUnweighted(const Scene& scene, const PathVertex* lightPath, int s, const PathVertex* cameraPath,
                                  int t, const PixelSampler& sampler, PendingConnection* out, const SubpathBsdfs& bsdfs = {});
// After the shadow ray found the connection unoccluded: the MIS weight, from the endpoints'
// densities that evaluateConnection found with their f (PendingConnection::cameraEnd / lightEnd).
void finishConnection(const Scene& scene, const PathVertex* lightPath, int s, const PathVertex* cameraPath, int t,
                      const PendingConnection& pending, const BdptSettings& settings, Connection* out);

// Production MIS weight of strategy (s, t), the recursive form (docs/mis.md): O(1) from the
// endpoints' dVCM/dVC (filled for the same `mis` by fillSubpathDensities / fillRecursiveMis) and
// the connection's densities. `sampled` is the fresh endpoint for s == 1 or t == 1.
double misWeightRecursive(const Scene& scene, const PathVertex* lightPath, int s, const PathVertex* cameraPath, int t,
                          const PathVertex& sampled, const ConnectionDensities& densities, const MisSettings& mis);

// Test oracle: the pdf-ratio walk over both subpaths in double, delta vertices skipped (pbrt-v3's
// remap0), ratios raised to the heuristic's exponent; O(s + t) and re-evaluates the densities.
// `sampled` is the fresh endpoint for s == 1 or t == 1 (ignored otherwise).
double misWeight(const Scene& scene, const PathVertex* lightPath, int s, const PathVertex* cameraPath, int t,
                 const PathVertex& sampled, const MisSettings& mis, const SubpathBsdfs& bsdfs = {});

// Definition MIS weights of a full path given camera-first (x0 = camera vertex, ..., x_{n-1} = the
// vertex on the light). Computes, from positions, normals, materials and lights alone (not from
// the stored pdfFwd/pdfRev), the density p_s of every strategy s = 0..n-1 (t = n - s) and returns
// w_s = p_s^b / sum_j p_j^b over the strategies that can sample the path (0 for those that cannot:
// a connection at a delta vertex, s = 0 on a non-emitter, ...). The `delta` flags of the vertices
// are part of the path's description (which lobe scattered it).
std::vector<double> misWeightsDefinition(const Scene& scene, const std::vector<PathVertex>& cameraFirstPath,
                                         const MisSettings& mis);

}  // namespace bdptref
