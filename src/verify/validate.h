// `bdptref validate`: runs a user's renderer on the conformance suite (scenes/conformance/), compares
// each result with the suite's reference (beauty, and per-depth layers when both have them) and
// reports per scene what it exercises, the verdict, the bias and the first failing depth
// (docs/validate.md). The pieces: the suite manifest (validate_suite.cpp), the renderer's command
// template and its processes (validate_command.cpp), the budget's shares (validate_budget.cpp), the
// pilots, renders and comparisons (validate_run.cpp), the HTML and JSON report (validate_report.cpp).
#pragma once

#include "verify/validate_signatures.h"
#include "bdptref/exr_io.h"
#include "bdptref/image_compare.h"

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace bdptref {

// ---- the suite -----------------------------------------------------------------------------------

// What kind of estimator a renderer uses: a scene lists the kinds that can render it without
// missing paths (a path tracer cannot reach a point light through a mirror, a light tracer cannot
// see a mirror from a pinhole camera).
enum class PortEstimator { Path, Light, Bidirectional };
PortEstimator parsePortEstimator(const std::string& name);  // "path", "light", "bidirectional"
const char* portEstimatorName(PortEstimator e);

// The strategy shares a scene's `strategyShares` name (SuiteScene::strategyShares).
inline constexpr const char* kLightTracingShare = "lightTracing";
inline constexpr const char* kDeepestEmitterHitShare = "deepestEmitterHit";
inline constexpr const char* kDeepestLightTracingShare = "deepestLightTracing";
// The emitter share a scene's `emitterShares` names (SuiteScene::emitterShares).
inline constexpr const char* kDoubleSidedFromDepth1Share = "doubleSidedFromDepth1";

// The kinds of light a scene's `lightShares` name (docs/diagnosis.md, "Light shares"): emissive
// triangles, point and spot lights, directional lights, the environment.
enum class LightKind { Area, Punctual, Directional, Environment };
inline constexpr int kLightKindCount = 4;
const char* lightKindName(LightKind k);  // "area", "punctual", "directional", "environment"
std::optional<LightKind> parseLightKind(const std::string& name);

struct SuiteScene {
    std::string name;
    std::string scene;       // absolute path of the glTF
    std::string reference;   // absolute path of the reference EXR
    int maxDepth = 8;        // scattering events; the renderer must use the same
    std::string envMap;      // absolute path of an equirectangular HDR/EXR environment, or empty
    double envScale = 1.0;
    std::string envConstant;  // "r,g,b" of a constant environment, or empty
    std::vector<PortEstimator> estimators;  // who can render it (see above)
    std::vector<std::string> exercises;     // the terms of the estimator a wrong port gets wrong here
    std::vector<std::string> suspects;      // the usual bugs when this scene fails
    std::vector<std::string> terms;         // term catalogue ids it exercises (docs/diagnosis.md)
    double ior = 0;                         // the index of refraction of its glass, 0: none (diagnosis)
    // Each kind of light's share of the image (area, punctual, directional, environment; they sum
    // to 1), for scenes lit by two kinds or more: a term that scales one kind changes the image by
    // 1 - s (1 - f) (docs/diagnosis.md, "Light shares"; scenes/conformance/light_shares.py). Empty:
    // one kind of light.
    std::map<LightKind, double> lightShares;
    // BDPT's weighted strategy shares of the image (docs/diagnosis.md, "Strategy shares";
    // scenes/conformance/strategy_shares.py): "lightTracing" (every t = 1 strategy) and
    // "deepestEmitterHit" (s = 0 at the maximum depth), "deepestLightTracing" (t = 1 at the maximum
    // depth), and each strategy class's by its name (strategyClassName: "emitterHit", "nextEvent",
    // "connections"; "lightTracing" is kLightTracingShare), each in [0, 1]. Empty: not measured.
    std::map<std::string, double> strategyShares;
    // The share of the image that some emitters light after a bounce (docs/diagnosis.md, "Emitter
    // shares"; scenes/conformance/light_shares.py): "doubleSidedFromDepth1", the double-sided
    // emitters' light from depth 1 on (what a light tracer samples with their direction density),
    // in [0, 1]. Empty: the scene has no such emitter.
    std::map<std::string, double> emitterShares;
    // The classes of strategies whose unweighted layers sample every path of the scene, so that
    // each one's average estimates the reference's depth layers (docs/validate.md, "Strategy
    // classes"): a subset of strategyClassName's names. Empty: none compared.
    std::vector<std::string> strategyClasses;
    // Per estimator other than the reference's: a long bdptref render of that estimator (absolute
    // path), whose per-sample shape compare takes as the port's (CompareOptions::testShape;
    // docs/validate.md, "Estimator shapes"). Missing: the reference's shape only.
    std::map<PortEstimator, std::string> shapes;
    // The bdptref render options that define the image besides size, spp and seed
    // (--max-depth, --env-map, ...): the {options} placeholder.
    std::vector<std::string> renderOptions() const;
};

struct Suite {
    std::string path;       // the manifest
    int width = 64, height = 64;
    std::vector<SuiteScene> scenes;
    std::vector<BugSignature> signatures;  // the optional "signatures" file (docs/diagnosis.md)
};

// Reads a suite manifest (JSON, docs/validate.md "The suite file"); paths in it are relative to
// the manifest's folder. Throws InputError naming the file and the entry.
Suite loadSuite(const std::string& manifestPath);
// The shipped suite: $BDPTREF_SUITE, else PREFIX/share/bdptref/scenes/conformance/suite.json next
// to the binary, else the source tree this binary was built from. Throws InputError if none.
std::string defaultSuitePath(const std::string& executable);

// ---- the renderer's command ----------------------------------------------------------------------

// The values a renderer command's placeholders stand for (docs/validate.md, "What your renderer
// must do"). A template with {seeds} gets every render of a scene in one process: `seeds` lists
// them and `output` is a pattern holding {seed}, one file per seed (outputForSeed).
struct RenderRequest {
    const SuiteScene* scene = nullptr;
    std::string output;
    int spp = 1, width = 64, height = 64;
    uint32_t seed = 1;
    std::vector<uint32_t> seeds;
};
// Placeholders a command template may use, each as {name} or {name:text}: text with every % replaced
// by the value (%% a literal %), or nothing when the value is empty ({env_map:--envmap %}).
const std::vector<std::string>& commandPlaceholders();
// Throws InputError when the template uses an unknown {name}, is malformed (an unclosed or nested
// {, a {name:text} without %), lacks {scene}, {out} or {spp}, or has neither or both of {seed} and
// {seeds} (without a seed every render would be the same; without {spp} the budget cannot be kept).
void checkCommandTemplate(const std::string& command);
// True when the template holds {seeds}: one process renders all of a scene's seeds.
bool commandTakesSeedList(const std::string& command);
// The file a {seeds} renderer writes for `seed`: `pattern` with every {seed} replaced by it.
std::string outputForSeed(const std::string& pattern, uint32_t seed);
// The shell command for one process: every placeholder replaced by its value, shell-quoted
// ({options}: each option quoted, space-separated; {seeds}: decimal, comma-separated).
std::string expandCommand(const std::string& command, const RenderRequest& request);

struct ProcessResult {
    int exitCode = -1;     // the command's exit status (128 + N when killed by signal N)
    bool timedOut = false, interrupted = false;
    double wallSeconds = 0;
};
// Runs `shellCommand` with /bin/sh in its own process group, stdout and stderr to `logPath`;
// kills the group after `timeoutSeconds` or when `stop` becomes true.
ProcessResult runShellCommand(const std::string& shellCommand, const std::string& logPath, double timeoutSeconds,
                              const std::function<bool()>& stop);

// ---- running the suite ---------------------------------------------------------------------------

// Render k of a scene uses seed seedBase + kRenderSeedSpacing k: a renderer that seeds thread i
// with seed + i would make consecutive seeds share streams (docs/validate.md, "References").
inline constexpr uint32_t kRenderSeedSpacing = 1000;

struct ValidateOptions {
    std::string command;            // the renderer's command template
    PortEstimator estimator = PortEstimator::Bidirectional;
    double budgetSeconds = 60;      // of the renderer's wall time, all scenes and renders together
    int renders = 8;                // independent renders per scene (N >= 2: their spread is the noise; docs/validate.md)
    // With a budget: take fewer renders (down to 4) where the renderer's fixed cost per process
    // would eat more than half of an equal share (budget / scenes; rendersForBudget). False: exactly `renders`.
    bool adaptRenders = true;
    int spp = 0;                    // > 0: this many samples per render, no budget
    double timeoutSeconds = 3600;   // per render with a fixed --spp (with a budget: 10x its share)
    double alpha = 0.01;            // false-alarm rate of the whole suite
    uint32_t seedBase = 1;          // render k of a scene uses seed seedBase + kRenderSeedSpacing k
    std::vector<std::string> only;  // scene names (empty: all the port's estimator can render)
    std::string outDir;             // renders, logs, heatmaps, report.html, report.json
    bool keepRenders = true;
};

// One pilot render (one process): its samples per pixel and wall seconds.
struct PilotTiming {
    int spp = 1;
    double seconds = 0;
};

enum class SceneVerdict { Consistent, Inconsistent, NoVerdict, Failed, Skipped };
const char* sceneVerdictName(SceneVerdict v);  // "consistent", "INCONSISTENT", "no verdict", "renderer failed", "skipped"

struct LayerOutcome {
    std::string layer;     // "beauty" or "depth<d>"
    int depth = -1;        // d, or -1 for the beauty
    double p = 1;          // global p-value of compare
    bool hasVerdict = false, consistent = true;
    double relativeBias = 0, relativeBiasLow = 0, relativeBiasHigh = 0;  // mean(t - r) / mean(r), 95% CI
    // The plain ratio of the image means, (mean t - mean r) / mean r with its 95% interval from the
    // pixels' variances. relativeBias weighs the bias test's tiles by their noise, which is right
    // for a verdict but is not the image-mean ratio a factor on one kind of light predicts by its
    // light share (docs/diagnosis.md, "Light shares"). hasMeanBias: the reference's mean is not 0.
    bool hasMeanBias = false;
    double meanRelativeBias = 0, meanRelativeBiasLow = 0, meanRelativeBiasHigh = 0;
    uint64_t tested = 0, compared = 0, equal = 0;  // equal: noiseless pixels both sides agree on (black)
    std::string sentence;
};

struct SceneOutcome {
    const SuiteScene* scene = nullptr;
    SceneVerdict verdict = SceneVerdict::Skipped;
    std::string message;                // why (skipped, failed, no verdict)
    int spp = 0, renders = 0;
    double renderSeconds = 0;           // wall time of the renders (not the pilots)
    // With a budget (0 with --spp): what the pilots measured, the reference's median shape
    // (referenceShapeMedian), the spp per render a verdict needs and the scene's share.
    double fixedSeconds = 0, secondsPerSample = 0, referenceShape = 0, budgetShareSeconds = 0;
    int samplesNeeded = 0;
    std::vector<PilotTiming> pilots;    // with a budget: the pilot renders, in order
    double p = 1;                       // Sidak over the layers tested
    std::vector<LayerOutcome> layers;   // beauty first, then depth layers in order
    // A bidirectional port's unweighted strategy layers, averaged per class (emitter hit, next
    // event, light tracing, connections) and compared with the reference's depth layer:
    // "depth<d>.<class>", by class then depth (validate_strategy_classes.cpp).
    std::vector<LayerOutcome> strategyClassLayers;
    int firstFailingDepth = -1;
    std::string heatmap;                // PNG of the beauty's z-scores (file name in outDir)
    std::string testPreview, referencePreview;  // PNGs of the mean of the renders and of the reference
    std::string testShape;              // the suite's shape of the port's estimator that compare used, or empty
};

struct ValidateReport {
    std::string suitePath, command;
    ValidateOptions options;
    double alphaPerScene = 0;  // Sidak: the suite's alpha over the scenes tested
    // With a budget: the seconds the scenes' needs add up to (allocateSceneBudgets), and whether
    // the budget held them (false: some scenes may get no verdict; that many seconds would do).
    double budgetNeededSeconds = 0;
    bool budgetSufficient = true;
    std::vector<SceneOutcome> scenes;
    std::vector<BugSignature> signatures;  // the suite's, for the diagnosis
    double seconds = 0;        // wall time of the whole run
    bool interrupted = false;
    int exitCode = 0;          // 0 all consistent, 1 any inconsistent, 2 otherwise no verdict/failure
};

// A line of progress (to stderr by the CLI).
using ProgressFn = std::function<void(const std::string&)>;
ValidateReport runValidation(const Suite& suite, const ValidateOptions& options, const ProgressFn& progress,
                             const std::function<bool()>& stop);

// ---- sizing the renders to the budget (validate_budget.cpp; docs/validate.md, "Budget and samples")

// How many renders a scene's budget share affords: the largest N <= maxRenders whose fixed costs
// N * fixedSeconds take at most half of shareSeconds, but at least min(4, maxRenders) (below 4
// the spread has too few degrees of freedom).
int rendersForBudget(double shareSeconds, double fixedSeconds, int maxRenders);

// The median, over the reference's pixels with noise (count >= 2, some channel with mean > 0 and
// variance > 0), of its relative per-sample variance C = (n - 1) var / mean^2 as compare bounds
// the test by it (the larger of the pixel's and its neighbours' mean), in the pixel's least noisy
// channel (compare tests a pixel when one channel can be tested), each channel's C raised to the
// port's estimator shape where given (CompareOptions::testShape). 0 without count and variances.
double referenceShapeMedian(const ExrImage& reference, const std::array<std::vector<float>, 3>& testShape = {});

// The suite's shape of `estimator` for scene `sc` (SuiteScene::shapes, CompareOptions::testShape)
// for images of width x height; empty arrays when the suite has none. *path: its file, or empty.
std::array<std::vector<float>, 3> suiteEstimatorShape(const SuiteScene& sc, PortEstimator estimator, int width,
                                                      int height, std::string* path);

// The spp per render for which N renders give the median pixel safety times compare's
// minimum effective samples: ceil(safety * minEffectiveSamples * (1 + shapeMedian) / renders),
// at least 1. compare's bound is N S / (1 + C) (CompareOptions::samplesPerRender); a verdict needs
// a quarter of the noisy pixels tested, and at safety 2 every pixel up to C = 2 C_med + 1 is.
int samplesNeededPerRender(double shapeMedian, int renders, double minEffectiveSamples = 10.0, double safety = 2.0);

// The spp of the next pilot, 0 when the pilots are done: first 1, then 16, then 4 times the last,
// until a pilot takes longer than the first by at least max(the first's time, kPilotMinSampleSeconds)
// (its sample part then outweighs the jitter of the start-up), or kMaxPilotSpp is reached.
constexpr double kPilotMinSampleSeconds = 0.1;
constexpr int kMaxPilotSpp = 65536;
int nextPilotSpp(const std::vector<PilotTiming>& done);
// The cost line fixed + spp * perSample through the first pilot and the last (the farthest apart).
// A last pilot that never drew clear of the first (a renderer whose samples cost almost nothing)
// counts as a tenth of the first's time more, so that the per-sample cost is small, never 0.
struct PilotFit {
    double fixedSeconds = 0, secondsPerSample = 0;
};
PilotFit fitPilotCost(const std::vector<PilotTiming>& pilots);

// What a scene's test costs, from its pilot renders and its reference.
struct SceneCost {
    double fixedSeconds = 0;      // per render process
    double secondsPerSample = 0;  // per spp of one render
    int renders = 8;
    int samplesNeeded = 1;        // spp per render (samplesNeededPerRender)
    bool oneProcess = false;      // {seeds}: all renders in one process, the fixed cost paid once
    // The least spp per render worth rendering: the median pixel at the test's threshold (k = 1 in
    // samplesNeededPerRender). Fewer leave most pixels untested and the verdict lost, whatever the
    // budget; sppForShare never goes below it.
    int samplesFloor = 1;
    int processes() const { return oneProcess ? 1 : renders; }
    // processes * fixed + renders * samplesNeeded * secondsPerSample
    double neededSeconds() const;
};
struct BudgetShares {
    std::vector<double> seconds;  // per scene, in the order given; they sum to the budget
    double neededSeconds = 0;     // the needs together: a budget that affords every verdict
    bool needsFit = true;         // false: the needs exceed the budget, shares are proportional to them
};
// Shares the budget by water-filling: when the needs fit, each scene gets max(its need, L) with
// the common level L that makes the shares sum to the budget (cheap scenes share the rest equally);
// otherwise each gets its fixed cost (processes * fixedSeconds) plus the same fraction of its
// samples' cost, the fraction that makes the shares sum to the budget.
BudgetShares allocateSceneBudgets(const std::vector<SceneCost>& scenes, double budgetSeconds);
// The spp per render a share affords: floor((share - processes * fixed) / (N * secondsPerSample)),
// at least samplesFloor (and 1).
int sppForShare(double shareSeconds, const SceneCost& cost);

// The comparisons of one scene's renders with its reference (beauty and common depth layers), at
// level `alpha`; fills outcome.layers, p, verdict, firstFailingDepth. samplesPerRender: the spp
// each render was asked for (CompareOptions::samplesPerRender; 0: unknown). Exposed for tests.
// testShape: the port's estimator shape for the beauty (CompareOptions::testShape; empty: unknown).
void compareSceneRenders(const std::vector<ExrImage>& renders, const ExrImage& reference, double alpha,
                         SceneOutcome& outcome, CompareResult* beauty = nullptr, int samplesPerRender = 0,
                         const std::array<std::vector<float>, 3>& testShape = {},
                         PortEstimator estimator = PortEstimator::Bidirectional);

// One compared layer's outcome (relative bias and its 95% interval from compare's tile test).
LayerOutcome layerOutcome(const CompareResult& r, const std::string& layer, int depth);
// Sidak: the level each of k tests gets so that the family has level alpha.
double sidakLevel(double alpha, int k);

// ---- strategy classes (validate_strategy_classes.cpp; docs/validate.md, "Strategy classes") ------

// The four kinds of BDPT strategy (s light vertices, t camera vertices): each kind reads other
// terms of the estimator (next-event estimation reads the light's sampling density, light tracing
// the camera's importance, connections both subpaths' BSDFs at their ends).
enum class StrategyClass { EmitterHit, NextEvent, LightTracing, Connections };
inline constexpr int kStrategyClassCount = 4;
const char* strategyClassName(StrategyClass c);  // "emitterHit", "nextEvent", "lightTracing", "connections"
std::optional<StrategyClass> parseStrategyClass(const std::string& name);
// t = 1: light tracing; else s = 0: an emitter hit; s = 1: next event; s >= 2: a connection.
StrategyClass strategyClassOf(int s, int t);
// The classes an estimator samples: a path tracer's emitter hits and next events (its BSDF-sampled
// emission and its next-event estimation), a light tracer's light tracing, a bidirectional one's all.
bool estimatorHasClass(PortEstimator e, StrategyClass c);

// The class's unweighted strategy layers s<S>t<T>.unweighted of depth s + t - 2 in one render,
// averaged: R, G, B only. False when the render holds none of them.
bool strategyClassImage(const ExrImage& render, StrategyClass c, int depth, ExrImage* out);

// The port's unweighted strategy layers, averaged per class of the scene's `strategyClasses` and
// depth, each compared with the reference's depth layer at the Sidak level of alpha over them;
// fills outcome.strategyClassLayers. Nothing when the renders hold no unweighted strategy layers;
// only the classes the port's estimator samples (estimatorHasClass).
void compareStrategyClasses(const std::vector<ExrImage>& renders, const ExrImage& reference, const std::vector<int>& depths,
                            double alpha, SceneOutcome& outcome, PortEstimator estimator = PortEstimator::Bidirectional);

// How much a consistent verdict says (docs/validate.md, "Low-power passes"): the fraction of the
// beauty's pixels with noise (compared, not equal) that were tested and the half-width of the
// bias's 95% interval. `low`: a consistent scene with fewer than kLowPowerTestedFraction of them
// tested or a half-width above kLowPowerBiasHalfWidth, so an error of a few percent could pass.
constexpr double kLowPowerTestedFraction = 0.5, kLowPowerBiasHalfWidth = 0.01;
struct PassPower {
    bool low = false;
    double testedFraction = 0, biasHalfWidth = 0;
};
PassPower passPower(const SceneOutcome& outcome);

std::string validateReportJson(const ValidateReport& report);
std::string validateReportHtml(const ValidateReport& report);
std::string validateSummaryText(const ValidateReport& report);

// Text made safe inside HTML (< > & "), for report.html (validate_report.cpp).
std::string htmlEscaped(const std::string& s);

}  // namespace bdptref
