// The readers behind readImage (exr_io.h), chosen by the file's first bytes, so that reading an
// EXR or a Radiance .hdr never loads OpenImageIO (which pulls ~260 shared libraries: OpenCV,
// GDAL, ffmpeg, ... and cost every command ~0.5 CPU-s of dynamic loading):
//   EXR                 OpenEXR (film/exr_read.h)
//   Radiance RGBE .hdr  stb_image (Debian's libstb, already loaded with tinygltf)
//   anything else       OpenImageIO, in the separately built module libbdptref_oiio.so,
//                       dlopen'ed on first use (image_module.cpp)
#pragma once

#include "bdptref/exr_io.h"

#include <string>

namespace bdptref {

bool hasRadianceMagic(const std::string& path);  // "#?RADIANCE" or "#?RGBE"
ExrImage readRadianceImage(const std::string& path);
ExrImage readImageWithModule(const std::string& path);

// The entry point the module exports (extern "C", built from src/image_module/oiio_read.cpp
// with the same compiler and headers). Returns false and sets *error on failure.
using ModuleReadFunction = bool (*)(const char* path, ExrImage* out, std::string* error);
inline constexpr const char* kModuleReadSymbol = "bdptref_module_read_image";
inline constexpr const char* kModuleFileName = "libbdptref_oiio.so";

}  // namespace bdptref
