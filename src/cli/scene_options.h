// Options shared by every subcommand that loads a scene (image size, camera override, environment).
#pragma once

#include "bdptref/scene.h"

#include <CLI/CLI.hpp>

#include <string>

namespace bdptref::cli {

struct SceneOptions {
    std::string scenePath;
    int width = 0, height = 0;  // 0 = not given: from the camera's aspect, else 256 (docs/camera.md)
    std::string camera;         // --camera N|NAME
    std::string env;           // "R,G,B"
    std::string envMap;        // --env-map FILE
    double envScale = 1.0, envRotate = 0.0;
    std::string cameraPos, cameraTarget, cameraUp = "0,1,0";
    double fovDegrees = 0;     // vertical; 0 = scene's
};

void addSceneOptions(CLI::App& app, SceneOptions& o);
// Loads, applies the command-line camera and environment, finalizes. Throws InputError.
Scene loadScene(const SceneOptions& o);
Vec3 parseVec3(const std::string& text, const std::string& option);

}  // namespace bdptref::cli
