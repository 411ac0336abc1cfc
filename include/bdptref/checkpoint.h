// A film saved with its exact state: every EXR that `bdptref render` writes (checkpoint, final or
// interrupted image, `merge` output) carries, next to the float beauty and variance layers, the
// film's double sums, sums of squares, light sums and uint64 counts bit for bit (each 64-bit value
// as two UINT channels `exact.<name>.hi` / `.lo`; strategy and depth layers too) and the sample ranges it
// holds. Reading it back gives the same Film, so a resumed render continues exactly where the
// interrupted one stopped and parts merge exactly. Layout: docs/exr.md.
#pragma once

#include "bdptref/exr_io.h"
#include "bdptref/film.h"

#include <map>
#include <string>

namespace bdptref {

// Header attributes that describe the exact state (besides the exact.* channels).
inline constexpr const char* kAttrExactFormat = "bdptref:exact.format";          // "1"
inline constexpr const char* kAttrSampleRanges = "bdptref:sampleRanges";         // SampleRanges::text()
inline constexpr const char* kAttrExactNonFinite = "bdptref:exact.nonFiniteSamples";
inline constexpr const char* kAttrExactStrategyDepth = "bdptref:exact.strategyMaxDepth";  // -1: none
inline constexpr const char* kAttrExactStrategyPasses = "bdptref:exact.strategyPasses";
// Non-finite strategy-layer values so far (absent in files written before it existed: read as 0).
inline constexpr const char* kAttrExactLayerNonFinite = "bdptref:exact.nonFiniteLayerValues";
inline constexpr const char* kAttrExactLight = "bdptref:exact.lightLayer";        // "1" or "0"
// Per-depth layers (`render --depth-layers`): written only when the film has them (absent: none).
inline constexpr const char* kAttrExactDepthMaxDepth = "bdptref:exact.depthLayersMaxDepth";
inline constexpr const char* kAttrExactDepthPasses = "bdptref:exact.depthLayersPasses";
inline constexpr const char* kAttrExactDepthNonFinite = "bdptref:exact.depthLayersNonFinite";
// Every setting that decides the pixels (scene hash, size, camera, environment, integrator, MIS,
// depth, seed, crop, strategy layers), as "key=value" lines: resume and merge refuse files whose
// settings differ. Written by `render` (src/cli/render_settings.cpp).
inline constexpr const char* kAttrSettings = "bdptref:settings";

struct FilmFile {
    std::string path;
    Film film;
    bool lightLayer = false;                        // the light.* layer (lt, bdpt) was written
    std::map<std::string, std::string> attributes;  // every header attribute, as text
    ExrMetadata metadata;  // the bdptref:* attributes with their types, except the exact-state ones
    std::string attribute(const std::string& name) const {
        const auto it = attributes.find(name);
        return it == attributes.end() ? std::string() : it->second;
    }
};

// Reads a film written by writeFilmExr bit for bit. Throws InputError naming the file when it
// cannot be read or holds no (or inconsistent) exact state.
FilmFile readFilmExr(const std::string& path);

}  // namespace bdptref
