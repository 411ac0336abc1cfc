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
// t >= 1. Path depth = n - 2 (DESIGN contract 5).
#pragma once

#include "bdptref/path_vertex.h"
#include "bdptref/rng.h"

#include <string>
#include <vector>

namespace bdptref {

class Scene;

enum class MisHeuristic : uint8_t { Balance, Power, Uniform };

struct MisSettings {
    MisHeuristic heuristic = MisHeuristic::Balance;
    double beta = 2.0;  // exponent of the power heuristic (balance = 1, uniform = 0)
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
int generateCameraSubpath(const Scene& scene, const PixelSampler& sampler, Vec2 raster, const BdptSettings& settings,
                          PathVertex* path);
// Light subpath: a light chosen by power, its emission sampled; path[0] is the light vertex.
int generateLightSubpath(const Scene& scene, const PixelSampler& sampler, const BdptSettings& settings,
                         PathVertex* path);

struct Connection {
    Rgb unweighted{0.f};   // the strategy's own estimate (before the MIS weight)
    double weight = 0.0;   // MIS weight (production implementation)
    bool splat = false;    // t == 1: goes to the light image at `raster`
    Vec2 raster{0.f};
};

// Evaluates strategy (s, t) of one pixel sample. Returns false when it contributes nothing
// (occluded, zero BSDF, delta endpoints, ...). `sampled` receives the fresh endpoint of s == 1
// (light sample) or t == 1 (camera) connections.
bool connectStrategy(const Scene& scene, const PathVertex* lightPath, int s, const PathVertex* cameraPath, int t,
                     const PixelSampler& sampler, const BdptSettings& settings, Connection* out,
                     PathVertex* sampled = nullptr);

// Production MIS weight of strategy (s, t): pdf-ratio walk over both subpaths in double, delta
// vertices skipped (pbrt-v3's remap0), ratios raised to the heuristic's exponent.
// `sampled` is the fresh endpoint for s == 1 or t == 1 (ignored otherwise).
double misWeight(const Scene& scene, const PathVertex* lightPath, int s, const PathVertex* cameraPath, int t,
                 const PathVertex& sampled, const MisSettings& mis);

// Definition MIS weights of a full path given camera-first (x0 = camera vertex, ..., x_{n-1} = the
// vertex on the light). Computes, from positions, normals, materials and lights alone (not from
// the stored pdfFwd/pdfRev), the density p_s of every strategy s = 0..n-1 (t = n - s) and returns
// w_s = p_s^b / sum_j p_j^b over the strategies that can sample the path (0 for those that cannot:
// a connection at a delta vertex, s = 0 on a non-emitter, ...). The `delta` flags of the vertices
// are part of the path's description (which lobe scattered it).
std::vector<double> misWeightsDefinition(const Scene& scene, const std::vector<PathVertex>& cameraFirstPath,
                                         const MisSettings& mis);

}  // namespace bdptref
