// Reads OpenEXR files with OpenEXR itself (single- and multi-part, scanline or tiled, HALF, FLOAT
// and UINT channels, every compression OpenEXR knows). readImage (exr_io.h) and readFilmExr
// (checkpoint.h) read through this, so neither needs OpenImageIO.
#pragma once

#include "bdptref/exr_io.h"

#include <OpenEXR/ImfForward.h>

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace bdptref {

// True if the file starts with the OpenEXR magic number (76 2f 31 01).
bool hasExrMagic(const std::string& path);

struct ExrPartInfo {
    std::string name;                  // the part's name ("" if the file has none)
    int x = 0, y = 0, width = 0, height = 0;  // data window
    int fullX = 0, fullY = 0, fullWidth = 0, fullHeight = 0;  // display window
    std::vector<std::string> channels;        // sorted, as OpenEXR lists them
    std::vector<bool> channelIsUint;          // per channel: UINT (else HALF or FLOAT)
    // Every attribute except the windows and the channel list, as text, under the names
    // OpenImageIO gave them (compression, PixelAspectRatio, oiio:subimagename, ...; user
    // attributes under their own name): what readImage reported before it read through OpenEXR.
    std::map<std::string, std::string> attributes;
    ExrMetadata typed;  // the STRING, INT and FLOAT user attributes with their types
    FilmWindow window() const { return {fullWidth, fullHeight, x - fullX, y - fullY, width, height}; }
};

class ExrReader {
public:
    explicit ExrReader(const std::string& path);  // throws InputError naming the file
    ~ExrReader();
    int parts() const { return int(parts_.size()); }
    const ExrPartInfo& part(int k) const { return parts_.at(size_t(k)); }
    // Every channel of part k as float: HALF and FLOAT exactly, UINT as v / (2^32 - 1) (as
    // OpenImageIO normalised it).
    std::map<std::string, std::vector<float>> readFloat(int k);
    // The named UINT channels of part k, bit for bit.
    std::map<std::string, std::vector<uint32_t>> readUint(int k, const std::vector<std::string>& names);

private:
    std::string path_;
    std::unique_ptr<Imf::MultiPartInputFile> file_;
    std::vector<ExrPartInfo> parts_;
};

// readImage for an EXR: the first part.
ExrImage readExrImage(const std::string& path);

}  // namespace bdptref
