// The hard cases of the numerical-stability suite (issue 8): small glTF scenes built in code,
// each aimed at one way a renderer's numbers go wrong (docs/hard-cases.md has the table).
#pragma once

#include "bdptref/scene.h"

#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace bdptref::test {

struct HardCase {
    std::string name;
    // Builds the scene (camera set, finalized) at the given resolution.
    std::function<Scene(int width, int height)> build;
    int maxDepth = 6;
    // Estimators whose image must converge to the reference: compared per pixel and by the image
    // mean. Names are those of the estimator list in test_hard_cases.cpp.
    std::vector<std::string> converging;
    // The reference image: this estimator on `referenceBuild` (or on `build` when unset).
    std::string reference = "path";
    std::function<Scene(int width, int height)> referenceBuild;
    // Samples per pixel of the reference render (0: `spp`, and the reference is the estimator's
    // own render). More where the reference estimator is heavy-tailed at `spp` (docs/hard-cases.md).
    int referenceSpp = 0;
    // Estimators compared with the reference on direct lighting only (both rendered at max depth
    // 1): their deeper paths are heavy-tailed on this scene, so a per-pixel comparison at full
    // depth would test the sample count, not the estimator (docs/hard-cases.md).
    std::vector<std::string> convergingDirectLighting;
    // Known expected value of every pixel (all channels), when the scene has a closed form.
    std::optional<double> analyticPixel;
    // Estimators whose image must be exactly zero everywhere (they cannot sample any light path).
    std::vector<std::string> exactlyBlack;
    int spp = 64;  // for the image-producing renders (scaled down under sanitizers)
    int size = 16;  // image width = height
};

std::vector<HardCase> hardCases();

// The case whose layered (sheen under clearcoat) surfaces coincide and touch; test_hard_cases.cpp
// also builds exactly coincident path vertices on its scene.
inline const char* const kLayeredCoincidentCase = "sheen under clearcoat on coincident and touching geometry";

}  // namespace bdptref::test
