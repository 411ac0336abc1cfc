// Ignored scene features: `render` records them in bdptref:ignoredFeatures, `info` lists them, and
// `render --strict-scene` refuses the scene (exit 2) instead of rendering without them.

#include "bdptref/exr_io.h"

#include "support/gltf_builder.h"
#include "support/render_util.h"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>

using namespace bdptref;
using namespace bdptref::test;
using json = nlohmann::json;

namespace {

// A lit triangle in front of a camera, plus a material extension the renderer does not implement
// (used, not required), so the file renders but something of it is left out.
std::string sceneWithIgnoredExtension() {
    Doc d;
    const int m = d.lambert({0.5, 0.5, 0.5}, {1, 1, 1});
    d.use("KHR_materials_iridescence");
    d.j["materials"][size_t(m)]["extensions"]["KHR_materials_iridescence"] = {{"iridescenceFactor", 1.0}};
    d.j["meshes"].push_back({{"primitives", json::array({Doc::prim(d.floats({-1, -1, 0, 1, -1, 0, 0, 1, 0}, "VEC3"), -1, -1, -1, 4, m)})}});
    d.node({{"mesh", int(d.j["meshes"].size()) - 1}});
    d.j["cameras"] = json::array({json{{"type", "perspective"}, {"perspective", {{"yfov", 1.0}, {"znear", 0.01}}}}});
    d.node({{"camera", 0}, {"translation", {0, 0, 3}}});
    return d.write("strict-iridescence.gltf");
}

}  // namespace

TEST_CASE("strict scene: ignored features are recorded, listed, and refused with --strict-scene", "[cli][gltf]") {
    const std::string dir = makeTempDir("strict-scene");
    const std::string scene = sceneWithIgnoredExtension();
    std::string out;
    REQUIRE(runCli("render " + scene + " -o " + dir + "/a.exr --width 8 --height 8 --spp 2 -q --no-preview", &out) == 0);
    CHECK(readImage(dir + "/a.exr").attributes.at("bdptref:ignoredFeatures") == "extension KHR_materials_iridescence");

    REQUIRE(runCli("info " + scene, &out) == 0);
    CHECK(out.find("ignored:      extension KHR_materials_iridescence") != std::string::npos);

    const int rc = runCli("render " + scene + " -o " + dir + "/b.exr --width 8 --height 8 --spp 2 -q --no-preview --strict-scene", &out);
    INFO(out);
    CHECK(rc == 2);
    CHECK(out.find("--strict-scene") != std::string::npos);
    CHECK(out.find("extension KHR_materials_iridescence") != std::string::npos);
    CHECK_FALSE(std::filesystem::exists(dir + "/b.exr"));

    // A scene with nothing ignored renders under --strict-scene and records "none".
    REQUIRE(runCli("render " + sourcePath("scenes/cornell-box.gltf") + " -o " + dir +
                       "/c.exr --width 8 --height 8 --spp 1 -q --no-preview --strict-scene",
                   &out) == 0);
    CHECK(readImage(dir + "/c.exr").attributes.at("bdptref:ignoredFeatures") == "none");
}
