// The one header for users of the library (docs/library.md): the three jobs a GPU port's test
// suite has for bdptref, as thin functions over the headers below.
//   1. MIS weights of a path: given by explicit per-vertex densities, or by vertices
//      (positions, normals, materials, lights) against a scene, in the "bdptref-path" format of
//      `bdptref mis` (docs/trace-and-mis.md);
//   2. the calibrated comparison of two images, or of a set of renders, with a reference
//      (docs/compare.md);
//   3. bdptref EXR films (mean, variance, count, layers, metadata): read, write, and render a scene
//      into one in-process.
// Errors are InputError (bdptref/errors.h) with the messages the CLI prints.
//
// Versioning: BDPTREF_VERSION (bdptref/version.h) is the version of the headers compiled against,
// libraryVersion() that of the library linked. Semantic versioning; the shared library's SONAME
// changes with the major version (docs/library.md, "Versioning and ABI").
#pragma once

#include "bdptref/bdpt.h"
#include "bdptref/checkpoint.h"
#include "bdptref/errors.h"
#include "bdptref/exr_io.h"
#include "bdptref/film.h"
#include "bdptref/gltf_loader.h"
#include "bdptref/image_compare.h"
#include "bdptref/integrator.h"
#include "bdptref/path_io.h"
#include "bdptref/renderer.h"
#include "bdptref/scene.h"
#include "bdptref/trace.h"
#include "bdptref/version.h"

#include <cstdint>
#include <string>
#include <vector>

namespace bdptref {

// ---- version -------------------------------------------------------------------------------
struct LibraryVersion {
    int major = 0, minor = 0, patch = 0;
    std::string text;         // "2.0.0"
    std::string gitRevision;  // of the build ("unknown" outside a git checkout)
};
LibraryVersion libraryVersion();

// ---- scenes --------------------------------------------------------------------------------
// Loads a glTF scene the way `bdptref render/trace/mis` do with these options (image size, camera
// override, constant environment, crop window) and finalizes it. SceneReference (path_io.h) is
// what a path JSON records in "scene"; contentHash is ignored here.
Scene loadSceneFile(const SceneReference& setup);
Scene loadSceneFile(const std::string& file, int width = 256, int height = 256);
// Parses an "x,y,z" option value of three finite numbers (--env, --camera-pos, ...); throws
// InputError naming `option` otherwise. The CLI parses its options with the same function.
Vec3 parseVec3Option(const std::string& text, const std::string& option);

// ---- 1. MIS weights ------------------------------------------------------------------------
struct MisReport {
    std::string form;                         // "scene" or "densities"
    std::vector<StrategyVerdict> strategies;  // s = 0..n-1 (t = n - s): weight, valid, reason
    double sum = 0.0;                         // of the weights: 1 when any strategy is valid
    MisSettings mis;                          // the heuristic used
    int producedBy = -1;                      // s of the strategy recorded in the path (-1: none)
    std::string sceneFile;                    // scene form: the scene file the weights were computed in
    std::vector<std::string> warnings;        // what `bdptref mis` prints as warnings
    RecursiveMisPath recursive;               // scene form: dVCM/dVC per vertex and recursive weights (trace.h)
    std::vector<double> weights() const;
};
// Explicit per-vertex densities (trace.h, PathDensities; the densities form of `bdptref mis`).
MisReport misWeights(const PathDensities& path, const MisSettings& mis = {});
// Vertices against a scene (camera first, positions in the scene's RENDER space: see
// verticesInRenderSpace): the definition weights (misWeightsDefinition) with every verdict.
MisReport misWeights(const Scene& scene, const std::vector<PathVertex>& cameraFirstPath, const MisSettings& mis = {});

// What `bdptref mis PATH [--form F] [--scene S] [--width W --height H] [--mis M --mis-beta B]` does.
struct MisPathOptions {
    std::string form = "auto";  // auto | scene | densities
    std::string sceneFile;      // overrides the scene the path records
    int width = 0, height = 0;  // override the recorded image size (0: keep)
    std::string camera;         // overrides the recorded camera choice (--camera; "": keep)
    // The heuristic and the power exponent the path records (else balance, 2) can be overridden
    // separately, like --mis and --mis-beta.
    bool overrideHeuristic = false;
    MisHeuristic heuristic = MisHeuristic::Balance;
    bool overrideBeta = false;
    double beta = 2.0;
    // s = 1's light choice (--light-sampler): the path's recorded mis.lightSampler (else power)
    // unless overridden (docs/mis.md, "Light tree in BDPT").
    bool overrideLightSampler = false;
    LightSamplerKind lightSampler = LightSamplerKind::Power;
};
MisReport misWeightsOfPath(const PathDescription& path, const MisPathOptions& options = {});
// A "bdptref-path" JSON text (or a "bdptref-trace" with s, t picking a connection).
MisReport misWeightsOfPathJson(const std::string& jsonText, const MisPathOptions& options = {});
MisReport misWeightsOfPathFile(const std::string& file, const MisPathOptions& options = {}, int s = -1, int t = -1);

// Volume absorption along a path (KHR_materials_volume; docs/materials.md, "Volume absorption"),
// which `bdptref mis` prints beside the weights. The weights never depend on it: the
// transmittance is a factor of the path's contribution, the same for every strategy, and no
// sampling density includes it (docs/materials.md, "Why MIS is unchanged").
// One segment x_from - x_{from+1} of a camera-first scene path whose transmittance is not 1.
struct SegmentAbsorption {
    int from = 0;
    int material = -1;                // whose medium the segment lies in (segmentMedium)
    std::string materialName;
    Rgb sigma{0.f};                   // that material's absorption coefficient (Material::absorption)
    double length = 0.0;              // |x_{from+1} - x_from|; +inf towards an infinite light or an escape
    Rgb transmittance{1.f};           // exp(-sigma length) per channel: segmentTransmittance, the renderer's factor
    bool recorded = false;            // the path JSON gave vertex from+1 a "transmittance" (the segment that reached it)
    Rgb recordedTransmittance{1.f};   // that value
};
// The absorbed segments (transmittance not 1) of a camera-first path in the scene's render space
// (verticesInRenderSpace), in path order; `recorded` is false.
std::vector<SegmentAbsorption> pathAbsorption(const Scene& scene, const std::vector<PathVertex>& cameraFirstPath);
// misWeightsOfPathFile, and into `absorption` (when not null) the absorbed segments of the path
// with the transmittance the file recorded for them: empty in the densities form. Every reader of
// a path file warns when a recorded "transmittance" differs from the scene's.
MisReport misWeightsOfPathFile(const std::string& file, const MisPathOptions& options, int s, int t,
                               std::vector<SegmentAbsorption>* absorption);

// ---- 2. comparison -------------------------------------------------------------------------
// An image from arrays (row-major, width * height * 3 interleaved RGB): the pixel mean, and
// optionally the variance of the mean (s^2/n) and the sample count (width * height). Null: absent.
ExrImage imageFromArrays(int width, int height, const float* rgbMean, const float* rgbVarianceOfMean = nullptr,
                         const float* count = nullptr);
// Reads both files as `bdptref compare TEST REF` does and compares them: refuses (InputError) an
// 8-bit or display-encoded file and a test image without variance layers (give N >= 2 renders to
// combineRenders instead; docs/compare.md, "Inputs").
CompareResult compareImageFiles(const std::string& testFile, const std::string& referenceFile,
                                const CompareOptions& options = {});

// A set of independent renders (e.g. seeds or GPU runs) each compared with one reference; the set
// is consistent when every comparison has a verdict and the Sidak-combined p-value of the smallest
// global p, 1 - (1 - p_min)^k, is >= alpha.
struct RenderSetComparison {
    std::vector<CompareResult> results;  // one per render, in order
    double pSet = 1.0;
    int worst = -1;                      // index of the render with the smallest p
    bool hasVerdict = false;
    bool consistent = false;             // meaningful only with hasVerdict
    std::string sentence;
};
RenderSetComparison compareRenderSet(const std::vector<ExrImage>& renders, const ExrImage& reference,
                                     const CompareOptions& options = {});

// ---- 3. films ------------------------------------------------------------------------------
// readFilmExr (checkpoint.h) reads a film bit for bit. writeFilm writes one as `render` does, with
// bdptref:version and bdptref:gitRevision added to the metadata unless already there.
void writeFilm(const std::string& path, const Film& film, const ExrMetadata& metadata = {}, bool lightLayer = false);

struct RenderJob {
    std::string integrator = "bdpt";  // path | lt | bdpt
    IntegratorSettings settings;      // max depth, MIS heuristic, strategy layers
    int spp = 16;
    uint64_t firstSample = 0;
    uint32_t seed = 0;
    int threads = 0;  // 0: all cores
};
// Renders the scene into a new film of the camera's size (strategy layers when
// settings.recordStrategies, depth layers when settings.recordDepths). The same pixels as
// `bdptref render` with these settings.
Film renderScene(const Scene& scene, const RenderJob& job, RenderStats* stats = nullptr);
// The metadata `render` would record for the job (integrator, heuristic, spp, seed, scene, version).
ExrMetadata renderMetadata(const Scene& scene, const RenderJob& job, const Film& film);

}  // namespace bdptref
