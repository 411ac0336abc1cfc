// The path object of a "bdptref-path" file, or of one connection of a "bdptref-trace", as
// readPathFile (bdptref/path_io.h) selects it: for readers that need keys PathDescription does
// not keep (the recorded "transmittance" of `bdptref mis`, src/api/api_mis.cpp).
#pragma once

#include "bdptref/path_io.h"

#include <string>

namespace bdptref {

// Throws InputError as readPathFile does (missing file, malformed JSON, no such connection).
nlohmann::ordered_json readPathJson(const std::string& file, int s = -1, int t = -1);
// pathFromJson with the file named in its errors: readPathFile(file, s, t) is
// pathFromFileJson(readPathJson(file, s, t), file).
PathDescription pathFromFileJson(const nlohmann::ordered_json& path, const std::string& file);

}  // namespace bdptref
