// A run's results against the suite's bug signatures (docs/diagnosis.md, "Bug signatures"): which
// known bug of a term the port fails like. The similarity of a run R and a signature S over the
// scenes both tested:
//   J = |F_R ∩ F_S| / |F_R ∪ F_S|                   (F: the failing scenes)
//   A = mean over F_R ∩ F_S of the ratios' agreement (sign and size: 0, 0.5 or 1), averaged with
//       the failing strategy classes' agreement where both compared classes (docs/diagnosis.md)
//   C = the share of the signature's failing scenes that the run tested
//   similarity = C J (1 + 3 A) / 4
// where the size agrees when the two ratios' intervals meet or their logs are within a factor 2.
// A signature measured with another estimator counts half.
#include "verify/validate_diagnosis.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

namespace bdptref {

namespace {

struct RunScene {
    bool failed;
    double ratio, low, high;
    unsigned testedClasses, failedClasses;  // strategyClassBit
};

double safeLog(double r) { return std::log(std::max(r, 1e-6)); }

// Sign and size of one scene failing in both: 0, 0.5 or 1.
double ratioAgreement(const RunScene& run, const SignatureScene& sig) {
    const double a = safeLog(run.ratio), b = safeLog(sig.ratio);
    if ((a > 0) != (b > 0)) return 0;
    const bool overlap = run.low <= sig.high && sig.low <= run.high;
    const double small = std::min(std::abs(a), std::abs(b)), large = std::max(std::abs(a), std::abs(b));
    return overlap || small >= 0.5 * large ? 1.0 : 0.5;
}

// The strategy classes both compared: the same failing ones 1, some failing in both 0.5, else 0;
// -1 when they compared none in common (no evidence).
double classAgreement(const RunScene& run, const SignatureScene& sig) {
    const unsigned both = run.testedClasses & sig.testedClasses;
    if (both == 0) return -1;
    const unsigned a = run.failedClasses & both, b = sig.failedClasses & both;
    return a == b ? 1.0 : (a & b) != 0 ? 0.5 : 0.0;
}

// A scene failing in both: its ratios' agreement, averaged with its strategy classes' where both have them.
double sceneAgreement(const RunScene& run, const SignatureScene& sig) {
    const double ratio = ratioAgreement(run, sig), classes = classAgreement(run, sig);
    return classes < 0 ? ratio : (ratio + classes) / 2;
}

double similarity(const std::map<std::string, RunScene>& run, const BugSignature& sig) {
    int both = 0, either = 0, sigFailed = 0, sigFailedTested = 0;
    double agree = 0;
    for (const SignatureScene& s : sig.scenes) {
        sigFailed += s.failed;
        const auto r = run.find(s.name);
        if (r == run.end()) continue;
        sigFailedTested += s.failed;
        if (r->second.failed || s.failed) ++either;
        if (r->second.failed && s.failed) ++both, agree += sceneAgreement(r->second, s);
    }
    if (both == 0) return 0;
    // Scenes the signature failed that the run did not test are no evidence either way: a run
    // that tests one of a broad bug's ten scenes resembles it less than one that tests all ten.
    const double coverage = double(sigFailedTested) / double(sigFailed);
    return coverage * double(both) / double(either) * (1 + 3 * agree / double(both)) / 4;
}

}  // namespace

SignatureMatch bestSignatureMatch(const DiagnosisInput& in, const std::string& term) {
    std::map<std::string, RunScene> run;
    for (const DiagnosisScene& s : in.scenes) {
        if (s.outcome == DiagnosisOutcome::Untested) continue;
        unsigned tested = 0, failed = 0;
        for (const DiagnosisClassLayer& c : s.classLayers)
            if (c.layer.tested) {
                tested |= strategyClassBit(c.strategyClass);
                if (!c.layer.consistent) failed |= strategyClassBit(c.strategyClass);
            }
        run[s.name] = {s.outcome == DiagnosisOutcome::Failed, s.ratio, s.low, s.high, tested, failed};
    }
    SignatureMatch best;
    for (const BugSignature& sig : in.signatures) {
        if (sig.term != term || sig.bug == in.leaveOut) continue;
        const double sameEstimator = sig.estimator == portEstimatorName(in.estimator) ? 1.0 : 0.5;
        const double s = sameEstimator * similarity(run, sig);
        if (s > best.similarity) {
            best.similarity = s, best.bug = sig.bug;
            char b[64];
            std::snprintf(b, sizeof b, "%.2f", s);
            best.words = "fails like the known bug " + sig.bug + " (a " + sig.estimator + " port; similarity " + b + ")";
        }
    }
    return best;
}

}  // namespace bdptref
