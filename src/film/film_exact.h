// The exact state of a Film as EXR channels and attributes (written by writeFilmExr, read by
// readFilmExr in checkpoint.h). Format: docs/exr.md, "Exact state".
#pragma once

#include "bdptref/exr_io.h"
#include "bdptref/film.h"

#include <vector>

namespace bdptref {

std::vector<ExrUintLayer> exactChannels(const Film& film, bool lightLayer);
void appendExactAttributes(const Film& film, bool lightLayer, ExrMetadata& md);

}  // namespace bdptref
