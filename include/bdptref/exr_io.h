// EXR output and input (OpenEXR; PNG previews with stb_image_write). Layers written by `render`:
//   R, G, B                        mean radiance per pixel (the beauty image)
//   variance.R, variance.G, variance.B   variance of that mean (s^2/n), per channel
//   count                           samples in the pixel
//   light.R, light.G, light.B        the light-tracing (splat) part of R,G,B (lt, bdpt)
//   s<S>t<T>.weighted.{R,G,B}, s<S>t<T>.unweighted.{R,G,B} and their .variance.{R,G,B}
//                                   per-strategy layers with --strategies (weighted ones sum to R,G,B)
// and, in a second part (subimage) named "exact" that viewers do not list as layers of the image:
//   exact.*.{hi,lo}                 the film's exact double/uint64 accumulators as pairs of UINT
//                                   channels (checkpoint.h): resume and merge read them bit for bit
// Header metadata: every render setting under "bdptref:*" (docs/exr.md) and `chromaticities`
// (linear Rec.709, D65). Every file is encoded in memory and written durably (core/output_file.h:
// temp file, checked writes, fsync, rename), so a reader never sees a partial file.
#pragma once

#include "bdptref/film.h"

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace bdptref {

// The name of the EXR part holding the exact state (written and read as subimage 1).
inline constexpr const char* kExactPartName = "exact";

struct ExrMetadata {
    std::vector<std::pair<std::string, std::string>> strings;
    std::vector<std::pair<std::string, int>> ints;
    std::vector<std::pair<std::string, float>> floats;
};

struct ExrLayer {
    std::string name;
    std::vector<float> pixels;  // width * height, row-major
};

struct ExrUintLayer {  // an EXR UINT (32-bit unsigned) channel
    std::string name;
    std::vector<uint32_t> pixels;  // width * height, row-major
};

// Writes the film's mean, variance of the mean and counts, plus its exact state (the exact.*
// channels and the film attributes of checkpoint.h), so the file is also a checkpoint that resume
// and merge read back bit for bit. Throws InputError if the file cannot be written.
void writeFilmExr(const std::string& path, const Film& film, const ExrMetadata& metadata, bool lightLayer = false);
// Writes named single-channel float layers (all width*height) as the first part and, if any,
// the UINT layers as a second part named kExactPartName. `window` (when its fullWidth > 0) places
// them as the data window inside a larger display window (a crop render).
void writeLayersExr(const std::string& path, int width, int height, const std::vector<ExrLayer>& layers,
                    const ExrMetadata& metadata, const std::vector<ExrUintLayer>& uintLayers = {},
                    const FilmWindow& window = {});
// Writes an 8-bit RGB PNG (rows top to bottom) durably (temp file, fsync, rename).
void writeRgb8Png(const std::string& path, int width, int height, const std::vector<uint8_t>& rgb);
// A tone-mapped (clamp, sRGB) 8-bit PNG of the film's mean.
void writePreviewPng(const std::string& path, const Film& film, float exposure = 1.f);

struct ExrImage {
    int width = 0, height = 0;  // of the data window: channels hold width * height values
    FilmWindow window;          // the data window inside the display window (full image)
    std::map<std::string, std::vector<float>> channels;
    std::map<std::string, std::string> attributes;  // every header attribute, printed as text
    bool has(const std::string& c) const { return channels.count(c) != 0; }
    float at(const std::string& c, int x, int y) const { return channels.at(c)[size_t(y) * size_t(width) + size_t(x)]; }
};
// Reads every channel of the first part (subimage 0) as float; throws InputError naming the file.
// EXR (any channel type, layout, compression) through OpenEXR, Radiance .hdr through stb_image;
// other formats (PNG, TIFF, PFM, ...) through OpenImageIO in the module libbdptref_oiio.so,
// loaded on first use from next to the binary, PREFIX/lib, or $BDPTREF_IMAGE_MODULE
// (src/film/image_read.h); without it such a read is an InputError saying so.
ExrImage readImage(const std::string& path);

// Fails early (before a long render) if `path` cannot be written: a folder, a missing folder, no
// permission (a probe file is created and removed next to it). Throws InputError.
void checkWritable(const std::string& path);

}  // namespace bdptref
