// Choosing the camera of a glTF file (docs/camera.md, "Choosing a camera", "Image size"): every
// camera node instance is listed, only the rendered one can make the file fail, `--camera N|NAME`
// picks one, and the image aspect follows the chosen camera unless both sides are given.
#include "bdptref/bdptref.h"
#include "bdptref/errors.h"
#include "bdptref/gltf_loader.h"

#include "support/gltf_builder.h"
#include "support/render_util.h"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <string>

using namespace bdptref;
using namespace bdptref::test;
using json = nlohmann::json;

namespace {

constexpr double kS = 0.70710678118654752;

// A triangle, a perspective camera 'persp' (yfov 0.8, aspect 2) on node 'front', an orthographic
// camera 'ortho' (xmag 1, ymag 0.5) on node 'top', and a camera with an invalid yfov on node 'bad'.
std::string threeCameras(const std::string& name, bool withBad = true) {
    Doc d;
    d.triangleNode();
    json cams = json::array({json{{"name", "persp"}, {"type", "perspective"},
                                  {"perspective", {{"yfov", 0.8}, {"aspectRatio", 2.0}, {"znear", 0.1}}}},
                             json{{"name", "ortho"}, {"type", "orthographic"},
                                  {"orthographic", {{"xmag", 1.0}, {"ymag", 0.5}, {"znear", 0.1}, {"zfar", 100.0}}}}});
    if (withBad) cams.push_back(json{{"name", "broken"}, {"type", "perspective"}, {"perspective", {{"yfov", 4.0}, {"znear", 0.1}}}});
    d.j["cameras"] = cams;
    d.node({{"name", "front"}, {"camera", 0}, {"translation", {0, 0, 5}}});
    d.node({{"name", "top"}, {"camera", 1}, {"translation", {0, 5, 0}}, {"rotation", {-kS, 0, 0, kS}}});
    if (withBad) d.node({{"name", "bad"}, {"camera", 2}, {"translation", {0, 0, 9}}});
    return d.write(name);
}

Scene loadWith(const std::string& path, const std::string& camera, int w = 0, int h = 0) {
    SceneReference ref;
    ref.file = path;
    ref.camera = camera;
    ref.width = w;
    ref.height = h;
    return loadSceneFile(ref);
}

std::string inputErrorOf(const std::string& path, const std::string& camera, int w = 0, int h = 0) {
    try {
        (void)loadWith(path, camera, w, h);
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

bool hasWarning(const Scene& s, const std::string& phrase) {
    for (const std::string& w : s.info.warnings)
        if (w.find(phrase) != std::string::npos) return true;
    return false;
}

}  // namespace

TEST_CASE("camera choice: every camera node is listed, unused invalid cameras only warn", "[camera][gltf]") {
    const std::string path = threeCameras("three-cameras.gltf");
    const Scene s = loadWith(path, "");
    REQUIRE(s.info.cameras.size() == 3);
    CHECK(s.info.cameraUsed == 0);
    CHECK(s.info.cameras[0].nodeName == "front");
    CHECK(s.info.cameras[1].type == "orthographic");
    CHECK(s.info.cameras[1].xmag == 1.0);
    CHECK(s.info.cameras[2].problem.find("yfov") != std::string::npos);
    CHECK(s.info.cameras[0].problem.empty());
    CHECK(hasWarning(s, "cannot be rendered"));
    CHECK(hasWarning(s, "the first in traversal order is used"));
    CHECK_FALSE(s.camera.isOrthographic());
}

TEST_CASE("camera choice: --camera by index and by node or camera name", "[camera][gltf]") {
    const std::string path = threeCameras("choose.gltf");
    const Scene byIndex = loadWith(path, "1");
    CHECK(byIndex.info.cameraUsed == 1);
    CHECK(byIndex.camera.isOrthographic());
    CHECK(byIndex.camera.forward().y == Approx(-1.f).margin(1e-6));  // node 'top' looks down
    CHECK(loadWith(path, "top").info.cameraUsed == 1);    // node name
    CHECK(loadWith(path, "ortho").info.cameraUsed == 1);  // camera name
    CHECK(loadWith(path, "persp").info.cameraUsed == 0);
    // Unknown: an InputError listing what there is.
    const std::string unknown = inputErrorOf(path, "side");
    INFO(unknown);
    CHECK(unknown.find("no camera node or camera is called that") != std::string::npos);
    CHECK(unknown.find("1: node 2 'top', camera 1 'ortho' (orthographic)") != std::string::npos);
    CHECK(inputErrorOf(path, "7").find("there is no camera 7") != std::string::npos);
    // The invalid camera, chosen: refused with its problem.
    CHECK(inputErrorOf(path, "bad").find("is not in (0, pi)") != std::string::npos);
}

TEST_CASE("camera choice: an invalid first camera refuses the file unless --camera-pos replaces it", "[camera][gltf]") {
    Doc d;
    d.triangleNode();
    d.j["cameras"] = json::array({json{{"type", "orthographic"}, {"orthographic", {{"xmag", 0}, {"ymag", 1}, {"znear", 0.1}, {"zfar", 9}}}}});
    d.node({{"camera", 0}, {"translation", {0, 0, 5}}});
    const std::string path = d.write("bad-first.gltf");
    CHECK(inputErrorOf(path, "").find("must be positive and finite") != std::string::npos);
    SceneReference ref;
    ref.file = path;
    ref.cameraPos = "0,0,5";
    ref.cameraTarget = "0,0,0";
    const Scene s = loadSceneFile(ref);
    CHECK(s.info.cameraSource == "command line");
    CHECK(hasWarning(s, "cannot be rendered"));
    // --camera and --camera-pos together: refused.
    ref.camera = "0";
    CHECK_THROWS_AS(loadSceneFile(ref), InputError);
}

TEST_CASE("camera choice: the image aspect follows the chosen camera unless both sides are given", "[camera][gltf]") {
    const std::string path = threeCameras("aspect.gltf", false);
    // Perspective, aspectRatio 2: the longer side is 256 by default; one side given: the other follows.
    const Scene p = loadWith(path, "0");
    CHECK(p.camera.width() == 256);
    CHECK(p.camera.height() == 128);
    const Scene pw = loadWith(path, "0", 100, 0);
    CHECK(pw.camera.height() == 50);
    const Scene ph = loadWith(path, "0", 0, 30);
    CHECK(ph.camera.width() == 60);
    // Orthographic, xmag/ymag = 2.
    const Scene o = loadWith(path, "1", 0, 64);
    CHECK(o.camera.width() == 128);
    CHECK(o.camera.xmag() == Approx(1.0));
    CHECK(o.camera.ymag() == Approx(0.5));
    // Both given: the vertical extent is kept, with a warning.
    const Scene both = loadWith(path, "0", 64, 64);
    CHECK(both.camera.width() == 64);
    CHECK(both.camera.yfov() == Approx(0.8));
    CHECK(hasWarning(both, "the vertical field of view is kept"));
    const Scene bothOrtho = loadWith(path, "1", 64, 64);
    CHECK(bothOrtho.camera.ymag() == Approx(0.5));
    CHECK(bothOrtho.camera.xmag() == Approx(0.5));
    CHECK(hasWarning(bothOrtho, "ymag"));
    // An extreme aspectRatio with one side given: refused, not an absurd image.
    Doc wide;
    wide.triangleNode();
    wide.j["cameras"] = json::array({json{{"type", "perspective"}, {"perspective", {{"yfov", 0.5}, {"aspectRatio", 1e6}, {"znear", 0.1}}}}});
    wide.node({{"camera", 0}, {"translation", {0, 0, 5}}});
    CHECK(inputErrorOf(wide.write("wide.gltf"), "", 0, 1000).find("out of range") != std::string::npos);
    // No aspectRatio and no camera: 256 x 256 as before.
    Doc d;
    d.triangleNode();
    const Scene def = loadWith(d.write("no-camera-aspect.gltf"), "");
    CHECK(def.camera.width() == 256);
    CHECK(def.camera.height() == 256);
}

TEST_CASE("camera choice: bdptref info lists the cameras and render follows --camera and its aspect", "[camera][cli]") {
    const std::string path = threeCameras("cli-cameras.gltf");
    std::string out;
    REQUIRE(runCli("info " + path + " --camera top", &out) == 0);
    INFO(out);
    CHECK(out.find("cameras:      3 in the file") != std::string::npos);
    CHECK(out.find("[1] node 2 'top', camera 1 'ortho': orthographic, xmag 1, ymag 0.5  <- used") != std::string::npos);
    CHECK(out.find("cannot be rendered") != std::string::npos);  // camera 2, listed with its problem
    checkInputError("info " + path + " --camera nope", "no camera node or camera is called that");
    checkInputError("render " + path + " --camera bad -o x.exr", "is not in (0, pi)");
    checkInputError("render " + path + " --camera 0 --camera-pos 0,0,5 --camera-target 0,0,0 -o x.exr", "cannot be combined");
    // The orthographic camera's xmag/ymag = 2 gives a 16 x 8 image from --height 8 (light tracing
    // through it: docs/camera.md).
    const std::string dir = makeTempDir("camera-choice");
    REQUIRE(runCli("render " + path + " --camera 1 --height 8 --spp 1 --integrator lt --env 1,1,1 -q --no-preview -o " + dir +
                       "/o.exr",
                   &out) == 0);
    REQUIRE(runCli("info " + path + " --camera 1 --height 8", &out) == 0);
    CHECK(out.find("16x8") != std::string::npos);
}
