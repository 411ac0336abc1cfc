// Path dump of one pixel sample and MIS weights of a given path: the tools that find "the first
// wrong vertex" of a GPU port (docs/trace-and-mis.md, docs/validating-a-gpu-port.md).
//
// traceSample() replays exactly the BDPT pixel sample the renderer computes for (seed, pixel,
// sample index): the same PixelSampler, generateCameraSubpath / generateLightSubpath and the same
// connectStrategy loop as the BDPT integrator (src/render/bdpt_integrator.cpp), and records every
// vertex and every (s, t) connection: its unweighted contribution, production MIS weight, the
// definition weights of all strategies of the full path, and why a connection contributed nothing.
// Its camera-side total and splats are bit-identical to what the integrator adds to the film.
//
// misWeightsFromDensities() is the MIS weight formula of docs/mis.md ("The density of a strategy")
// on explicit per-vertex densities, for ports that have their own scene representation.
#pragma once

#include "bdptref/bdpt.h"
#include "bdptref/integrator.h"
#include "bdptref/path_vertex.h"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace bdptref {

class Scene;
struct WavefrontOptions;

// ---------------------------------------------------------------------------------------------
// MIS weights from explicit densities
// ---------------------------------------------------------------------------------------------

// The densities of one vertex x_i of a full path x_0 (the pinhole) ... x_{n-1} (on a light), in
// the measure of x_i (area; solid angle for an infinite-light vertex), docs/mis.md notation:
struct VertexDensities {
    double camera = 0.0;  // p->(x_i): density of x_i when the CAMERA subpath samples it (x_0: 1)
    double light = 0.0;   // p<-(x_i): density of x_i when the LIGHT subpath samples it; for x_{n-1}
                          // the light subpath's origin density (pmf * pdfPos, used by s >= 2);
                          // unused for x_0
    bool delta = false;   // interior vertex scattered through a delta lobe (mirror, smooth glass);
                          // ignored at the endpoints. The densities sampled THROUGH a delta vertex
                          // (camera of x_{i+1}, light of x_{i-1}) are Dirac factors: the formula
                          // uses 1 whatever is stored there (pbrt's remap0; docs/mis.md).
};

struct PathDensities {
    std::vector<VertexDensities> vertices;  // x_0 .. x_{n-1}, camera first
    double lightNextEvent = 0.0;  // p<-_1(x_{n-1}): density of the light endpoint when next-event
                                  // estimation from x_{n-2} samples it (pmf * pdfLi, in x_{n-1}'s measure)
    bool deltaLight = false;      // x_{n-1} is a point, spot or directional light: s = 0 cannot hit it
};

// Per-strategy verdict for one full path.
struct StrategyVerdict {
    int s = 0, t = 0;
    bool valid = false;      // the strategy can sample this path (non-zero weight possible)
    double weight = 0.0;     // w_s
    double logDensity = 0.0; // natural log of p_s (densities form only; -inf when invalid)
    std::string reason;      // why it cannot sample the path (empty when valid)
};

// w_s = p_s^b / sum_j p_j^b over the valid strategies s = 0..n-1 (t = n - s), with
// p_s = prod_{i<t} camera(x_i) * [s == 1 ? lightNextEvent : s >= 2 ? light(x_{n-1}) : -] *
//       prod_{t<=k<n-1} light(x_k),
// b = mis.exponent(). Validity rules (docs/mis.md, "Which strategies count"): s = 0 needs a
// hittable light (!deltaLight); depth 0 (n = 2) is s = 0 alone; a connection x_{t-1}--x_t may not
// touch a delta vertex; a zero (or NaN) factor removes the strategy. Evaluated in log space in
// long double (no overflow for any path length). Throws InputError on a path of < 2 vertices or
// a negative density.
std::vector<double> misWeightsFromDensities(const PathDensities& path, const MisSettings& mis);
// The same with the reason of every invalid strategy and log p_s.
std::vector<StrategyVerdict> analyseMisDensities(const PathDensities& path, const MisSettings& mis);

// The densities of a scene path (camera first; as misWeightsDefinition takes it), evaluated with
// the vertex density functions the production ratio walk uses (render/bdpt_vertex.h), not with
// the definition's code: a second, independent evaluation of the same numbers (they agree with
// the definition within float32 rounding). Throws InputError when the path does not reference
// valid materials/lights or does not end on a light.
// `nextEventSampler`: the light choice of s = 1 in pdfNextEvent (MisSettings::lightSampler; the tree
// asks its pmf at x_{n-2}: docs/mis.md, "Light tree in BDPT").
PathDensities pathDensitiesFromScene(const Scene& scene, const std::vector<PathVertex>& cameraFirstPath,
                                     LightSamplerKind nextEventSampler);

// The recursive MIS quantities (docs/mis.md, "The recursive form") of a full scene path, for ports
// that compute the weights that way: vertex x_i as the last vertex of the camera subpath
// x_0..x_i and as the last vertex of the light subpath x_{n-1}..x_i (densities from the
// positions, fillSubpathDensities), and the weight misWeightRecursive gives every strategy that
// can sample the path (0 for those that cannot: analyseMisScene says why).
struct RecursiveMisVertex {
    double cameraDVCM = 0.0, cameraDVC = 0.0;  // x_i as camera-subpath vertex i
    double lightDVCM = 0.0, lightDVC = 0.0;    // x_i as light-subpath vertex n-1-i
};
struct RecursiveMisPath {
    std::vector<RecursiveMisVertex> vertices;  // x_0 .. x_{n-1}
    std::vector<double> weights;               // s = 0 .. n-1
};
RecursiveMisPath recursiveMisOfScenePath(const Scene& scene, const std::vector<PathVertex>& cameraFirstPath,
                                         const MisSettings& mis);

// Why each strategy cannot sample a scene path (empty string: it can, as far as the structural
// rules go), for the scene form of `bdptref mis`; combine with misWeightsDefinition for the weights.
std::vector<StrategyVerdict> analyseMisScene(const Scene& scene, const std::vector<PathVertex>& cameraFirstPath,
                                             const MisSettings& mis);

// Checks that a scene path can be handed to misWeightsDefinition (x_0 is the camera, indices in
// range, x_{n-1} on a light). Throws InputError naming the vertex otherwise.
void validateScenePath(const Scene& scene, const std::vector<PathVertex>& cameraFirstPath);

// The full path of strategy (s, t), camera first: cameraPath[0..t-1], then lightPath[s-1..0], with
// the fresh endpoint `sampled` replacing camera[0] (t == 1) or else light[0] (s == 1). The connection
// endpoints x_{t-1}, x_t lose their delta flag (the connection evaluates their non-delta lobes;
// docs/mis.md rule 4) - exactly how tests/unit/test_mis.cpp assembles paths.
std::vector<PathVertex> assembleFullPath(const PathVertex* cameraPath, int t, const PathVertex* lightPath, int s,
                                         const PathVertex& sampled);

// ---------------------------------------------------------------------------------------------
// Replay of one pixel sample
// ---------------------------------------------------------------------------------------------

struct TraceSettings {
    std::string integrator = "bdpt";  // "bdpt" (every (s, t), MIS-weighted) or "lt" (t = 1 only, weight 1)
    uint32_t seed = 0;
    BdptSettings bdpt;  // maxDepth, rouletteStartDepth, MIS heuristic: as IntegratorSettings
    bool fullPaths = true;  // record the full path (+ densities, definition weights) of contributions
};

// What happened to one (s, t) connection.
enum class ConnectionStatus : uint8_t {
    Contributed,       // connectStrategy returned a non-zero contribution
    DepthLimit,        // s + t - 2 > maxDepth: not evaluated
    DepthZeroRule,     // (s, t) = (1, 1): depth 0 is strategy (0, 2) alone
    NotOnEmitter,      // s = 0: x_{t-1} is not on a light, or emits nothing towards x_{t-2}
    DeltaVertex,       // a connection endpoint has only delta lobes, or is a delta-direction light
    NotConnectible,    // a connection endpoint is not a surface (an escaped ray, an infinite light for t = 1)
    OutsideImage,      // t = 1: the light vertex projects outside the image / crop window
    LightSampleFailed, // s = 1: the light sample has no density or no radiance
    ZeroContribution,  // BSDF, emission or throughput is zero for this connection
    ZeroGeometry,      // coincident endpoints, or a cosine of zero at an endpoint
    Occluded,          // the shadow ray is blocked
    NonFinite,         // the contribution is not finite (never reaches the film)
    Unexplained,       // connectStrategy returned false for a reason the diagnosis did not find
};
const char* connectionStatusName(ConnectionStatus s);  // "contributed", "occluded", ...

struct TracedConnection {
    int s = 0, t = 0, depth = 0;
    ConnectionStatus status = ConnectionStatus::Unexplained;
    std::string reason;        // human-readable; empty when contributed
    Rgb unweighted{0.f};       // Connection::unweighted
    double weight = 0.0;       // production MIS weight (Connection::weight)
    Rgb weighted{0.f};         // unweighted * float(weight): what the integrator adds
    bool splat = false;        // t == 1
    Vec2 raster{0.f};          // splat position (full-image raster)
    bool hasSampled = false;   // s == 1 or t == 1 connection that produced a fresh endpoint
    PathVertex sampled{};
    // Contributions only (with TraceSettings::fullPaths):
    std::vector<PathVertex> path;            // assembleFullPath(...)
    PathDensities densities;                 // pathDensitiesFromScene(path)
    std::vector<double> definitionWeights;   // misWeightsDefinition(path), all strategies s = 0..n-1
    std::vector<StrategyVerdict> strategies; // verdicts (valid / why not) of every strategy of the path
};

// Random numbers of one subpath vertex (docs/rng.md), for the port to compare its own draws.
struct VertexRandom {
    uint32_t bounce = 0;         // vertex reached after `bounce` scattering events
    uint32_t dimensionBase = 0;  // dim::vertex(bounce, 0)
    float bsdfLobe = 0.f;
    Vec2 bsdfDirection{0.f};
    float roulette = 0.f;
    float neeLight = 0.f;        // camera stream only
    Vec2 neePosition{0.f};       // camera stream only
};

// One connection-queue entry of the wavefront mode, stage by stage (traceSampleWavefront).
struct WavefrontQueueRecord {
    uint64_t slot = 0;         // connection slot (the scan's order: path, t, s)
    int s = 0, t = 0;
    bool connected = false;    // connect: evaluateConnection found a contribution (before visibility)
    Rgb unoccluded{0.f};       // connect: PendingConnection::unweighted (when connected)
    bool shadowRay = false;    // connect: PendingConnection::needsShadowRay (when connected)
    bool visible = false;      // shadow: the entry reached finish (unoccluded, or no shadow ray needed)
    double weight = 0.0;       // finish: Connection::weight (when visible; 1 for lt)
    Rgb weighted{0.f};         // accumulate: the value added to L or splatted (when visible)
};

struct TracedSample {
    std::string mode = "megakernel";  // "megakernel" (traceSample) or "wavefront" (traceSampleWavefront)
    int x = 0, y = 0;
    uint64_t sample = 0;
    uint32_t pixelIndex = 0;  // RNG key word 0: y * width + x of the full image
    TraceSettings settings;
    Vec2 raster{0.f};         // (x, y) + the film jitter (camera stream, dimension 0)
    float lightChoice = 0.f;  // light stream dimension 0
    Vec2 emitPosition{0.f}, emitDirection{0.f};  // light stream dimensions 1, 2
    std::vector<PathVertex> cameraPath, lightPath;
    std::vector<VertexRandom> cameraRandom, lightRandom;  // per vertex (index 0: unused)
    std::vector<TracedConnection> connections;  // integrator order: t = 1.., s = 0.. (depth < 0 omitted)
    Rgb L{0.f};                 // camera-side estimate: exactly SampleOutput::L of the integrator
    std::vector<Splat> splats;  // exactly SampleOutput::splats (t = 1 contributions, weighted)
    std::vector<WavefrontQueueRecord> connectionQueue;  // wavefront mode only, in slot order
};

// How one strategy (s, t) came out, as some scheduler computed it: false = no contribution;
// true = *out (unweighted, weight, splat, raster) and the fresh endpoint *sampled (s = 1, t = 1).
using StrategyOutcome = std::function<bool(int s, int t, Connection* out, PathVertex* sampled)>;

// The trace of one pixel sample whose two subpaths (densities filled in) and strategy outcomes
// were computed elsewhere: visits the integrator's (s, t) loop in its order, asks `outcome` for
// every strategy it evaluates, diagnoses those without a contribution, and sums L and the splats
// as the integrator does. traceSample = this with generate*Subpath and connectStrategy.
TracedSample traceFromSubpaths(const Scene& scene, const TraceSettings& settings, int x, int y, uint64_t sample,
                               std::vector<PathVertex> cameraPath, std::vector<PathVertex> lightPath,
                               const StrategyOutcome& outcome);

// Replays BDPT pixel sample `sample` of pixel (x, y) (full-image coordinates; inside the camera's
// crop window). Pure function of (scene, settings, x, y, sample). Sets FTZ/DAZ on the calling
// thread, as the renderer's threads do. Throws InputError on a pixel outside the window.
TracedSample traceSample(const Scene& scene, const TraceSettings& settings, int x, int y, uint64_t sample);

// The same pixel sample computed by the wavefront scheduler (src/wavefront/wavefront_trace.cpp):
// one pass restricted to this pixel; the subpaths are the PathVertex records the stages stored in
// the pool buffers, each strategy's outcome is its connection-queue entry (connect, shadow,
// finish), L and the splats are what the accumulate stage produced, and `connectionQueue` lists
// every entry stage by stage. Equal to traceSample field for field (tests/unit/test_trace_wavefront.cpp).
// `queues`: the pool and queue capacities (null: the defaults; the observer is the trace's own);
// small capacities force flushes and must not change the trace.
// Throws InputError as traceSample, std::logic_error when the stages disagree with the loop.
TracedSample traceSampleWavefront(const Scene& scene, const TraceSettings& settings, int x, int y, uint64_t sample,
                                  const WavefrontOptions* queues = nullptr);

// The first index at which two vertex sequences differ: type, delta/infinite flags, light or
// material index, or a position / normal farther apart than `tolerance` (relative to the scene
// scale the caller chooses). Returns -1 when they agree (and have the same length; otherwise the
// shorter length).
int firstDivergentVertex(const std::vector<PathVertex>& reference, const std::vector<PathVertex>& other,
                         float tolerance);

// Restricts the scene's camera to the window "x0,y0,x1,y1" (x1, y1 exclusive), exactly as
// `bdptref render --crop` does (the window changes We and the t = 1 densities: docs/mis.md).
// Empty: nothing. Throws InputError on a malformed or out-of-image window.
void applyCropWindow(Scene& scene, const std::string& crop);

}  // namespace bdptref
