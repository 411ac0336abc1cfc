// Bug signatures (docs/diagnosis.md, "Bug signatures"): what each known port bug of
// tools/port_bugs.py did to the conformance suite when the suite was made — which scenes it
// failed, by which ratio test / reference — shipped beside the suite (its "signatures" file) so that
// the diagnosis can say "this port fails like bug X, a wrong term T".
#pragma once

#include <string>
#include <vector>

namespace bdptref {

struct SignatureScene {
    std::string name;
    bool failed = false;
    double ratio = 1, low = 1, high = 1;  // the beauty's ratio test / reference and its 95% interval
    // A bidirectional port's strategy classes (docs/validate.md, "Strategy classes"), one bit per
    // StrategyClass: those compared with a verdict, and those of them with an inconsistent layer.
    unsigned testedClasses = 0, failedClasses = 0;
};

struct BugSignature {
    std::string bug;        // the bug's name in tools/port_bugs.py
    std::string term;       // the catalogue id it breaks
    std::string estimator;  // the port it played: path, light or bidirectional
    std::vector<SignatureScene> scenes;  // the scenes that had a verdict
};

// Reads a signatures file (JSON: {"signatures": [{"bug", "term", "estimator", "scenes": {name:
// {"failed", "ratio", "low", "high"[, "testedClasses": [...], "failedClasses": [...]]}}}]}). Throws
// InputError naming the file and the entry.
std::vector<BugSignature> loadSignatures(const std::string& path);

}  // namespace bdptref
