// --env-map files (docs/lights.md, "Environment"): a good EXR or Radiance .hdr file becomes the map
// texel for texel; every bad file is an InputError naming the file and the problem (missing, not
// an image, NaN / infinite / negative texels, black everywhere, wrong format), also through the
// command line (exit 2).
#include "support/render_util.h"

#include "bdptref/bdptref.h"
#include "bdptref/env_map.h"
#include "bdptref/errors.h"
#include "bdptref/exr_io.h"
#include "bdptref/path_io.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <fstream>
#include <limits>

using namespace bdptref;
using namespace bdptref::test;

namespace {

// Writes a w x h RGB EXR whose texel (x, y) is f(x, y).
template <class F>
std::string writeMap(const std::string& dir, const std::string& name, int w, int h, F f) {
    std::vector<ExrLayer> layers{{"R", {}}, {"G", {}}, {"B", {}}};
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const Rgb v = f(x, y);
            for (int k = 0; k < 3; ++k) layers[size_t(k)].pixels.push_back(v[k]);
        }
    const std::string path = dir + "/" + name;
    writeLayersExr(path, w, h, layers, ExrMetadata{});
    return path;
}

// A flat (not run-length encoded) Radiance RGBE file: each texel given as mantissas and exponent.
std::string writeHdr(const std::string& dir, int w, int h, const std::vector<std::array<uint8_t, 4>>& rgbe) {
    const std::string path = dir + "/map.hdr";
    std::ofstream f(path, std::ios::binary);
    f << "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y " << h << " +X " << w << "\n";
    for (const auto& p : rgbe) f.write(reinterpret_cast<const char*>(p.data()), 4);
    return path;
}

void requireInputError(const std::string& path, const std::string& expect) {
    try {
        loadEnvironmentMap(path, 0.f);
        FAIL("no InputError for " << path);
    } catch (const InputError& e) {
        const std::string m = e.what();
        INFO(m);
        CHECK(m.find(path) != std::string::npos);
        CHECK(m.find(expect) != std::string::npos);
    }
}

}  // namespace

TEST_CASE("Environment map file: an EXR is read texel for texel, top row first", "[envmap]") {
    const std::string dir = makeTempDir("envmap-read");
    const std::string path = writeMap(dir, "ok.exr", 8, 4, [](int x, int y) { return Rgb(float(x), float(y), 0.25f); });
    const EnvironmentMap m = loadEnvironmentMap(path, 90.f);
    REQUIRE(m.width() == 8);
    REQUIRE(m.height() == 4);
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 8; ++x) CHECK(m.texel(x, y) == Rgb(float(x), float(y), 0.25f));
    CHECK(m.rotation() == Approx(0.5 * 3.14159265358979323846));
    // Row 0 is the top of the image: straight up (+Y) finds it.
    CHECK(m.lookup(Vec3(0, 1, 0)).g == 0.f);
    CHECK(m.lookup(Vec3(0, -1, 0)).g == 3.f);
}

TEST_CASE("Environment map file: a Radiance .hdr is read", "[envmap]") {
    // RGBE (128, 64, 32, 129) = (128, 64, 32) / 256 * 2^(129-128) = (1, 0.5, 0.25); exponent 130: x2.
    const std::string dir = makeTempDir("envmap-hdr");
    std::vector<std::array<uint8_t, 4>> px;
    for (int i = 0; i < 8; ++i) px.push_back({128, 64, 32, uint8_t(i < 4 ? 129 : 130)});
    const std::string path = writeHdr(dir, 4, 2, px);
    const EnvironmentMap m = loadEnvironmentMap(path, 0.f);
    REQUIRE(m.width() == 4);
    REQUIRE(m.height() == 2);
    CHECK(m.texel(0, 0).r == Approx(1.0).epsilon(0.02));
    CHECK(m.texel(3, 0).g == Approx(0.5).epsilon(0.02));
    CHECK(m.texel(2, 1).b == Approx(0.5).epsilon(0.02));
    CHECK(m.texel(1, 1).r == Approx(2.0).epsilon(0.02));
}

TEST_CASE("Environment map file: bad files are input errors naming the file and the problem", "[envmap]") {
    const std::string dir = makeTempDir("envmap-bad");
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    requireInputError(dir + "/missing.exr", "no such file");
    requireInputError(writeMap(dir, "nan.exr", 4, 2, [&](int x, int y) { return Rgb(1.f, x == 2 && y == 1 ? nan : 1.f, 1.f); }),
                      "texel (2, 1) channel G is NaN");
    requireInputError(writeMap(dir, "inf.exr", 4, 2, [&](int x, int) { return Rgb(x == 3 ? inf : 1.f, 1.f, 1.f); }), "infinite");
    requireInputError(writeMap(dir, "neg.exr", 4, 2, [&](int x, int y) { return Rgb(1.f, 1.f, x == 0 && y == 0 ? -0.5f : 1.f); }),
                      "channel B is negative");
    requireInputError(writeMap(dir, "black.exr", 4, 2, [](int, int) { return Rgb(0.f); }), "every texel is black");
    {
        std::ofstream(dir + "/text.exr") << "this is not an image\n";
        requireInputError(dir + "/text.exr", "not a readable image");
        std::ofstream(dir + "/map.png") << "x";
        requireInputError(dir + "/map.png", "not an EXR or Radiance .hdr file");
        std::ofstream(dir + "/empty.hdr");
        requireInputError(dir + "/empty.hdr", "not a readable image");
    }
}

TEST_CASE("Environment map options: the command line refuses bad maps and bad combinations with exit 2", "[envmap][cli]") {
    const std::string dir = makeTempDir("envmap-cli");
    const std::string scene = sourcePath("scenes/cornell-box.gltf");
    const std::string good = writeMap(dir, "good.exr", 8, 4, [](int, int) { return Rgb(1.f); });
    const std::string black = writeMap(dir, "black.exr", 8, 4, [](int, int) { return Rgb(0.f); });
    const std::string out = " --spp 1 --width 8 --height 8 -o " + dir + "/o.exr";
    checkInputError("render " + scene + " --env-map " + dir + "/nope.exr" + out, dir + "/nope.exr: no such file");
    checkInputError("render " + scene + " --env-map " + black + out, "every texel is black");
    // The option combinations, through the loader the command line uses (faster than a process each).
    auto loadError = [&](SceneReference ref) -> std::string {
        ref.file = scene;
        ref.width = ref.height = 8;
        try {
            loadSceneFile(ref);
        } catch (const InputError& e) {
            return e.what();
        }
        return "no error";
    };
    SceneReference both;
    both.envMap = good;
    both.env = "1,1,1";
    CHECK_THAT(loadError(both), Catch::Contains("--env and --env-map cannot be combined"));
    SceneReference negative;
    negative.envMap = good;
    negative.envScale = -1.0;
    CHECK_THAT(loadError(negative), Catch::Contains("--env-scale: must be a finite number > 0"));
    SceneReference scaleOnly;
    scaleOnly.envScale = 2.0;
    CHECK_THAT(loadError(scaleOnly), Catch::Contains("--env-map, which is not given"));
    // Scale x brightest texel beyond the limit every light has (docs/lights.md, "Limits").
    SceneReference tooBright;
    tooBright.envMap = good;
    tooBright.envScale = 1e26;
    CHECK_THAT(loadError(tooBright), Catch::Contains("exceeds the renderer's limit of 1e25"));
    SceneReference rotateOnly;
    rotateOnly.envRotate = 10.0;
    CHECK_THAT(loadError(rotateOnly), Catch::Contains("--env-map, which is not given"));
    // A good map renders (exit 0) and the header says which environment lit the image.
    std::string log;
    REQUIRE(runCli("render " + scene + " --env-map " + good + " --env-scale 0.5 --env-rotate 30" + out, &log) == 0);
    const ExrImage img = readImage(dir + "/o.exr");
    REQUIRE(img.attributes.count("bdptref:environment"));
    CHECK(img.attributes.at("bdptref:environment") == "map " + good);
}

TEST_CASE("Environment map options: --resume renders with the header's map, scale and rotation", "[envmap][cli]") {
    // The settings record the map (envMap, envScale, envRotate): a resumed render continues with
    // them (the same pixels as one uninterrupted render), and a conflicting option is refused.
    const std::string dir = makeTempDir("envmap-resume");
    const std::string scene = sourcePath("scenes/env-map-outdoor.gltf"), map = sourcePath("scenes/env-map-sky.hdr");
    const std::string common = scene + " --env-map " + map + " --env-scale 0.5 --env-rotate 30 --width 12 --height 12";
    REQUIRE(runCli("render " + common + " --spp 2 -o " + dir + "/a.exr") == 0);
    REQUIRE(runCli("render --resume " + dir + "/a.exr --spp 4 -o " + dir + "/b.exr") == 0);
    REQUIRE(runCli("render " + common + " --spp 4 -o " + dir + "/c.exr") == 0);
    const ExrImage b = readImage(dir + "/b.exr"), c = readImage(dir + "/c.exr");
    for (const char* ch : {"R", "G", "B"}) {
        REQUIRE(b.has(ch));
        CHECK(b.channels.at(ch) == c.channels.at(ch));
    }
    double sum = 0.0;
    for (float v : b.channels.at("G")) sum += double(v);
    CHECK(sum > 0.0);  // lit by the map
    checkInputError("render --resume " + dir + "/a.exr --env-rotate 10 --spp 4 -o " + dir + "/d.exr", "--env-rotate conflicts with the checkpoint");
}

TEST_CASE("Environment map options: the map's bytes are part of the scene hash, so another map is refused", "[envmap][cli]") {
    // A checkpoint or a part rendered with one map must not be continued or merged with another
    // file of the same name: the header's sceneHash covers the map's content (docs/scenes.md).
    const std::string dir = makeTempDir("envmap-hash");
    const std::string scene = sourcePath("scenes/env-map-outdoor.gltf");
    const std::string map = writeMap(dir, "sky.exr", 8, 4, [](int x, int y) { return Rgb(1.f + float(x), 2.f, 0.5f + float(y)); });
    const std::string common = scene + " --env-map " + map + " --width 8 --height 8 -q --no-preview";
    REQUIRE(runCli("render " + common + " --spp 2 -o " + dir + "/a.exr") == 0);
    REQUIRE(runCli("render " + common + " --sample-range 2:4 -o " + dir + "/p2.exr") == 0);
    const std::string hashA = readImage(dir + "/a.exr").attributes.at("bdptref:sceneHash");
    const std::string plain = loadSceneFile(scene, 8, 8).info.contentHash;
    CHECK(hashA.size() == 16);
    CHECK(hashA != plain);  // the map joined the hash

    // The same name, one texel changed: another hash, and --resume and merge refuse it.
    writeMap(dir, "sky.exr", 8, 4, [](int x, int y) { return Rgb(1.f + float(x), x == 3 && y == 1 ? 2.5f : 2.f, 0.5f + float(y)); });
    REQUIRE(runCli("render " + common + " --sample-range 4:6 -o " + dir + "/p3.exr") == 0);
    const std::string hashB = readImage(dir + "/p3.exr").attributes.at("bdptref:sceneHash");
    CHECK(hashB != hashA);
    CHECK(hashB != plain);
    checkInputError("render --resume " + dir + "/a.exr --spp 4 -o " + dir + "/b.exr", "sceneHash");
    checkInputError("merge " + dir + "/a.exr " + dir + "/p3.exr -o " + dir + "/m.exr", "another scene");
    // The unchanged parts still merge (the check is on content, not on names).
    writeMap(dir, "sky.exr", 8, 4, [](int x, int y) { return Rgb(1.f + float(x), 2.f, 0.5f + float(y)); });
    CHECK(runCli("merge " + dir + "/a.exr " + dir + "/p2.exr -o " + dir + "/m.exr -q") == 0);
    SceneReference ref;
    ref.file = scene;
    ref.width = ref.height = 8;
    ref.envMap = map;
    CHECK(loadSceneFile(ref).info.contentHash == hashA);  // the library's loader hashes the same way
}
