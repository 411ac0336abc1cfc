// Exact merge of images rendered as separate sample ranges of the same settings
// (`render --sample-range A:B` on many machines, then `bdptref merge`). The parts' double sums,
// sums of squares, light sums and uint64 counts are added in the order of their first sample
// index, so the result does not depend on the order the parts are given in, and equals a single
// render of the union to double precision (the sums differ only by summation order: at most
// 2 (n - 1) u sum|x| for n passes, u = 2^-53; the counts are exact).
#pragma once

#include "bdptref/checkpoint.h"

#include <map>
#include <string>
#include <vector>

namespace bdptref {

struct MergeOptions {
    bool allowGaps = false;  // accept parts whose sample ranges leave holes between them
};

struct MergedFilm {
    Film film;
    bool lightLayer = false;
    ExrMetadata metadata;               // the first part's (by sample index), to be updated by the caller
    std::vector<std::string> warnings;  // e.g. parts made by different bdptref revisions
    std::vector<size_t> order;          // indices of the parts in the order they were added
};

// Throws InputError naming the parts when they differ in scene hash, settings, size, strategy or
// depth layers or light layer, when their sample ranges overlap, or (unless allowGaps) leave a gap.
MergedFilm mergeFilms(const std::vector<FilmFile>& parts, const MergeOptions& options = {});

// The "key=value" lines of a settings text (kAttrSettings) as a map.
std::map<std::string, std::string> parseSettingsText(const std::string& text);

// The "key=value" lines of two settings texts (kAttrSettings) that differ, for error messages:
// "maxDepth: 5 vs 6; seed: 0 vs 1".
std::string describeSettingsDifference(const std::string& a, const std::string& b);

}  // namespace bdptref
