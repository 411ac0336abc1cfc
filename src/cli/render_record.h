// What `render` records in the EXR header so that an image can be re-made from the header alone:
// the settings that decide the pixels (compared by --resume and `merge`) and a command line that
// reproduces the image. Attributes: docs/exr.md.
#pragma once

#include "bdptref/sample_range.h"

#include <cstdint>
#include <string>

namespace bdptref::cli {

struct ImageSettings {
    std::string scenePath, sceneHash;
    int width = 0, height = 0;
    std::string camera;                             // --camera N|NAME ("" = the file's first)
    std::string cameraPos, cameraTarget, cameraUp;  // canonical "x,y,z" ("" = the scene's camera)
    double fovDegrees = 0;                          // 0 = the scene camera's
    std::string env;                                // canonical "R,G,B" or ""
    std::string envMap;                             // --env-map FILE or ""
    double envScale = 1, envRotate = 0;             // with envMap only
    std::string integrator, mis;                    // mis: "none" for path and lt
    double misBeta = 2;
    int maxDepth = 0;
    uint32_t seed = 0;
    std::string crop;  // "x0,y0,x1,y1" or ""
    bool strategies = false;
    bool depthLayers = false;
    std::string lightSampler = "power";  // --light-sampler
};

// "key=value" lines, one per setting that decides the pixels (kAttrSettings). The scene path is
// not one of them (parts rendered on different machines have different paths): its hash is.
std::string settingsText(const ImageSettings& s);

// A `bdptref render` command that renders exactly these samples into `output`.
std::string reproduceCommand(const ImageSettings& s, const SampleRanges& samples, const std::string& output);

// Rewrites the --sample-range and -o of a command made by reproduceCommand for another set of
// samples and output (merge): one command per range, then the merge, when the ranges have gaps.
std::string retargetCommand(const std::string& command, const SampleRanges& samples, const std::string& output);

// The exact text of a number: %.17g.
std::string exactNumber(double v);
// Quotes for a POSIX shell when needed.
std::string shellQuote(const std::string& s);

}  // namespace bdptref::cli
