// Reading and checking an environment map file (--env-map): every problem is an InputError that
// names the file, so a bad map never renders as a silently different picture.
#include "bdptref/env_map.h"
#include "bdptref/errors.h"
#include "bdptref/exr_io.h"

#include <cmath>
#include <fstream>

namespace bdptref {

namespace {

std::string lowerExtension(const std::string& path) {
    const size_t dot = path.find_last_of('.');
    const size_t slash = path.find_last_of("/\\");
    if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
    std::string e = path.substr(dot + 1);
    for (char& c : e) c = char(std::tolower(static_cast<unsigned char>(c)));
    return e;
}

const char* problemOf(float x) {
    if (std::isnan(x)) return "NaN";
    if (std::isinf(x)) return "infinite";
    if (x < 0.f) return "negative";
    return nullptr;
}

}  // namespace

EnvironmentMap loadEnvironmentMap(const std::string& path, float rotationDegrees) {
    const std::string who = "environment map " + path;
    if (!std::ifstream(path, std::ios::binary).good()) throw InputError(who + ": no such file (or it cannot be opened)");
    const std::string ext = lowerExtension(path);
    if (ext != "exr" && ext != "hdr")
        throw InputError(who + ": not an EXR or Radiance .hdr file (an equirectangular HDR image is needed)");
    if (!std::isfinite(rotationDegrees)) throw InputError(who + ": --env-rotate must be a finite number of degrees");
    ExrImage img;
    try {
        img = readImage(path);
    } catch (const InputError& e) {
        throw InputError(who + ": not a readable image (" + e.what() + ")");
    }
    if (img.width <= 0 || img.height <= 0) throw InputError(who + ": the image has zero size");
    // The map and its sampling tables take about 24 bytes per texel: 2^27 texels (16384 x 8192)
    // is over 3 GB already.
    if (double(img.width) * double(img.height) > double(1 << 27))
        throw InputError(who + ": " + std::to_string(img.width) + "x" + std::to_string(img.height) +
                         " texels is more than the 2^27 (e.g. 16384x8192) an environment map may have");
    std::vector<const std::vector<float>*> ch;
    if (img.has("R") && img.has("G") && img.has("B")) {
        ch = {&img.channels.at("R"), &img.channels.at("G"), &img.channels.at("B")};
    } else if (img.channels.size() == 1 || img.has("Y")) {
        const std::vector<float>* grey = img.has("Y") ? &img.channels.at("Y") : &img.channels.begin()->second;
        ch = {grey, grey, grey};
    } else {
        throw InputError(who + ": needs channels R, G, B (or a single grey channel)");
    }
    const size_t n = size_t(img.width) * size_t(img.height);
    std::vector<Rgb> texels(n);
    bool anyLight = false;
    for (size_t i = 0; i < n; ++i) {
        for (int k = 0; k < 3; ++k) {
            const float x = (*ch[size_t(k)])[i];
            if (const char* p = problemOf(x))
                throw InputError(who + ": texel (" + std::to_string(i % size_t(img.width)) + ", " + std::to_string(i / size_t(img.width)) +
                                 ") channel " + "RGB"[k] + " is " + p + " (radiance must be finite and >= 0)");
            texels[i][k] = x;
        }
        anyLight = anyLight || !isBlack(texels[i]);
    }
    if (!anyLight) throw InputError(who + ": every texel is black, the map emits nothing (leave out --env-map for no environment)");
    const float rotation = float(double(rotationDegrees) * 3.14159265358979323846 / 180.0);
    return EnvironmentMap(img.width, img.height, std::move(texels), rotation);
}

}  // namespace bdptref
