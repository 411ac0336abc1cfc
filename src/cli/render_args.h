// The options of `bdptref render` (src/cli/cmd_render.cpp), shared with the code that fills them
// from a checkpoint's header (render_resume.cpp).
#pragma once

#include "cli/scene_options.h"

#include <set>
#include <string>

namespace bdptref::cli {

struct RenderArgs {
    SceneOptions scene;
    std::string output, preview;
    bool noPreview = false, quiet = false;
    int spp = 16, maxDepth = 64, threads = 0;
    long long seed = 0;
    std::string integrator = "path";
    std::string mis = "balance";
    double misBeta = 2.0;
    bool strategies = false;
    bool depthLayers = false;  // per-depth layers depth<d>.* (every integrator)
    std::string exrCompression = "zip";  // --exr-compression zip|none
    std::string lightSampler = "power";  // --light-sampler power|tree (docs/lights.md, "Light tree")
    bool strict = false;  // non-finite samples make the run fail (exit kExitNonFinite)
    bool strictScene = false;  // a scene feature that is ignored (SceneInfo::ignoredFeatures) is an error
    std::string crop;
    // Ground-truth production (docs/ground-truth.md).
    bool sppGiven = false;
    double timeBudget = 0, checkpointEvery = 0;
    std::string resume, sampleRange, statsPath;
    std::string requestedFromHeader;  // --resume without --spp/--sample-range: the header's "A:B" or "A:"
    // GPU-style wavefront schedule (docs/wavefront.md).
    std::string mode = "megakernel", gpuReport;
    int wavefrontPool = 0;
    // The options given on the command line, by their long name ("--max-depth"; "scene" for the
    // positional): --resume takes every other setting from the checkpoint's header.
    std::set<std::string> given;
    bool has(const std::string& option) const { return given.count(option) != 0; }
};

}  // namespace bdptref::cli
