// Encodes an OpenEXR file (one part, or several: OpenEXR multi-part) into memory with OpenEXR
// itself, so that a write error cannot hide in a library that writes to the path directly.
// The bytes then go to writeOutputBytes (core/output_file.h), which checks every write.
#pragma once

#include "bdptref/exr_io.h"

#include <cstdint>
#include <string>
#include <vector>

namespace bdptref {

// One part: its data window (x, y, width, height) inside a display window at 0,0 of
// fullWidth x fullHeight, its channels (FLOAT or UINT, 4 bytes each), its name (empty: none in a
// single-part file, "image"/"partK" in a multi-part one) and its attributes.
struct ExrPartSpec {
    int x = 0, y = 0, width = 0, height = 0;
    int fullWidth = 0, fullHeight = 0;
    struct Channel {
        std::string name;
        bool isUint = false;  // Imf::UINT, else Imf::FLOAT
    };
    std::vector<Channel> channels;
    std::string name;
    bool compress = true;         // ZIP, else none
    bool chromaticities = false;  // linear Rec.709 primaries, D65 white (exr_encode.cpp)
    ExrMetadata metadata;         // STRING, INT and FLOAT attributes, in this order
};

struct ExrPart {
    ExrPartSpec spec;
    const void* pixels;  // interleaved, 4 bytes per channel, rows of the data window
};

std::vector<char> encodeExr(const std::vector<ExrPart>& parts);

// writeFilmExr and writeLayersExr (exr_io.h) with the choice of compression: ZIP (theirs), or none,
// for files read once by a program (`render --exr-compression none`: validate's renders with
// strategy layers, where ZIP took half the time of a 5-spp render; docs/validate.md).
void writeFilmExr(const std::string& path, const Film& film, const ExrMetadata& metadata, bool lightLayer, bool compress);
void writeLayersExr(const std::string& path, int width, int height, const std::vector<ExrLayer>& layers,
                    const ExrMetadata& metadata, const std::vector<ExrUintLayer>& uintLayers, const FilmWindow& window,
                    bool compress);

}  // namespace bdptref
