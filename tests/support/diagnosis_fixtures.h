// Synthetic per-scene results over the shipped suite's `terms` for the diagnosis's tests
// (test_validate_diagnosis.cpp, test_validate_strategy_classes.cpp): no renders.
#pragma once

#include "support/render_util.h"
#include "verify/validate_diagnosis.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <sstream>
#include <string>

namespace bdptref::test {

inline const Suite& shippedSuite() {
    static const Suite suite = loadSuite(sourcePath("scenes/conformance/suite.json"));
    return suite;
}

inline const SuiteScene& suiteScene(const std::string& name) {
    for (const SuiteScene& s : shippedSuite().scenes)
        if (s.name == name) return s;
    FAIL("no scene " << name << " in the shipped suite");
    throw 0;
}

inline bool renders(const SuiteScene& s, PortEstimator e) {
    return std::find(s.estimators.begin(), s.estimators.end(), e) != s.estimators.end();
}

// A layer or beauty whose ratio is known to +-`relHalf` (95%), consistent when that holds 1.
inline DiagnosisLayer layerAt(int depth, double ratio, double relHalf) {
    DiagnosisLayer l;
    l.depth = depth;
    l.tested = true;
    l.ratio = ratio;
    l.low = ratio * (1 - relHalf);
    l.high = ratio * (1 + relHalf);
    l.consistent = l.low <= 1 && l.high >= 1;
    return l;
}

// A scene's result whose depth d has ratio `atDepth(d)` (depth 0 untested where nothing is seen
// directly) and whose beauty has ratio `beauty`; its outcome is the beauty's.
inline DiagnosisScene result(const SuiteScene& s, double beauty, const std::function<double(int)>& atDepth,
                             bool depth0Tested = true) {
    DiagnosisScene d;
    d.name = s.name;
    d.terms = s.terms;
    d.ior = s.ior;
    d.lightShares = s.lightShares;
    d.strategyShares = s.strategyShares;
    d.emitterShares = s.emitterShares;
    d.maxDepth = s.maxDepth;
    const DiagnosisLayer b = layerAt(-1, beauty, 0.01);
    d.ratio = b.ratio, d.low = b.low, d.high = b.high;
    d.outcome = b.consistent ? DiagnosisOutcome::Passed : DiagnosisOutcome::Failed;
    for (int k = 0; k <= s.maxDepth; ++k) {
        if (k == 0 && !depth0Tested) {
            d.depths.push_back(DiagnosisLayer{});  // tested = false
            continue;
        }
        d.depths.push_back(layerAt(k, atDepth(k), 0.02 * (1 + k / 4.0)));  // deep layers are noisier
    }
    return d;
}

inline DiagnosisScene passing(const SuiteScene& s) {
    return result(s, 1.0, [](int) { return 1.0; });
}

// A failing scene off by r from depth 1 (depth 0 right), its image mean by r too, +-meanHalfWidth.
inline DiagnosisScene fromDepth1WithMean(const SuiteScene& s, double r, double meanHalfWidth) {
    DiagnosisScene d = result(s, r, [r](int k) { return k == 0 ? 1.0 : r; });
    d.hasMean = true, d.meanRatio = r, d.meanLow = r - meanHalfWidth, d.meanHigh = r + meanHalfWidth;
    return d;
}

// Every scene of the suite the estimator renders: `failures` gives the failing ones, the others pass.
inline DiagnosisInput run(PortEstimator e,
                          const std::map<std::string, std::function<DiagnosisScene(const SuiteScene&)>>& failures,
                          bool othersRun = true) {
    DiagnosisInput in;
    in.estimator = e;
    for (const SuiteScene& s : shippedSuite().scenes) {
        if (!renders(s, e)) continue;
        const auto f = failures.find(s.name);
        if (f != failures.end()) in.scenes.push_back(f->second(s));
        else if (othersRun) in.scenes.push_back(passing(s));
    }
    return in;
}

// The score and evidence of `term` in the ranking of `in` (score NaN and no evidence when it is
// not a candidate).
inline DiagnosisEntry entryOf(DiagnosisInput in, const std::string& term) {
    in.top = 1000;
    for (DiagnosisEntry& e : diagnose(in))
        if (e.term == term) return e;
    return {term, 0, std::nan(""), ""};
}

inline std::string ranking(const std::vector<DiagnosisEntry>& d) {
    std::ostringstream s;
    for (const DiagnosisEntry& e : d) s << e.term << " " << e.confidence << " (" << e.score << "): " << e.evidence << "\n";
    return s.str();
}

}  // namespace bdptref::test
