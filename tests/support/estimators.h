// Rendering one scene with each of the estimators the agreement, wavefront and feature tests
// compare: path tracing, light tracing and BDPT (balance, power), megakernel or wavefront, and the
// checks those tests share (per-pixel agreement with its power check, bit-identity of two films).
#pragma once

#include "support/image_stats.h"

#include "bdptref/film.h"
#include "bdptref/integrator.h"
#include "bdptref/scene.h"
#include "bdptref/wavefront.h"

#include <array>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace bdptref::test {

struct EstimatorSetup {
    std::string integrator = "bdpt";  // "path", "lt" or "bdpt"
    MisHeuristic heuristic = MisHeuristic::Balance;
    int spp = 16, maxDepth = 5;
    int threads = 0;    // 0 = every core
    int tileSize = 0;   // 0 = the renderer's default
    uint32_t seed = 1;
    bool layers = false;      // record the per-(s,t) strategy layers
    bool depthLayers = false; // record the per-depth layers
    bool wavefront = false;   // render through the wavefront scheduler
    LightSamplerKind lightSampler = LightSamplerKind::Power;  // --light-sampler (tree: path and bdpt)
    WavefrontOptions wavefrontOptions;
};

IntegratorSettings integratorSettingsOf(const EstimatorSetup& s);
// "path", "lt", "bdpt-balance", "bdpt-power" or "bdpt-uniform".
std::string estimatorName(const EstimatorSetup& s);
// PT, LT, BDPT balance and BDPT power, in that order, with the other fields at their defaults.
std::vector<EstimatorSetup> everyEstimator();

// Renders with the settings of `s`. `afterPass` (optional) sees the film after every pass;
// `wavefrontReport` (optional, wavefront renders only) receives the scheduler's report.
Film renderEstimator(const Scene& scene, const EstimatorSetup& s,
                     const std::function<void(const Film&, int passesDone)>& afterPass = {}, GpuReport* wavefrontReport = nullptr);

// Independent renders of everyEstimator() (render i: spp[i] samples, seed seedBase + seedStep * i),
// each checked for non-finite samples, as (estimator name, film).
std::vector<std::pair<std::string, Film>> renderEveryEstimator(const Scene& scene, const std::array<int, 4>& spp,
                                                               uint32_t seedBase, uint32_t seedStep = 17);
// (name, momentsOf(film)) of each: the input of checkPairwiseAgreement.
std::vector<std::pair<std::string, MomentImage>> momentsOfEach(const std::vector<std::pair<std::string, Film>>& films);

// The same image with mean and standard error scaled by `factor` (a uniform relative error).
MomentImage scaledMoments(MomentImage img, double factor);

// Per-pixel agreement of every pair of independent renders (different seeds) with the rule of
// image_stats.h, plus its power: almost every pixel is tested, and a uniform relative error of
// `detectableBias` in either image of a pair makes the comparison fail.
// blackRegions: an image (e.g. a depth layer) with regions black in both: the t-tested share is
// of the pixels not exactly equal with zero variance, at least half of them; detectableBias 0
// skips the power check (a layer present in a few pixels only).
void checkPairwiseAgreement(const std::vector<std::pair<std::string, MomentImage>>& images, double detectableBias,
                            bool blackRegions = false);

// Pixels whose statistics differ at all (0 = bit-identical): beauty sums, squares and counts,
// the light (splat) image, and every strategy layer up to maxDepth and every depth layer (sums and
// squares) when the films have them.
struct FilmDifference {
    int beauty = 0, light = 0, layers = 0;
    int total() const { return beauty + light + layers; }
};
FilmDifference filmDifference(const Film& a, const Film& b, int maxDepth);

double meanLuminance(const Film& f);  // over the pixels of the beauty image
double lightImageTotal(const Film& f);  // luminance summed over the light (splat) image

// Renders `s` with the megakernel and with the wavefront scheduler (s.wavefrontOptions) and checks
// that every film statistic is bit-identical, and that the check is not vacuous (a non-black
// image, splats for LT and BDPT, every pixel sample counted by the scheduler).
void checkWavefrontIdentical(const Scene& scene, EstimatorSetup s, GpuReport* reportOut = nullptr);
// checkWavefrontIdentical for PT, LT, BDPT balance and BDPT power (strategy and depth layers on
// for all: the path tracer's are its emitter hits s = 0 and next events s = 1).
void checkWavefrontIdenticalEveryEstimator(const Scene& scene, const EstimatorSetup& base);

}  // namespace bdptref::test
