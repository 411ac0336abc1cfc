#include "cli/scene_options.h"

#include "bdptref/errors.h"
#include "bdptref/gltf_loader.h"

#include <sstream>

namespace bdptref::cli {

void addSceneOptions(CLI::App& app, SceneOptions& o) {
    app.add_option("scene", o.scenePath, "glTF 2.0 scene (.gltf or .glb)")->required();
    app.add_option("--width", o.width, "image width in pixels (default 256)");
    app.add_option("--height", o.height, "image height in pixels (default 256)");
    app.add_option("--env", o.env, "constant environment radiance R,G,B (e.g. 1,1,1); default none");
    app.add_option("--camera-pos", o.cameraPos, "camera position x,y,z (replaces the scene's camera)");
    app.add_option("--camera-target", o.cameraTarget, "point the camera looks at x,y,z (with --camera-pos)");
    app.add_option("--camera-up", o.cameraUp, "camera up vector x,y,z (default 0,1,0)");
    app.add_option("--fov", o.fovDegrees, "vertical field of view in degrees (default: the scene camera's, else 45)");
}

Vec3 parseVec3(const std::string& text, const std::string& option) {
    std::stringstream ss(text);
    Vec3 v;
    char c1 = 0, c2 = 0;
    const bool parsed = bool(ss >> v.x >> c1 >> v.y >> c2 >> v.z);
    ss >> std::ws;
    if (!parsed || !ss.eof() || c1 != ',' || c2 != ',' || !isFinite(v))
        throw InputError(option + ": expected three finite numbers 'x,y,z', got '" + text + "'");
    return v;
}

Scene loadScene(const SceneOptions& o) {
    constexpr int kMaxSize = 65536;
    if (o.width < 1 || o.height < 1 || o.width > kMaxSize || o.height > kMaxSize ||
        double(o.width) * double(o.height) > 512.0 * 1024 * 1024)
        throw InputError("--width/--height: image size " + std::to_string(o.width) + "x" + std::to_string(o.height) +
                         " is out of range (1..65536 per side, at most 512 Mpixels)");
    if (o.fovDegrees != 0 && !(o.fovDegrees > 0 && o.fovDegrees < 180))
        throw InputError("--fov: must be between 0 and 180 degrees");
    LoadOptions lo;
    lo.width = o.width;
    lo.height = o.height;
    Scene scene = loadGltfScene(o.scenePath, lo);
    scene.camera = scene.camera.withResolution(o.width, o.height);
    if (!o.cameraPos.empty() || !o.cameraTarget.empty()) {
        if (o.cameraPos.empty() || o.cameraTarget.empty())
            throw InputError("--camera-pos and --camera-target must be given together");
        const Vec3 eye = parseVec3(o.cameraPos, "--camera-pos"), target = parseVec3(o.cameraTarget, "--camera-target");
        const Vec3 up = parseVec3(o.cameraUp, "--camera-up");
        if (glm::length(target - eye) == 0.f || glm::length(glm::cross(target - eye, up)) == 0.f)
            throw InputError("--camera-pos/--camera-target/--camera-up: the view direction is zero or parallel to up");
        const float fov = float((o.fovDegrees > 0 ? o.fovDegrees : 45.0) * kPi / 180.0);
        scene.camera = Camera::lookAt(eye, target, up, fov, o.width, o.height);
        scene.info.cameraSource = "command line";
    } else if (o.fovDegrees > 0) {
        const Camera& c = scene.camera;
        scene.camera = Camera::lookAt(c.position(), c.position() + c.forward(), c.up(), float(o.fovDegrees * kPi / 180.0),
                                      o.width, o.height);
    }
    if (!o.env.empty()) {
        const Vec3 L = parseVec3(o.env, "--env");
        if (L.x < 0 || L.y < 0 || L.z < 0) throw InputError("--env: radiance must be non-negative, got '" + o.env + "'");
        scene.setEnvironment(L);
    }
    scene.finalize();
    return scene;
}

}  // namespace bdptref::cli
