// The ranked diagnosis of an inconsistent validate run (docs/diagnosis.md, "The score"): a pure
// function of the per-scene results. Each term of the catalogue used by the port's estimator gets
// a log-likelihood-style score from three kinds of evidence:
//   coverage: which scenes that exercise it failed and which passed;
//   scale:    the factors it predicts against each failing scene's ratio test / reference;
//   depth:    the depth structures it predicts against each failing scene's depth layers.
// The candidates are the terms that some failing scene exercises; the confidences are the scores'
// softmax over them (a uniform prior).
#include "verify/validate_diagnosis.h"
#include "verify/validate_diagnosis_classes.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

namespace bdptref {

namespace {

// The weights of the score, in natural-log units (docs/diagnosis.md, "The score").
constexpr double kPower = 0.6;           // chance that a scene exercising a wrong term fails
constexpr double kStray = 0.02;          // chance that a scene fails for a term it does not exercise
constexpr double kExactFactor = 3.0;     // a failing scene's interval holds a factor the term predicts
constexpr double kExactFactorMax = 6.0;  // ... in a narrow interval (exactWeight)
constexpr double kPriorLogRange = 13.815510557964274;  // log(1000) - log(1/1000)
constexpr double kPartialFactor = 1.0;   // its ratio lies between 1 and a factor of part of the image,
                                         // or its interval meets a wide range (kNarrowRange)
constexpr double kNarrowRange = 0.1;     // a range up to 10% wide (in log) is as specific as a constant
constexpr double kSpecificLogWidth = 1.3862943611198906;  // log 4: a range up to x4 wide scores kPartialFactor
constexpr double kFactorAgainst = -1.5;  // a significant factor that none of an exhaustive list explains
constexpr double kDepthMatch = 1.5;      // the depth structure is one the term produces
constexpr double kDepthAgainst = -1.5;   // it is none of those the term lists
constexpr double kNoNetFactor = 3.0;     // a failing scene's ratio holds 1, for a term that moves pixels only (as kExactFactor)
constexpr double kFactorsApart = -3.0;   // a term of one factor for every scene, failing scenes apart
constexpr double kScenesApartLog = 0.0953;  // log 1.1: farther apart than the harness's systematic floor
constexpr double kMinConfidence = 0.02;  // entries below are left out, but for the first kMinListed:
constexpr size_t kMinListed = 3;         // a reviewer sees the runners-up of even a confident first
constexpr double kSignatureCandidate = 0.25;  // a term whose known bug the run resembles this much is a candidate
// A per-bounce factor counts when its interval excludes 1 and it is at least 1% per bounce.
constexpr double kMinPerBounceLog = 0.01;
// Two failing depths whose ratios differ by more than this factor (their intervals apart) are not
// one uniform factor: a camera that sees another part of the scene moves each depth by how its
// own light is spread over the image (a doubled field of view: x0.04 at depth 0, x0.6 at depth 1).
constexpr double kDepthsDifferLog = 0.405;  // log 1.5
constexpr double kZ95 = 1.959963984540054;

struct Interval {
    double value = 1, low = 1, high = 1;
    bool excludesOne() const { return low > 1 || high < 1; }
    bool overlaps(double lo, double hi) const { return low <= hi && high >= lo; }
};

std::string num(double v) {
    char b[32];
    std::snprintf(b, sizeof b, "%.3g", v);
    return b;
}
std::string interval(const Interval& i) { return "x" + num(i.value) + " [" + num(i.low) + ", " + num(i.high) + "]"; }

// ---- what a scene's depth layers say ----

struct DepthObservation {
    bool has = false;           // layers were tested and some failed
    unsigned shapes = 0;        // the k* shapes the layers are compatible with
    int firstFailing = -1;
    bool depth0Fails = false;   // depth 0 (emitters seen directly) was tested and is inconsistent
    bool growthSignificant = false;  // the shape is kGrowing: perBounce holds its factor
    Interval perBounce;         // exp of the fitted slope of log(ratio) over depth >= 1
    std::string words;          // "only depth 0 fails", ...
};

// Weighted least squares of log(ratio) on depth over the tested layers of depth >= 1; the slope's
// variance is scaled by the reduced chi-square when above 1 (a ratio that is not geometric).
bool fitPerBounce(const std::vector<DiagnosisLayer>& layers, Interval* out) {
    double s = 0, sx = 0, sxx = 0, sy = 0, sxy = 0;
    std::vector<std::array<double, 3>> pts;  // x, y, w
    for (const DiagnosisLayer& l : layers) {
        if (!l.tested || l.depth < 1) continue;
        const double floor = 1e-6;  // a layer that is missing (ratio 0) still has a log
        const double y = std::log(std::max(l.ratio, floor));
        const double sigma = std::max((std::log(std::max(l.high, floor)) - std::log(std::max(l.low, floor))) / (2 * kZ95), 1e-4);
        const double w = 1 / (sigma * sigma), x = double(l.depth);
        pts.push_back({x, y, w});
        s += w, sx += w * x, sxx += w * x * x, sy += w * y, sxy += w * x * y;
    }
    if (pts.size() < 3) return false;
    const double det = s * sxx - sx * sx;
    if (!(det > 0)) return false;
    const double b = (s * sxy - sx * sy) / det, a = (sy - b * sx) / s;
    double chi2 = 0;
    for (const auto& p : pts) chi2 += p[2] * (p[1] - a - b * p[0]) * (p[1] - a - b * p[0]);
    const double se = std::sqrt(s / det * std::max(1.0, chi2 / double(pts.size() - 2)));
    *out = {std::exp(b), std::exp(b - kZ95 * se), std::exp(b + kZ95 * se)};
    return true;
}

// Some layer of depth 1 .. below-1 was tested (it carries light) and agrees.
bool agreesBelow(const std::vector<DiagnosisLayer>& layers, int below) {
    return std::any_of(layers.begin(), layers.end(), [&](const DiagnosisLayer& l) {
        return l.tested && l.consistent && l.depth >= 1 && l.depth < below;
    });
}

Interval toInterval(const DiagnosisLayer& l) { return {l.ratio, l.low, l.high}; }

// An agreeing depth 0 says "depth 0 is right" only when its interval excludes the factor of the
// first failing layer: a depth 0 of a few dim pixels agrees with any factor.
bool depth0Clears(const DiagnosisLayer& depth0, const std::vector<DiagnosisLayer>& layers) {
    for (const DiagnosisLayer& l : layers)
        if (l.tested && !l.consistent && l.depth >= 1) return l.ratio < depth0.low || l.ratio > depth0.high;
    return true;
}

// A factor per bounce shows once at depth 1: a depth 1 that agrees and whose interval excludes the
// fitted factor says the change starts deeper (roulette, a path length), not at every bounce.
bool depth1Clears(const std::vector<DiagnosisLayer>& layers, double perBounce) {
    return std::any_of(layers.begin(), layers.end(), [&](const DiagnosisLayer& l) {
        return l.tested && l.consistent && l.depth == 1 && (perBounce < l.low || perBounce > l.high);
    });
}

// Two tested failing layers, both darker, whose ratios are apart by more than kDepthsDifferLog with
// disjoint intervals, or two on opposite sides of 1. A layer without a bias estimate (its interval [1, 1]: a
// layer judged on pixels alone) says nothing of its factor.
bool depthsDiffer(const std::vector<DiagnosisLayer>& layers, std::string* words) {
    std::vector<const DiagnosisLayer*> failing;
    for (const DiagnosisLayer& l : layers)
        if (l.tested && !l.consistent && l.low < l.high && l.low > 0) failing.push_back(&l);
    for (size_t i = 0; i < failing.size(); ++i)
        for (size_t j = i + 1; j < failing.size(); ++j) {
            const DiagnosisLayer &a = *failing[i], &b = *failing[j];
            const bool apart = a.high < b.low || b.high < a.low;
            const bool opposite = (a.high < 1 && b.low > 1) || (b.high < 1 && a.low > 1);
            // Light added (a lamp that emits where it should not) also moves depth 0 most, by
            // ratios above 1 that fall towards it: that is emission's, so only losses count here.
            const bool darker = a.high < 1 && b.high < 1;
            if (!(opposite || (darker && apart && std::abs(std::log(a.ratio / b.ratio)) > kDepthsDifferLog))) continue;
            *words = "depth 0 and deeper fail, by factors that differ (x" + num(a.ratio) + " at depth " +
                     std::to_string(a.depth) + ", x" + num(b.ratio) + " at depth " + std::to_string(b.depth) + ")";
            return true;
        }
    return false;
}

DepthObservation observeDepths(const DiagnosisScene& sc) {
    DepthObservation o;
    std::vector<int> failing;
    int deepestTested = -1;
    const DiagnosisLayer* depth0 = nullptr;
    for (const DiagnosisLayer& l : sc.depths) {
        if (!l.tested) continue;
        deepestTested = std::max(deepestTested, l.depth);
        if (l.depth == 0) depth0 = &l;
        if (!l.consistent) failing.push_back(l.depth);
    }
    if (failing.empty()) return o;
    o.has = true;
    o.firstFailing = failing.front();
    const bool depth0Fails = depth0 && !depth0->consistent;
    o.depth0Fails = depth0Fails;
    // A per-bounce factor leaves depth 0 (no bounce) alone and moves the ratio away from 1 with
    // depth: ratios above 1 that fall towards it are something added, not a factor per bounce.
    Interval fit;
    const DiagnosisLayer* deepestFailing = nullptr;
    for (const DiagnosisLayer& l : sc.depths)
        if (l.tested && !l.consistent) deepestFailing = &l;
    const bool geometric = !depth0Fails && fitPerBounce(sc.depths, &fit) && fit.excludesOne() &&
                           std::abs(std::log(fit.value)) >= kMinPerBounceLog &&
                           (fit.value > 1) == (deepestFailing->ratio > 1) && !depth1Clears(sc.depths, fit.value);
    if (failing == std::vector<int>{0}) {
        o.shapes = kDepth0Only, o.words = "only depth 0 fails";
    } else if (depth0Fails && depthsDiffer(sc.depths, &o.words)) {
        o.shapes = kAnyDepthShape;  // no uniform factor: only a term of no shape in particular fits
    } else if (depth0Fails) {
        o.shapes = kUniform, o.words = "depth 0 and deeper fail";
    } else if (failing.size() == 1 && failing[0] == sc.maxDepth && sc.maxDepth >= 2) {
        // Shallower layers that carry light and agree make it the length limit alone; without
        // them (the deepest layer is the only lit one) any term of that layer may be wrong.
        o.shapes = kLastDepth | (agreesBelow(sc.depths, sc.maxDepth) ? 0u : kDeep);
        o.words = "only the deepest layer (" + std::to_string(sc.maxDepth) + ") fails";
    } else if (failing == std::vector<int>{1} && deepestTested >= 2) {
        o.shapes = kDepth1Only, o.words = "only depth 1 fails, deeper layers agree";
    } else if (failing == std::vector<int>{1}) {  // deeper layers untested: it may go on, by a factor per bounce too
        o.shapes = kDepth1Only | kFromDepth1 | kGrowing | (depth0 ? 0u : kUniform);
        o.words = "depth 1 fails, deeper layers untested";
    } else if (geometric) {
        o.growthSignificant = true, o.perBounce = fit;
        o.shapes = kGrowing, o.words = "the ratio changes " + interval(fit) + " per bounce";
    } else if (o.firstFailing >= 2) {
        o.shapes = kDeep | (o.firstFailing == 2 ? kFromDepth2 : 0u);
        o.words = "the first failing depth is " + std::to_string(o.firstFailing);
    } else if (depth0 && depth0Clears(*depth0, sc.depths)) {
        o.shapes = kFromDepth1, o.words = "depth 0 agrees, depths >= 1 off by a similar factor";
    } else if (depth0) {  // an agreeing depth 0 too noisy to rule out the deeper layers' factor
        o.shapes = kUniform | kFromDepth1;
        o.words = "depths >= 1 off by a similar factor, depth 0 too noisy to tell (" + interval(toInterval(*depth0)) + ")";
    } else {  // nothing seen directly (depth 0 untested): from depth 1 is every depth
        o.shapes = kUniform | kFromDepth1, o.words = "every depth off by a similar factor";
    }
    return o;
}

// How the evidence names a share of the image (suite.json strategyShares and emitterShares).
struct ShareWords {
    const char* name;
    const char* of;       // "... holds 1/2 on <of> 0.22 of the image"
    const char* without;  // a scene without the share: "passes a, b, which have <without>"
};
constexpr ShareWords kShareWords[] = {
    {kLightTracingShare, "light tracing's share", "no light tracing"},
    {kDeepestEmitterHitShare, "the deepest depth's emitter hits' share", "no emitter hits at the deepest depth"},
    {kDeepestLightTracingShare, "the deepest depth's light tracing's share", "no light tracing at the deepest depth"},
    {kDoubleSidedFromDepth1Share, "the double-sided emitters' light from depth 1,", "no double-sided emitter"},
};
const ShareWords& shareWords(const std::string& name) {
    for (const ShareWords& w : kShareWords)
        if (name == w.name) return w;
    static const ShareWords unknown{"", "the share", "none of it"};
    return unknown;
}

// ---- one term's score ----

struct TermScore {
    double score = 0;
    std::vector<std::string> pro, con;
};

bool exercises(const DiagnosisScene& sc, const Term& t) {
    return std::find(sc.terms.begin(), sc.terms.end(), t.id) != sc.terms.end();
}

std::string nameList(const std::vector<std::string>& names) {
    std::string s;
    for (size_t i = 0; i < names.size(); ++i) s += (i ? ", " : "") + names[i];
    return s;
}

// Naive Bayes over the scenes with a verdict: a wrong term fails a scene that exercises it with
// probability kPower, one that does not with kStray. With `confinedTo` (confiningEmitterShare) the
// error is one of some emitters alone: a passing scene without them says nothing about it.
void addCoverage(const Term& t, const DiagnosisInput& in, const char* confinedTo, TermScore& ts) {
    std::vector<std::string> failedWith, failedWithout, passedWith, passedWithout;
    for (const DiagnosisScene& sc : in.scenes) {
        if (sc.outcome == DiagnosisOutcome::Untested) continue;
        const bool failed = sc.outcome == DiagnosisOutcome::Failed, ex = exercises(sc, t);
        if (!failed && ex && confinedTo && !sc.emitterShares.count(confinedTo)) {
            passedWithout.push_back(sc.name);
            continue;
        }
        ts.score += std::log(ex ? (failed ? kPower : 1 - kPower) : (failed ? kStray : 1 - kStray));
        if (failed) (ex ? failedWith : failedWithout).push_back(sc.name);
        else if (ex) passedWith.push_back(sc.name);
    }
    auto which = [](const std::vector<std::string>& n, const char* one, const char* many) {
        return nameList(n) + (n.size() == 1 ? one : many);
    };
    if (!failedWith.empty()) ts.pro.push_back("fails " + which(failedWith, ", which exercises it", ", which exercise it"));
    if (!failedWithout.empty()) ts.con.push_back("fails " + which(failedWithout, ", which does not exercise it", ", which do not exercise it"));
    if (!passedWith.empty()) ts.con.push_back("passes " + which(passedWith, ", which exercises it", ", which exercise it"));
    if (!passedWithout.empty())
        ts.pro.push_back("passes " + which(passedWithout, ", which has ", ", which have ") + shareWords(confinedTo).without + " (no evidence)");
}

// The factor's range on this scene; false when it needs a glass the scene has not.
bool factorRange(const TermFactor& f, const DiagnosisScene& sc, double* lo, double* hi) {
    switch (f.of) {
        case TermFactor::Of::Constant: *lo = f.low, *hi = f.high; return true;
        case TermFactor::Of::SceneEta2: *lo = *hi = sc.ior * sc.ior; return sc.ior > 0;
        case TermFactor::Of::SceneInvEta2: *lo = *hi = 1 / (sc.ior * sc.ior); return sc.ior > 0;
        case TermFactor::Of::SceneEta4: *lo = *hi = std::pow(sc.ior, 4.0); return sc.ior > 0;
        case TermFactor::Of::SceneInvEta4: *lo = *hi = std::pow(sc.ior, -4.0); return sc.ior > 0;
    }
    return false;
}

// The best match of a term's factors of one mode with a significant measured ratio on one scene.
struct FactorMatch {
    bool anyFactor = false;  // the term has a factor of this mode that applies to the scene
    double weight = 0;       // kExactFactor, kPartialFactor or 0
    bool exact = false;
    std::string factor, words;
};

// kPartialFactor for a range up to kSpecificLogWidth wide (in log), less in proportion beyond.
double specificWeight(double logWidth) {
    return kPartialFactor * std::min(1.0, kSpecificLogWidth / std::max(logWidth, 1e-9));
}

// An interval that holds a predicted constant says more the narrower it is: a ratio that falls by
// chance within +-0.5% of 4 is rarer than one within +-20%. The weight is the log of the prior
// range of log-ratios (kPriorLogRange: factors between 1/1000 and 1000) over the interval's
// width in log, at least kExactFactor (a wide interval) and at most kExactFactorMax.
double exactWeight(const Interval& measured) {
    const double logWidth = std::log(std::max(measured.high, 1e-300) / std::max(measured.low, 1e-300));
    if (!(logWidth > 0)) return kExactFactorMax;
    return std::clamp(std::log(kPriorLogRange / logWidth), kExactFactor, kExactFactorMax);
}

// Factor matching widens the measured interval by kSystematicFloor on each side (the header says
// why); significance is judged on the interval as measured.
Interval withSystematicFloor(const Interval& m) {
    return {m.value, m.low * (1 - kSystematicFloor), m.high * (1 + kSystematicFloor)};
}

// A factor f on a share s of the image (a kind of light's, a strategy's) against the image mean:
// 1 - s (1 - f) is as specific as a constant.
void matchMeanOnShare(const DiagnosisScene& sc, double share, double f, const std::string& name, const std::string& of,
                      FactorMatch* m) {
    const RatioRange p = ratioOnShare(share, f);
    const Interval mean = withSystematicFloor({sc.meanRatio, sc.meanLow, sc.meanHigh});
    if (!mean.overlaps(p.low, p.high) || m->weight >= exactWeight(mean)) return;
    m->weight = exactWeight(mean), m->exact = true, m->factor = name;
    m->words = sc.name + ": the image mean's " + interval(mean) + " holds " + name + " on " + of + " " + num(share) +
               " of the image ([" + num(p.low) + ", " + num(p.high) + "])";
}

// A factor on a named share of the image: TermFactor::strategyShare, one of BDPT's strategy
// shares, read by a bidirectional port; TermFactor::emitterShare, some emitters' light from depth
// 1 on, read by a light tracer (it samples their directions; depth 0 joins their point to the
// camera with no direction density). Other ports, and scenes without the share or the image mean,
// skip it.
void matchOnNamedShare(const TermFactor& f, PortEstimator e, const DiagnosisScene& sc, FactorMatch* m) {
    const bool emitter = f.emitterShare != nullptr;
    const std::map<std::string, double>& shares = emitter ? sc.emitterShares : sc.strategyShares;
    const auto s = shares.find(emitter ? f.emitterShare : f.strategyShare);
    if (e != (emitter ? PortEstimator::Light : PortEstimator::Bidirectional) || s == shares.end() || !sc.hasMean) return;
    m->anyFactor = true;
    matchMeanOnShare(sc, s->second, f.low, f.name, shareWords(s->first).of, m);
}

FactorMatch bestFactorMatch(const Term& t, PortEstimator e, const DiagnosisScene& sc, TermFactor::Mode mode,
                            const Interval& measured) {
    FactorMatch m;
    const std::string per = mode == TermFactor::Mode::PerBounce ? " per bounce" : "";
    const bool layersTested = std::any_of(sc.depths.begin(), sc.depths.end(), [](const DiagnosisLayer& l) { return l.tested; });
    for (const TermFactor& f : t.factors) {
        double lo, hi;
        if (f.mode != mode || !factorRange(f, sc, &lo, &hi) || (f.withoutDepthLayers && layersTested)) continue;
        if (f.strategyShare || f.emitterShare) {
            matchOnNamedShare(f, e, sc, &m);
            continue;
        }
        m.anyFactor = true;
        const std::string name = f.name + (f.of == TermFactor::Of::Constant ? "" : " = " + num(lo));
        const bool narrow = hi == lo || std::log(hi / lo) <= kNarrowRange;  // hi == lo: also 0 (nothing)
        const bool between = hi < 1 ? measured.value > hi && measured.value < 1 : measured.value < lo && measured.value > 1;
        // A wide range says little: "in range" of a roulette loss (0.05 to 0.995) or "between 1
        // and 1/4096" holds most ratios; the weight falls with the range's width in log.
        const double inRange = specificWeight(std::log(hi / lo));
        const double partial = specificWeight(std::abs(std::log(hi < 1 ? hi : lo)));
        const double exact = exactWeight(measured);
        // A factor on one kind of light, on a scene lit by several: the share says how much of
        // the image it scales (light shares), and 1 - s (1 - f) is as specific as a constant.
        // It is matched with the plain image-mean ratio (light shares are of the mean).
        const double share = f.lights != 0 && mode == TermFactor::Mode::Uniform ? lightShareOf(sc, f.lights) : 1.0;
        if (share > 0 && share < 1 && sc.hasMean) matchMeanOnShare(sc, share, lo, name, "the lights' share", &m);
        if (measured.overlaps(lo, hi) && m.weight < (narrow ? exact : inRange)) {
            m.weight = narrow ? exact : inRange, m.exact = narrow, m.factor = f.name;
            m.words = sc.name + ": " + interval(measured) + per + (narrow ? " holds " : " is in ") + name;
        // A factor on a kind of light covers the whole image of a scene lit by that kind alone
        // (share 1): no part of it is spared, so "between 1 and the factor" is no match there
        // (sphere-point-light at x0.875 is no 1/683 on part of the image).
        } else if (mode == TermFactor::Mode::Uniform && f.partial && !wholeImageInLightTracer(t, e) && between && (f.lights == 0 || share < 1) &&
                   m.weight < partial) {
            m.weight = partial, m.exact = false, m.factor = f.name;
            m.words = sc.name + ": " + interval(measured) + " lies between 1 and " + name + " (part of the image)";
        }
    }
    return m;
}

// The uniform factors against the beauty's ratio, the per-bounce ones against the depth fit.
void addScaleFit(const Term& t, PortEstimator e, const DiagnosisScene& sc, const DepthObservation& d, TermScore& ts,
                 std::vector<std::string>* exactFactors) {
    for (const TermFactor::Mode mode : {TermFactor::Mode::Uniform, TermFactor::Mode::PerBounce}) {
        const bool perBounce = mode == TermFactor::Mode::PerBounce;
        const Interval measured = perBounce ? d.perBounce : Interval{sc.ratio, sc.low, sc.high};
        if (!(perBounce ? d.growthSignificant : measured.excludesOne())) continue;
        const FactorMatch m = bestFactorMatch(t, e, sc, mode, withSystematicFloor(measured));
        if (m.weight > 0) {
            ts.score += m.weight;
            ts.pro.push_back(m.words);
            if (m.exact) exactFactors->push_back(m.factor);
        } else if (m.anyFactor && t.factorsExhaustive) {
            ts.score += kFactorAgainst;
            ts.con.push_back(sc.name + ": " + interval(measured) + (perBounce ? " per bounce" : "") + " is none of its factors");
        }
    }
}

void addDepthStructure(const Term& t, PortEstimator e, const DiagnosisScene& sc, const DepthObservation& d, TermScore& ts) {
    const unsigned shapes = depthShapesFor(t, e);
    if (!d.has || shapes == 0) return;
    // Depth 0 is the emitters seen directly: a wrong term no camera ray reads there cannot fail it.
    if ((shapes & d.shapes) && !(d.depth0Fails && !movesDepth0(t))) {
        ts.score += kDepthMatch;
        ts.pro.push_back(sc.name + ": " + d.words);
    } else {
        ts.score += kDepthAgainst;
        ts.con.push_back(sc.name + ": " + d.words);
    }
}

void addStrategyClasses(const Term& t, PortEstimator e, const DiagnosisScene& sc, const ClassObservation& c, TermScore& ts) {
    const double w = strategyClassWeight(t, e, c);
    if (w == 0) return;
    ts.score += w;
    (w > 0 ? ts.pro : ts.con).push_back(sc.name + ": " + c.words);
}

// A term of one factor for every scene (oneFactorForEveryScene) cannot explain two failing
// scenes whose ratios are more than kScenesApartLog apart, their intervals disjoint.
void addFactorsApart(const Term& t, const DiagnosisInput& in, TermScore& ts) {
    if (!oneFactorForEveryScene(t, in.estimator)) return;
    const DiagnosisScene *low = nullptr, *high = nullptr;
    for (const DiagnosisScene& sc : in.scenes) {
        if (sc.outcome != DiagnosisOutcome::Failed || !exercises(sc, t) || !(sc.low > 0)) continue;
        if (!low || sc.high < low->high) low = &sc;
        if (!high || sc.low > high->low) high = &sc;
    }
    if (!low || low == high) return;
    const Interval a = withSystematicFloor({low->ratio, low->low, low->high}), b = withSystematicFloor({high->ratio, high->low, high->high});
    if (!(a.high < b.low && std::log(high->ratio / low->ratio) > kScenesApartLog)) return;
    ts.score += kFactorsApart;
    ts.con.push_back("one factor for every scene, but " + low->name + " is " + interval(a) + " and " + high->name + " " + interval(b));
}

// A scene that fails although its beauty's ratio (and image mean, where reported) holds 1: the
// pixels differ, the image as a whole does not, as a blur across pixels does.
void addNoNetFactor(const Term& t, const DiagnosisScene& sc, TermScore& ts) {
    const Interval beauty{sc.ratio, sc.low, sc.high}, mean{sc.meanRatio, sc.meanLow, sc.meanHigh};
    if (!movesPixelsNotTheMean(t) || !(sc.low > 0) || beauty.excludesOne() || (sc.hasMean && mean.excludesOne())) return;
    ts.score += kNoNetFactor;
    ts.pro.push_back(sc.name + ": fails with no net factor (" + interval(beauty) + "): the pixels differ, not the image");
}

// The emitter share (TermFactor::emitterShare) whose predicted factor a failing scene's image mean
// holds: the error is then one of those emitters, and scenes without them need not fail.
const char* confiningEmitterShare(const Term& t, const DiagnosisInput& in) {
    for (const DiagnosisScene& sc : in.scenes) {
        if (sc.outcome != DiagnosisOutcome::Failed || !exercises(sc, t)) continue;
        for (const TermFactor& f : t.factors) {
            if (!f.emitterShare) continue;
            FactorMatch m;
            matchOnNamedShare(f, in.estimator, sc, &m);
            if (m.exact) return f.emitterShare;
        }
    }
    return nullptr;
}

TermScore scoreTerm(const Term& t, const DiagnosisInput& in, const std::vector<DepthObservation>& depths,
                    const std::vector<ClassObservation>& classes) {
    TermScore ts;
    addCoverage(t, in, confiningEmitterShare(t, in), ts);
    std::vector<std::string> exactFactors;
    int failingExercised = 0;
    for (size_t i = 0; i < in.scenes.size(); ++i) {
        const DiagnosisScene& sc = in.scenes[i];
        if (sc.outcome != DiagnosisOutcome::Failed || !exercises(sc, t)) continue;
        ++failingExercised;
        addScaleFit(t, in.estimator, sc, depths[i], ts, &exactFactors);
        addDepthStructure(t, in.estimator, sc, depths[i], ts);
        addStrategyClasses(t, in.estimator, sc, classes[i], ts);
        addNoNetFactor(t, sc, ts);
    }
    addFactorsApart(t, in, ts);
    const SignatureMatch like = bestSignatureMatch(in, t.id);
    if (like.similarity > 0 && in.signatureWeight > 0) {
        ts.score += in.signatureWeight * like.similarity;
        ts.pro.push_back(like.words);
    }
    // Said, not scored again: the per-scene matches already add up.
    if (failingExercised >= 2 && int(exactFactors.size()) >= failingExercised &&
        std::all_of(exactFactors.begin(), exactFactors.end(), [&](const std::string& n) { return n == exactFactors[0]; }))
        ts.pro.insert(ts.pro.begin(), "the same factor " + exactFactors[0] + " on all " + std::to_string(failingExercised) +
                                          " failing scenes that exercise it");
    return ts;
}

// "Signature. For: a; b. Against: c; d."
std::string evidenceText(const Term& t, const TermScore& ts) {
    auto join = [](const std::vector<std::string>& items) {
        std::string s;
        for (size_t i = 0; i < items.size(); ++i) s += (i ? "; " : "") + items[i];
        return s;
    };
    std::string e = std::string(t.signature) + ". For: " + (ts.pro.empty() ? std::string("nothing but its prior") : join(ts.pro)) + ".";
    if (!ts.con.empty()) e += " Against: " + join(ts.con) + ".";
    return e;
}

// The scenes' term lists extended by the signatures: a scene that a known bug of term T failed,
// played by the port's estimator, exercises T, whether or not the suite's list says so (the
// lists are written by hand). Another estimator's bug says less: a light tracer's cosine-sampling
// bug fails every diffuse scene, where a path tracer's next events carry most of the light and
// the same term barely shows (measured: it put a path tracer's area-light Jacobian bug on
// lambert.sample).
DiagnosisInput withSignatureTerms(const DiagnosisInput& in) {
    DiagnosisInput out = in;
    if (!(in.signatureWeight > 0)) return out;  // signatures off
    for (DiagnosisScene& sc : out.scenes)
        for (const BugSignature& sig : in.signatures) {
            if (sig.estimator != portEstimatorName(in.estimator)) continue;
            if (sig.bug == in.leaveOut || std::find(sc.terms.begin(), sc.terms.end(), sig.term) != sc.terms.end()) continue;
            if (std::any_of(sig.scenes.begin(), sig.scenes.end(), [&](const SignatureScene& s) { return s.failed && s.name == sc.name; }))
                sc.terms.push_back(sig.term);
        }
    return out;
}

// In BDPT every pixel is a weighted sum of several strategies: every scene exercises the MIS
// weights, whatever the scene's list (written for path tracers, whose weights matter where next
// events and BSDF samples overlap).
DiagnosisInput withBidirectionalWeights(DiagnosisInput in) {
    if (in.estimator != PortEstimator::Bidirectional) return in;
    for (DiagnosisScene& sc : in.scenes)
        if (std::find(sc.terms.begin(), sc.terms.end(), "mis.weights") == sc.terms.end()) sc.terms.push_back("mis.weights");
    return in;
}

}  // namespace

double lightShareOf(const DiagnosisScene& sc, unsigned lights) {
    if (sc.lightShares.empty()) return 1.0;
    double s = 0;
    for (const auto& [kind, share] : sc.lightShares)
        if (lights & lightKindBit(kind)) s += share;
    return s;
}

RatioRange ratioOnShare(double share, double f) {
    // A share of 1 is exact (a scene lit by that kind of light alone), not a measurement.
    const double lo = share < 1 ? std::max(0.0, share - kShareTolerance) : 1.0, hi = std::min(1.0, share + kShareTolerance);
    const double a = 1 - lo * (1 - f), b = 1 - hi * (1 - f);
    return {std::min(a, b), std::max(a, b)};
}

std::vector<DiagnosisEntry> diagnose(const DiagnosisInput& input, size_t maxEntries) {
    const DiagnosisInput in = withBidirectionalWeights(withSignatureTerms(input));
    if (std::none_of(in.scenes.begin(), in.scenes.end(),
                     [](const DiagnosisScene& s) { return s.outcome == DiagnosisOutcome::Failed; }))
        return {};
    std::vector<DepthObservation> depths;
    std::vector<ClassObservation> classes;
    for (const DiagnosisScene& sc : in.scenes) depths.push_back(observeDepths(sc)), classes.push_back(observeClasses(sc));

    // The candidates: the terms the estimator uses that some failing scene exercises (a diagnosis
    // explains the failures), or whose known bugs the run resembles. None when the failing scenes
    // list no terms and no signature matches (a suite of one's own): a ranking of the whole
    // catalogue by the passing scenes alone would say nothing.
    std::vector<const Term*> candidates;
    for (const Term& t : termCatalogue())
        if ((t.estimators & estimatorBit(in.estimator)) &&
            (std::any_of(in.scenes.begin(), in.scenes.end(), [&](const DiagnosisScene& s) {
                 return s.outcome == DiagnosisOutcome::Failed && exercises(s, t);
             }) || (in.signatureWeight > 0 && bestSignatureMatch(in, t.id).similarity >= kSignatureCandidate)))
            candidates.push_back(&t);

    std::vector<DiagnosisEntry> all;
    for (const Term* tp : candidates) {
        const Term& t = *tp;
        const TermScore ts = scoreTerm(t, in, depths, classes);
        all.push_back({t.id, 0, ts.score, evidenceText(t, ts)});
    }
    if (all.empty()) return {};
    // Softmax of the scores: the posterior of "this term is the wrong one" under a uniform prior.
    const double top = std::max_element(all.begin(), all.end(), [](auto& a, auto& b) { return a.score < b.score; })->score;
    double sum = 0;
    for (DiagnosisEntry& e : all) sum += (e.confidence = std::exp(e.score - top));
    for (DiagnosisEntry& e : all) e.confidence /= sum;
    std::stable_sort(all.begin(), all.end(), [](const DiagnosisEntry& a, const DiagnosisEntry& b) { return a.score > b.score; });

    std::vector<DiagnosisEntry> out;
    if (in.top > 0) maxEntries = in.top;
    for (DiagnosisEntry& e : all) {
        if (out.size() >= maxEntries || (out.size() >= kMinListed && in.top == 0 && e.confidence < kMinConfidence)) break;
        out.push_back(std::move(e));
    }
    return out;
}

}  // namespace bdptref
