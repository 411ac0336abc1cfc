// glTF 2.0 (.gltf, .glb) -> Scene. Everything the file says that would change the picture is
// either implemented or an InputError naming the file and the problem; see docs/scenes.md.
#pragma once

#include "bdptref/scene.h"

#include <string>

namespace bdptref {

struct LoadOptions {
    int width = 256, height = 256;  // image size for the camera's aspect ratio
};

// Loads the geometry, materials, textures, punctual lights and camera (the first perspective
// camera node; else a default camera framing the bounds, recorded in info.cameraSource).
// Does NOT call finalize(), so the caller can still add an environment or replace the camera.
Scene loadGltfScene(const std::string& path, const LoadOptions& options);

}  // namespace bdptref
