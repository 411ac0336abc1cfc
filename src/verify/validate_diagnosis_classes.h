// What a failing scene's strategy classes say about a term (docs/diagnosis.md, "Strategy
// classes"): which classes fail, which clear (too precise to hide the port's error, or empty in
// the scene), and the weight that adds to a term's score.
#pragma once

#include <string>

#include "verify/validate_diagnosis.h"

namespace bdptref {

struct ClassObservation {
    unsigned failing = 0;   // strategyClassBit of the classes with an inconsistent layer
    unsigned clearing = 0;  // ... of those without, one of whose layers rules out the port's error there,
                            // or not compared and empty in the scene (emptyStrategyClasses)
    std::string words;      // as the evidence says it
};

ClassObservation observeClasses(const DiagnosisScene& sc);

// The classes whose weighted share of the scene's image is nil (SuiteScene::strategyShares).
unsigned emptyStrategyClasses(const DiagnosisScene& sc);

// kClassMatch, kClassAgainst or 0: the classes that fail should be among those the term moves.
double strategyClassWeight(const Term& t, PortEstimator e, const ClassObservation& c);

}  // namespace bdptref
