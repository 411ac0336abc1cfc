// glTF 2.0 (.gltf, .glb) -> Scene. Everything the file says that would change the picture is
// either implemented or an InputError naming the file and the problem; see docs/scenes.md.
#pragma once

#include "bdptref/scene.h"

#include <string>

namespace bdptref {

struct LoadOptions {
    // Image size; 0 = follow the chosen camera's aspect ratio (docs/camera.md, "Image size"),
    // 256 for the longer side when neither is given.
    int width = 256, height = 256;
    // The camera node instance to render: its index in traversal order (as info.cameras lists
    // them) or its node's or camera's name; empty = the first. Unknown: InputError.
    std::string camera;
    // The caller replaces the camera (--camera-pos): no camera of the file is rendered, so none
    // can make the file fail (they are still listed and their problems warned about).
    bool cameraFromCommandLine = false;
};

// Loads the geometry, materials, textures, punctual lights and camera (the chosen camera node;
// else a default camera framing the bounds, recorded in info.cameraSource).
// Does NOT call finalize(), so the caller can still add an environment or replace the camera.
Scene loadGltfScene(const std::string& path, const LoadOptions& options);

}  // namespace bdptref
