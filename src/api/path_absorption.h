// What a path JSON recorded about volume absorption, against the scene (api_path_absorption.cpp):
// used by misWeightsOfPath* (api_mis.cpp) beside pathAbsorption (bdptref.h).
#pragma once

#include "bdptref/bdptref.h"

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace bdptref {

// Reads the "transmittance" of each vertex of `path` (that of the segment reaching it) into the
// matching entry of `segments` (pathAbsorption of the same path), and appends a warning for each
// recorded value the scene does not give: one that differs, one on a segment the scene does not
// absorb, or one that is not three numbers.
void compareRecordedTransmittance(const nlohmann::ordered_json& path, std::vector<SegmentAbsorption>& segments,
                                  std::vector<std::string>* warnings);

}  // namespace bdptref
