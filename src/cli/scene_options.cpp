#include "cli/scene_options.h"

#include "bdptref/errors.h"
#include "bdptref/bdptref.h"
#include "bdptref/gltf_loader.h"

#include <sstream>

namespace bdptref::cli {

namespace {
// 0 stands for "not given" inside (SceneReference): an explicit 0 is refused here.
std::string positivePixels(const std::string& v) {
    try {
        if (std::stoll(v) >= 1) return "";
    } catch (const std::exception&) {
    }
    return "must be a positive number of pixels, got '" + v + "'";
}
}  // namespace

void addSceneOptions(CLI::App& app, SceneOptions& o) {
    app.add_option("scene", o.scenePath, "glTF 2.0 scene (.gltf or .glb)")->required();
    app.add_option("--width", o.width,
                   "image width in pixels (default: from the camera's aspect ratio with --height, else 256 for the longer side)")
        ->check(positivePixels);
    app.add_option("--height", o.height, "image height in pixels (default: like --width)")->check(positivePixels);
    app.add_option("--camera", o.camera,
                   "camera of the file to render: its index in traversal order (as `info` lists them) or its node's or camera's name");
    app.add_option("--env", o.env, "constant environment radiance R,G,B (e.g. 1,1,1); default none");
    app.add_option("--env-map", o.envMap,
                   "equirectangular environment map (EXR or Radiance .hdr; top row = +Y, centre column = +X; docs/lights.md)");
    app.add_option("--env-scale", o.envScale, "multiplies the --env-map radiance (default 1)");
    app.add_option("--env-rotate", o.envRotate, "turns the --env-map about the up axis +Y by DEGREES (right-handed; default 0)");
    app.add_option("--camera-pos", o.cameraPos, "camera position x,y,z (replaces the scene's camera)");
    app.add_option("--camera-target", o.cameraTarget, "point the camera looks at x,y,z (with --camera-pos)");
    app.add_option("--camera-up", o.cameraUp, "camera up vector x,y,z (default 0,1,0)");
    app.add_option("--fov", o.fovDegrees, "vertical field of view in degrees (default: the scene camera's, else 45)");
}

Vec3 parseVec3(const std::string& text, const std::string& option) { return parseVec3Option(text, option); }

Scene loadScene(const SceneOptions& o) {
    // One loader for the CLI and the library (src/api/api_scene.cpp): the same checks and messages.
    SceneReference ref;
    ref.file = o.scenePath;
    ref.width = o.width;
    ref.height = o.height;
    ref.env = o.env;
    ref.envMap = o.envMap;
    ref.envScale = o.envScale;
    ref.envRotate = o.envRotate;
    ref.camera = o.camera;
    ref.cameraPos = o.cameraPos;
    ref.cameraTarget = o.cameraTarget;
    ref.cameraUp = o.cameraUp;
    ref.fov = o.fovDegrees;
    return loadSceneFile(ref);
}

}  // namespace bdptref::cli
