// The diagnosis of an inconsistent `bdptref validate` run (docs/diagnosis.md): which term of the
// port's estimator best explains the scenes that failed, and why. Two pieces:
//  - the term catalogue (validate_terms.cpp): every term a BDPT / PT / LT port implements, with a
//    stable id, the estimators that use it and the signature a wrong term leaves on the suite
//    (a factor, a depth structure); the suite file says which scenes exercise which term (`terms`);
//  - the ranking (validate_diagnosis.cpp): a pure function of a small struct of per-scene results,
//    so that it is tested without renders; validate_diagnosis_report.cpp converts a
//    ValidateReport into that struct and writes the ranking into the summary, JSON and HTML.
#pragma once

#include "verify/validate.h"

#include <nlohmann/json.hpp>

#include <map>
#include <string>
#include <vector>

namespace bdptref {

// ---- the term catalogue --------------------------------------------------------------------------

// The estimators that use a term, one bit per PortEstimator.
enum : unsigned { kUsedByPath = 1u, kUsedByLight = 2u, kUsedByBidirectional = 4u, kUsedByAll = 7u };
unsigned estimatorBit(PortEstimator e);

// How the per-depth ratios test / reference of a scene look (docs/diagnosis.md, "Depth structure").
// A term lists the shapes a wrong implementation of it produces; an observation is a set of the
// shapes it is compatible with.
enum : unsigned {
    kDepth0Only = 1u,   // only depth 0 (emitters seen directly) differs: emission or the camera
    kDepth1Only = 2u,   // only depth 1 differs: next-event estimation / light sampling
    kFromDepth1 = 4u,   // depth 0 agrees, every depth >= 1 off by about the same factor
    kUniform = 8u,      // every depth off by about the same factor (depth 0 included or untested)
    kGrowing = 16u,     // the ratio changes geometrically with depth: a per-bounce factor
    kDeep = 32u,        // the first failing depth is >= 2 and the ratio is not geometric
    kLastDepth = 64u,   // only the deepest layer differs: the path length limit
    kFromDepth2 = 128u, // kDeep whose first failing depth is 2: light one bounce away from the camera's first hit
    // No shape in particular: an error that depends on where on the image the light lands (the
    // camera, the pixel filter) changes each depth layer by how its own light is spread over the
    // image, so the layers can take any shape, and they are no evidence either way.
    kAnyDepthShape = 0u,
};

// A factor that a wrong term multiplies the image (Uniform) or each bounce (PerBounce) by.
struct TermFactor {
    enum class Mode { Uniform, PerBounce };
    // A range [low, high], or the scene's (ior)^(+-2) or (ior)^(+-4) (the ratio inverted: (1/eta^2) / eta^2).
    enum class Of { Constant, SceneEta2, SceneInvEta2, SceneEta4, SceneInvEta4 };
    Mode mode = Mode::Uniform;
    Of of = Of::Constant;
    double low = 1, high = 1;
    const char* name = "";   // as the evidence writes it: "1/683", "eta^2"
    // The term may touch part of the image only (punctual lights beside emissive meshes, rays that
    // refract beside rays that reflect): a ratio between 1 and the factor matches weakly.
    bool partial = false;
    // The kinds of light whose whole contribution the factor scales (lightKindBit; 0: not one kind
    // of light): on a scene with lightShares it predicts 1 - s (1 - f), s their share.
    unsigned lights = 0;
    // A uniform range that stands in for a per-bounce factor where no depth layer shows it (a
    // port that writes none: Blender Cycles), matched only on such a scene. Where depth layers
    // were tested the per-bounce factor says it; the range alone held any brightening of 2% to x4.
    bool withoutDepthLayers = false;
    // A factor on one share of a bidirectional port's weighted image (SuiteScene::strategyShares:
    // light tracing's, the deepest emitter hits'): 1 - s (1 - f) on the image mean; other ports
    // and scenes without the share skip it.
    const char* strategyShare = nullptr;
    // A factor on the share of a light-tracing port's image that some emitters light from depth 1
    // on (SuiteScene::emitterShares): 1 - s (1 - f) on the image mean; other ports skip it.
    const char* emitterShare = nullptr;
};
inline constexpr unsigned lightKindBit(LightKind k) { return 1u << unsigned(k); }

struct Term {
    const char* id;           // stable: reports and scripts key on it
    const char* description;  // one line: what the term is
    unsigned estimators;      // kUsedBy* bits
    const char* signature;    // what a wrong term does to the suite, in words
    unsigned depthShapes;     // k* depth shapes a wrong term produces (0: none in particular)
    std::vector<TermFactor> factors;
    bool factorsExhaustive;   // a significant factor of a mode none of `factors` matches speaks against it
    bool convention;          // a convention difference of foreign renderers (Cycles, ...), not a bug
    unsigned bidirectionalDepthShapes = 0;  // shapes a bidirectional port adds to depthShapes
};
// The shapes a wrong `t` produces in a port of estimator `e`.
unsigned depthShapesFor(const Term& t, PortEstimator e);
// A term of light tracing's camera end alone (camera importance, splat normalisation: the
// strategy class lightTracing only) in a light-tracing port, where every path ends there: its
// factors cover the whole image, none is partial ("between 1 and 1/4096" is no match there).
bool wholeImageInLightTracer(const Term& t, PortEstimator e);
// A term whose error is one factor, the same on every scene, for a port of estimator `e`: a light
// tracer's splats are normalised by numbers no scene changes (the pixel count, the spp).
bool oneFactorForEveryScene(const Term& t, PortEstimator e);

// A term whose error moves light between pixels and leaves the image mean as it is (a filter
// that blurs across pixels): a scene failing without a net factor speaks for it.
bool movesPixelsNotTheMean(const Term& t);

// Whether a wrong `t` can change depth 0, the emitters a camera ray sees directly (docs/diagnosis.md,
// "Depth structure"): their emission, the camera and the pixel filter, what lies between (alpha,
// an absorbing medium) and the weights of the strategies that sample it. A BSDF, a light's
// sampling or a subpath's roulette cannot: no bounce and no sampled light lies on such a path.
bool movesDepth0(const Term& t);

// The classes of BDPT strategy whose unweighted contributions a wrong `t` moves, one bit per
// StrategyClass (docs/diagnosis.md, "Strategy classes"): next-event estimation alone reads the
// light's sampling density, light tracing alone the camera's importance, light subpaths (light
// tracing and connections) the emission density; the MIS weights move none (the unweighted
// layers do not hold them). kAllStrategyClasses: any, or not known.
inline constexpr unsigned kAllStrategyClasses = (1u << kStrategyClassCount) - 1;
inline constexpr unsigned strategyClassBit(StrategyClass c) { return 1u << unsigned(c); }
unsigned strategyClassesOf(const Term& t);
// The classes a port of estimator `e` samples (estimatorHasClass) as bits: emitter hits and next
// events for a path tracer, whose BSDF-sampled emission and next-event estimation are BDPT's
// strategies s = 0 and s = 1; a term moves the ones among them that strategyClassesOf names.
unsigned strategyClassesOfEstimator(PortEstimator e);

// Every term, in the order of docs/diagnosis.md. Ids are unique.
const std::vector<Term>& termCatalogue();
const Term* findTerm(const std::string& id);  // nullptr when unknown

// The markdown table of docs/diagnosis.md ("The terms"), with the scenes of `suite` that list each
// term (none: no scenes column). tests/unit/test_validate_diagnosis.cpp holds the doc to it.
std::string termCatalogueMarkdown(const Suite* suite);

// ---- the diagnosis -------------------------------------------------------------------------------

enum class DiagnosisOutcome { Passed, Failed, Untested };

// One depth layer: the ratio test / reference (1 + relative bias) with its 95% interval.
struct DiagnosisLayer {
    int depth = 0;
    bool tested = false, consistent = true;
    double ratio = 1, low = 1, high = 1;
};

// One class of strategy at one depth: its unweighted average against the reference's depth layer.
struct DiagnosisClassLayer {
    StrategyClass strategyClass = StrategyClass::EmitterHit;
    DiagnosisLayer layer;
};

// What the diagnosis needs of one scene's result.
struct DiagnosisScene {
    std::string name;
    DiagnosisOutcome outcome = DiagnosisOutcome::Untested;
    double ratio = 1, low = 1, high = 1;   // the beauty's ratio test / reference and its 95% interval
    // The beauty's plain image-mean ratio and its 95% interval (LayerOutcome::meanRelativeBias),
    // which light-share predictions are matched with; hasMean false in older reports.
    bool hasMean = false;
    double meanRatio = 1, meanLow = 1, meanHigh = 1;
    std::vector<DiagnosisLayer> depths;    // depth layers, increasing depth (empty: the port wrote none)
    std::vector<DiagnosisClassLayer> classLayers;  // strategy classes (empty: not written or not compared)
    std::vector<std::string> terms;        // the catalogue ids the scene exercises (suite.json `terms`)
    double ior = 0;                        // the index of refraction of the scene's glass (0: none)
    std::map<LightKind, double> lightShares;  // each kind of light's share of the image (empty: one kind)
    std::map<std::string, double> strategyShares;  // BDPT's weighted strategy shares (SuiteScene::strategyShares)
    std::map<std::string, double> emitterShares;   // some emitters' share from depth 1 (SuiteScene::emitterShares)
    int maxDepth = 8;
};

// A measured ratio is no more exact than the harness: clean runs show biases up to about half a
// percent that their intervals exclude (lights-room: -0.44% [-0.64%, -0.24%], docs/validate.md),
// and an interval of +-0.3% around 0.317 should still hold 1/pi = 0.3183. A predicted factor is
// matched against the measured interval widened by this much on each side.
inline constexpr double kSystematicFloor = 0.005;

// Light shares (docs/diagnosis.md, "Light shares"): the share of a scene's image that some kinds
// of light give (lightKindBit), 1 for a scene without lightShares (lit by one kind), and the
// ratio a factor f on that share predicts, 1 - s (1 - f), for s within +-kShareTolerance (a share
// of 1, a scene lit by one kind, is exact). A share
// is of the image mean (light_shares.py: measured to +-0.0002), so the prediction is matched
// with the plain image-mean ratio (DiagnosisScene::meanRatio), not the bias test's tile-weighted
// one: that weighs tiles by their noise, and a light removed from the test removes its noise too
// (measured: spots divided by 683 in lights-room read -62% tile-weighted for -52.5% of the mean).
// The tolerance covers a share that differs a little between the port's model and bdptref's.
inline constexpr double kShareTolerance = 0.02;
struct RatioRange {
    double low = 1, high = 1;
};
double lightShareOf(const DiagnosisScene& sc, unsigned lights);
RatioRange ratioOnShare(double share, double f);

// The weight of a bug signature's similarity in a term's score (natural-log units;
// docs/diagnosis.md, "Bug signatures").
constexpr double kSignatureWeight = 4.0;

struct DiagnosisInput {
    PortEstimator estimator = PortEstimator::Bidirectional;
    std::vector<DiagnosisScene> scenes;
    std::vector<BugSignature> signatures;  // known bugs' results on the suite (may be empty)
    std::string leaveOut;                  // a bug whose signature is ignored (leave-one-out measurement)
    double signatureWeight = kSignatureWeight;
    size_t top = 0;  // > 0: list this many terms, however low their confidence (`bdptref diagnose --top`)
};

// How much the run looks like one known bug's signature, in [0, 1]: the overlap of the failing
// scenes (Jaccard) times the agreement of their ratios (sign and size); docs/diagnosis.md.
struct SignatureMatch {
    double similarity = 0;
    std::string bug, words;  // the best-matching bug and the evidence in words
};
SignatureMatch bestSignatureMatch(const DiagnosisInput& input, const std::string& term);

struct DiagnosisEntry {
    std::string term;
    double confidence = 0;  // exp(score) normalised over the candidates (docs/diagnosis.md)
    double score = 0;       // the log-likelihood-style sum of docs/diagnosis.md, "The score"
    std::string evidence;   // the evidence that moved the score, in words
};

// The terms that best explain the failing scenes, best first, at most `maxEntries`, those below
// kMinConfidence left out (the first is always given). Empty when no scene failed, or when the
// failing scenes exercise no term the port's estimator uses (a suite without `terms`).
std::vector<DiagnosisEntry> diagnose(const DiagnosisInput& input, size_t maxEntries = 5);

// The best term of each failing scene taken alone: the other failing scenes left untested, the
// passing ones kept. A foreign renderer differs in several independent conventions at once
// (Cycles' stock materials: Burley on the Lambert scenes, 683 on the point light, no eta^2 behind
// glass), and one ranking over all scenes names only the term that explains most of them.
//
// Then each scene's term is weighed against the others' (explaining away, docs/diagnosis.md,
// "Several terms at once"): a scene whose own best term no other failing scene names, but whose
// ratio one or two terms named by other scenes predict together (a factor on one kind of light,
// by the scene's lightShares, times a factor on the whole image), is put on those: lights-room
// under Cycles is 1/683 on its spots and Burley's gain on every wall, both named elsewhere,
// not a third term of its own.
struct SceneDiagnosis {
    std::string scene;
    DiagnosisEntry best;             // the term named first (with `joint`: its first term)
    std::vector<std::string> joint;  // the terms named by other scenes that explain it together (empty: best alone)
};
std::vector<SceneDiagnosis> diagnosePerScene(const DiagnosisInput& input);

// ---- the report's hooks (validate_diagnosis_report.cpp) ------------------------------------------

DiagnosisInput diagnosisInput(const ValidateReport& report);
nlohmann::ordered_json diagnosisJson(const ValidateReport& report);  // [{"term", "confidence", ...}]
std::string diagnosisSummaryText(const ValidateReport& report);     // "" when there is nothing to say
std::string diagnosisHtml(const ValidateReport& report);            // "" when there is nothing to say
nlohmann::ordered_json diagnosisPerSceneJson(const ValidateReport& report);  // [{"scene", "term", ...}]

// The same from a saved report.json and its suite (`bdptref diagnose`): another catalogue,
// signatures file or leave-one-out without rendering again. Throws InputError on a report that
// does not fit the suite.
DiagnosisInput diagnosisInputFromJson(const nlohmann::json& report, const Suite& suite);
std::string diagnosisText(const DiagnosisInput& input);
nlohmann::ordered_json diagnosisJson(const DiagnosisInput& input);
nlohmann::ordered_json diagnosisPerSceneJson(const DiagnosisInput& input);

}  // namespace bdptref
