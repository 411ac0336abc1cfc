// Strategy classes as evidence for the diagnosis (docs/diagnosis.md, "Strategy classes").
#include "verify/validate_diagnosis_classes.h"

namespace bdptref {

namespace {

constexpr double kEmptyClassShare = 1e-3;  // a strategy class this small a share of the image holds no error
constexpr double kClassMatch = 2.0;        // the failing strategy classes are among those the term moves
constexpr double kClassAgainst = -2.0;     // a class fails that the term does not move, or one it moves clears

std::string classNames(unsigned bits) {
    std::string s;
    for (int c = 0; c < kStrategyClassCount; ++c)
        if (bits & strategyClassBit(StrategyClass(c))) s += (s.empty() ? "" : ", ") + std::string(strategyClassName(StrategyClass(c)));
    return s;
}

// The error a class layer of depth d should show if its strategies carried it: the port's own
// depth-d layer when that one failed, else the beauty's (a port without depth layers).
const DiagnosisLayer* errorAtDepth(const DiagnosisScene& sc, int depth) {
    for (const DiagnosisLayer& l : sc.depths)
        if (l.depth == depth) return l.tested && !l.consistent ? &l : nullptr;
    return nullptr;
}

}  // namespace

// No emitter a ray can hit (a point light's scene), no connection at maxDepth 1: they hide no error.
unsigned emptyStrategyClasses(const DiagnosisScene& sc) {
    unsigned empty = 0;
    for (int c = 0; c < kStrategyClassCount; ++c) {
        const auto s = sc.strategyShares.find(strategyClassName(StrategyClass(c)));
        if (s != sc.strategyShares.end() && s->second < kEmptyClassShare) empty |= strategyClassBit(StrategyClass(c));
    }
    return empty;
}

ClassObservation observeClasses(const DiagnosisScene& sc) {
    ClassObservation o;
    unsigned tested = 0, cleared = 0;
    for (const DiagnosisClassLayer& cl : sc.classLayers) {
        const DiagnosisLayer& l = cl.layer;
        if (!l.tested) continue;
        const unsigned bit = strategyClassBit(cl.strategyClass);
        tested |= bit;
        if (!l.consistent) o.failing |= bit;
        const DiagnosisLayer* err = errorAtDepth(sc, l.depth);
        const double ratio = err ? err->ratio : sc.depths.empty() ? sc.ratio : 1.0;
        if (ratio != 1.0 && (ratio < l.low || ratio > l.high)) cleared |= bit;
    }
    o.clearing = cleared & ~o.failing;
    // Only where the port's class layers were compared: a class nobody compared is no evidence.
    const unsigned empty = tested ? emptyStrategyClasses(sc) & ~tested : 0u;
    const std::string emptyWords = empty ? classNames(empty) + " empty in this scene" : "";
    if (o.failing) o.words = "the unweighted " + classNames(o.failing) + " strategies fail";
    else if (o.clearing)
        o.words = "no strategy class fails (" + classNames(o.clearing) + " too precise to hide the error" +
                  (empty ? "; " + emptyWords + ")" : ")");
    else if (empty) o.words = "no strategy class fails (" + emptyWords + ")";
    o.clearing |= empty;
    return o;
}

// When none fails, a term all of whose classes cleared cannot explain the scene, and a term that
// moves none (the MIS weights) explains it when every class cleared: a class the suite does not
// compare on the scene may carry the error. Only the classes the port's estimator samples count
// (a path tracer's emitter hits and next events).
double strategyClassWeight(const Term& t, PortEstimator e, const ClassObservation& c) {
    const unsigned sampled = strategyClassesOfEstimator(e);
    const unsigned moves = strategyClassesOf(t) & sampled, failing = c.failing & sampled, clearing = c.clearing & sampled;
    if (failing) {
        if ((failing & ~moves) != 0) return kClassAgainst;
        return moves != sampled ? kClassMatch : 0.0;  // a term that moves every class: no evidence
    }
    if (moves == 0) return clearing == sampled ? kClassMatch : 0.0;
    return (moves & ~clearing) == 0 ? kClassAgainst : 0.0;
}

}  // namespace bdptref
