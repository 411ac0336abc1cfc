// Scene loading for library users (bdptref.h): the options of `bdptref render/trace/mis` as a
// SceneReference, with the CLI's checks and messages (src/cli/scene_options.cpp).
#include "bdptref/bdptref.h"
#include "bdptref/errors.h"

#include "core/fnv1a64.h"

#include <cmath>
#include <fstream>
#include <iterator>
#include <sstream>

namespace bdptref {

Vec3 parseVec3Option(const std::string& text, const std::string& option) {
    std::stringstream ss(text);
    Vec3 v;
    char c1 = 0, c2 = 0;
    const bool parsed = bool(ss >> v.x >> c1 >> v.y >> c2 >> v.z);
    ss >> std::ws;
    if (!parsed || !ss.eof() || c1 != ',' || c2 != ',' || !isFinite(v))
        throw InputError(option + ": expected three finite numbers 'x,y,z', got '" + text + "'");
    return v;
}

LibraryVersion libraryVersion() {
    LibraryVersion v;
    v.text = BDPTREF_VERSION;
    v.gitRevision = BDPTREF_GIT_REVISION;
    char dot = 0;
    std::stringstream(v.text) >> v.major >> dot >> v.minor >> dot >> v.patch;
    return v;
}

namespace {
// The hash of `hash` (a hex string) followed by the bytes of `file` (already read successfully).
std::string contentHashWithFile(const std::string& hash, const std::string& file) {
    std::ifstream in(file, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (!in.good() && !in.eof()) throw InputError(file + ": cannot be read again to hash it");
    Fnv1a64 h;
    h.add(hash);
    h.add(bytes);
    return h.hex();
}
}  // namespace

Scene loadSceneFile(const SceneReference& o) {
    constexpr int kMaxSize = 65536;
    // 0 = not given: the side follows the chosen camera's aspect (docs/camera.md, "Image size").
    if (o.width < 0 || o.height < 0 || o.width > kMaxSize || o.height > kMaxSize ||
        double(o.width) * double(o.height) > 512.0 * 1024 * 1024)
        throw InputError("--width/--height: image size " + std::to_string(o.width) + "x" + std::to_string(o.height) +
                         " is out of range (1..65536 per side, at most 512 Mpixels)");
    if (o.fov != 0 && !(o.fov > 0 && o.fov < 180)) throw InputError("--fov: must be between 0 and 180 degrees");
    const bool commandLineCamera = !o.cameraPos.empty() || !o.cameraTarget.empty();
    if (commandLineCamera && !o.camera.empty())
        throw InputError("--camera selects a camera of the file; it cannot be combined with --camera-pos/--camera-target");
    LoadOptions lo;
    lo.width = o.width;
    lo.height = o.height;
    lo.camera = o.camera;
    lo.cameraFromCommandLine = commandLineCamera;
    Scene scene = loadGltfScene(o.file, lo);  // the camera has the resolved image size
    const int width = scene.camera.width(), height = scene.camera.height();
    if (double(width) * double(height) > 512.0 * 1024 * 1024)
        throw InputError("image size " + std::to_string(width) + "x" + std::to_string(height) + " (from the camera's aspect) is over 512 Mpixels");
    if (commandLineCamera) {
        if (o.cameraPos.empty() || o.cameraTarget.empty())
            throw InputError("--camera-pos and --camera-target must be given together");
        const Vec3 eye = parseVec3Option(o.cameraPos, "--camera-pos"), target = parseVec3Option(o.cameraTarget, "--camera-target");
        const Vec3 up = parseVec3Option(o.cameraUp.empty() ? "0,1,0" : o.cameraUp, "--camera-up");
        if (glm::length(target - eye) == 0.f || glm::length(glm::cross(target - eye, up)) == 0.f)
            throw InputError("--camera-pos/--camera-target/--camera-up: the view direction is zero or parallel to up");
        const float fov = float((o.fov > 0 ? o.fov : 45.0) * kPi / 180.0);
        scene.camera = Camera::lookAt(eye, target, up, fov, width, height);
        scene.info.cameraSource = "command line";
    } else if (o.fov > 0) {
        const Camera& c = scene.camera;
        if (c.isOrthographic())
            throw InputError("--fov: the chosen camera is orthographic (it has no field of view)");
        scene.camera = Camera::lookAt(c.position(), c.position() + c.forward(), c.up(), float(o.fov * kPi / 180.0),
                                      width, height);
    }
    if (!o.envMap.empty()) {
        if (!o.env.empty()) throw InputError("--env and --env-map cannot be combined (scale a map with --env-scale)");
        if (!(std::isfinite(o.envScale) && o.envScale > 0 && o.envScale <= 1e30))
            throw InputError("--env-scale: must be a finite number > 0, got " + std::to_string(o.envScale));
        if (!std::isfinite(o.envRotate)) throw InputError("--env-rotate: must be a finite number of degrees");
        scene.setEnvironmentMap(loadEnvironmentMap(o.envMap, float(o.envRotate)), float(o.envScale),
                                "the environment map " + o.envMap + " (--env-map)");
        // The map lights the scene like a file the scene loads: its bytes join the content hash,
        // so that a header's sceneHash (merge, --resume, `mis`) tells another map from this one.
        scene.info.contentHash = contentHashWithFile(scene.info.contentHash, o.envMap);
    } else if (o.envScale != 1.0 || o.envRotate != 0.0) {
        throw InputError("--env-scale and --env-rotate apply to --env-map, which is not given");
    }
    if (!o.env.empty()) {
        const Vec3 L = parseVec3Option(o.env, "--env");
        if (L.x < 0 || L.y < 0 || L.z < 0) throw InputError("--env: radiance must be non-negative, got '" + o.env + "'");
        scene.setEnvironment(L);
    }
    scene.finalize();
    applyCropWindow(scene, o.crop);
    return scene;
}

Scene loadSceneFile(const std::string& file, int width, int height) {
    SceneReference ref;
    ref.file = file;
    ref.width = width;
    ref.height = height;
    return loadSceneFile(ref);
}

}  // namespace bdptref
