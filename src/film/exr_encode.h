// Encodes an OpenEXR file (one part, or several: OpenEXR multi-part) into memory with OpenEXR
// itself. OpenImageIO 2.4 cannot do this for multi-part files: given an IOProxy, its EXR writer
// ignores it and writes to the path directly, and it does not report a full disk there.
// The bytes then go to writeOutputBytes (core/output_file.h), which checks every write.
#pragma once

#include <OpenImageIO/imageio.h>

#include <vector>

namespace bdptref {

struct ExrPart {
    // Geometry (data window x, y, width, height; display window full_*), channel names and
    // formats (FLOAT or UINT), and attributes: STRING, INT, FLOAT, `chromaticities` (FLOAT[8]),
    // `compression` ("zip" or "none") and `oiio:subimagename` (the part's name).
    OIIO::ImageSpec spec;
    const void* pixels;  // interleaved, 4 bytes per channel, rows of the data window
};

std::vector<char> encodeExr(const std::vector<ExrPart>& parts);

}  // namespace bdptref
