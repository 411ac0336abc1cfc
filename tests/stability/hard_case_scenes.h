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
    // Known expected value of every pixel (all channels), when the scene has a closed form.
    std::optional<double> analyticPixel;
    // Estimators whose image must be exactly zero everywhere (they cannot sample any light path).
    std::vector<std::string> exactlyBlack;
    int spp = 64;  // for the image-producing renders (scaled down under sanitizers)
    int size = 16;  // image width = height
};

std::vector<HardCase> hardCases();

}  // namespace bdptref::test
