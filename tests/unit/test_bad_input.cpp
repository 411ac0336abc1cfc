// Malformed input, end to end through the real `bdptref` binary (issue 8): every row of the table
// in docs/errors.md is one case here. Each must exit with code 2 (input error), print a message
// that names the file or option and the problem, not crash, and write no output file. The scene
// files are built with the shared glTF builder (tests/support/gltf_builder.h); the library-level
// loader tests (test_gltf_loader.cpp) check the same messages one level down.
#include "support/gltf_builder.h"
#include "support/render_util.h"

#include <catch2/catch.hpp>

#include <filesystem>
#include <limits>
#include <string>
#include <vector>

using namespace bdptref::test;

namespace {

struct BadInput {
    std::string what;     // the row's name in docs/errors.md
    std::string args;     // after "bdptref"
    std::string names;    // the message must contain this (the file or the option) ...
    std::string problem;  // ... and this (the problem)
};

// A valid one-triangle scene with an emissive material, for the CLI-value cases.
Doc litTriangle() {
    Doc d;
    d.triangleNode();
    d.j["meshes"][0]["primitives"][0]["material"] = d.lambert({0.5, 0.5, 0.5}, {1, 1, 1});
    return d;
}

std::vector<BadInput> badInputs(const std::string& dir) {
    const std::string out = " -o " + dir + "/out.exr --spp 1 --width 8 --height 8 -q";
    auto render = [&](const std::string& scene) { return "render " + scene + out; };
    std::vector<BadInput> cases;
    auto add = [&](const std::string& what, const std::string& scene, const std::string& problem) {
        cases.push_back({what, render(scene), scene, problem});
    };
    {
        Doc d = litTriangle();
        const std::string text = d.finished().dump();
        add("truncated JSON", writeFile("truncated.gltf", text.substr(0, text.size() / 2)), "glTF parse error");
    }
    {
        Doc d = litTriangle();
        d.j["accessors"][0]["componentType"] = kU16;
        add("POSITION accessor of the wrong component type", d.write("pos-type.gltf"), "expected FLOAT");
    }
    {
        Doc d = litTriangle();
        d.j["accessors"][0]["type"] = "VEC2";
        add("POSITION accessor of the wrong type", d.write("pos-vec2.gltf"), "has type VEC2; expected VEC3");
    }
    {
        Doc d = litTriangle();
        d.j["accessors"][0]["count"] = 4;
        add("accessor count larger than its bufferView", d.write("acc-count.gltf"), "reads past the end of bufferView 0");
    }
    {
        Doc d = litTriangle();
        d.j["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = 99;
        add("accessor index out of range", d.write("acc-range.gltf"), "accessor 99 (POSITION) does not exist");
    }
    {
        Doc d;
        const int pos = d.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3");
        d.node({{"mesh", d.mesh(Doc::prim(pos, d.indices<uint16_t>({0, 1, 7})))}});
        add("vertex index out of range", d.write("index-range.gltf"), "index 7 at position 2 is out of range");
    }
    {
        Doc d;
        const int pos = d.floats({0, 0, 0, 1, std::numeric_limits<float>::quiet_NaN(), 0, 0, 1, 0}, "VEC3");
        d.node({{"mesh", d.mesh(Doc::prim(pos))}});
        add("NaN vertex position", d.write("nan-position.gltf"), "vertex 1 is not finite");
    }
    {
        Doc d;
        const int pos = d.floats({0, 0, 0, 1, 0, 0, 0, std::numeric_limits<float>::infinity(), 0}, "VEC3");
        d.node({{"mesh", d.mesh(Doc::prim(pos))}});
        add("Inf vertex position", d.write("inf-position.gltf"), "vertex 2 is not finite");
    }
    {
        Doc d = litTriangle();
        json j = d.finished();
        j["buffers"][0]["uri"] = "missing-buffer.bin";
        add("missing external buffer", writeFile("missing-buffer.gltf", j.dump()), "missing-buffer.bin");
    }
    {
        Doc d = litTriangle();
        d.j["bufferViews"][0]["byteLength"] = 4000;
        add("buffer shorter than its bufferViews", d.write("short-buffer.gltf"), "extends past the end of buffer 0");
    }
    {
        Doc d = litTriangle();
        d.use("EXT_unknown_feature", true);
        add("unknown extension in extensionsRequired", d.write("required-ext.gltf"), "extension 'EXT_unknown_feature' is required");
    }
    {
        Doc d = litTriangle();
        d.j["materials"][0]["emissiveFactor"] = {1, -0.5, 1};
        add("negative emission", d.write("negative-emission.gltf"), "is negative");
    }
    {   // A base-colour texture whose image file does not exist.
        Doc d = litTriangle();
        d.j["images"] = json::array({json{{"uri", "missing-texture.png"}}});
        d.j["textures"] = json::array({json{{"source", 0}}});
        d.j["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
        d.j["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = d.floats({0, 0, 1, 0, 0, 1}, "VEC2");
        add("missing image file", d.write("missing-image.gltf"), "missing-texture.png");
    }
    {   // A PNG cut short in the middle of its pixel data.
        std::vector<unsigned char> png = makePng(4, 4, 3, 8, std::vector<uint16_t>(48, 128));
        png.resize(png.size() / 2);
        writeFile("short.png", png);
        Doc d = litTriangle();
        d.j["images"] = json::array({json{{"uri", "short.png"}}});
        d.j["textures"] = json::array({json{{"source", 0}}});
        d.j["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
        d.j["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = d.floats({0, 0, 1, 0, 0, 1}, "VEC2");
        add("truncated image file", d.write("short-image.gltf"), "short.png");
    }
    {   // A PNG whose header claims 100000 x 100000 pixels (40 GB decoded) over a few bytes of data.
        std::vector<unsigned char> png = makePng(1, 1, 3, 8, {1, 2, 3});
        for (int k = 0; k < 2; ++k) {  // IHDR width and height, then fix the chunk CRC
            const uint32_t v = 100000;
            for (int b = 0; b < 4; ++b) png[size_t(16 + 4 * k + b)] = (unsigned char)(v >> (24 - 8 * b));
        }
        const uint32_t crc = crc32(png.data() + 12, 17);
        for (int b = 0; b < 4; ++b) png[size_t(29 + b)] = (unsigned char)(crc >> (24 - 8 * b));
        writeFile("huge.png", png);
        Doc d = litTriangle();
        d.j["images"] = json::array({json{{"uri", "huge.png"}}});
        d.j["textures"] = json::array({json{{"source", 0}}});
        d.j["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
        d.j["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = d.floats({0, 0, 1, 0, 0, 1}, "VEC2");
        add("absurd image size in a texture", d.write("huge-image.gltf"), "huge.png");
    }
    {
        Doc d = litTriangle();
        const int a = 0;
        d.j["nodes"][size_t(a)]["children"] = {a};
        add("node graph with a cycle", d.write("cycle.gltf"), "is its own child");
    }
    {
        std::vector<unsigned char> glb = {'g', 'l', 'T', 'F', 2, 0, 0, 0, 200, 0, 0, 0, 100, 0, 0, 0, 'J', 'S', 'O', 'N', '{'};
        const std::string p = writeFile("truncated.glb", glb);
        add("truncated GLB", p, "Invalid glTF binary");
    }
    // Invalid command-line values and outputs: the message names the option (or the output path).
    const std::string scene = litTriangle().write("lit.gltf");
    auto cli = [&](const std::string& what, const std::string& extra, const std::string& names, const std::string& problem) {
        cases.push_back({what, "render " + scene + " -o " + dir + "/out.exr -q " + extra, names, problem});
    };
    cli("absurd image size on the command line", "--width 100000 --height 100000", "--width", "out of range");
    cli("non-numeric --spp", "--spp abc", "--spp", "abc");
    cli("--mis-beta out of range", "--integrator bdpt --mis-beta 0", "--mis-beta", "(0, 16]");
    cli("unknown --mis heuristic", "--integrator bdpt --mis magic", "magic", "magic");
    cli("empty --crop window", "--crop 5,5,1,1", "--crop", "x0 < x1");
    cli("negative --threads", "--threads -1", "--threads", ">= 0");
    cases.push_back({"output into a missing folder", "render " + scene + " -o " + dir + "/no/such/folder/out.exr -q",
                     dir + "/no/such/folder/out.exr", "cannot write"});
    cases.push_back({"output path is a directory", "render " + scene + " -o " + dir + " -q", dir, "is a directory"});
    cases.push_back({"output on a read-only file system", "render " + scene + " -o /proc/bdptref-out.exr -q",
                     "/proc/bdptref-out.exr", "cannot write"});
    return cases;
}

}  // namespace

TEST_CASE("Bad input: every malformed input of docs/errors.md exits 2 naming the file and the problem", "[cli][errors][bad-input]") {
    const std::string dir = makeTempDir("bad-input");
    const std::vector<BadInput> cases = badInputs(dir);
    CHECK(cases.size() >= 15);
    for (const BadInput& c : cases) {
        std::string out;
        const int rc = runCli(c.args, &out);
        INFO(c.what << "\n  bdptref " << c.args << "\n" << out);
        CHECK(rc == 2);
        CHECK(out.find(c.names) != std::string::npos);
        CHECK(out.find(c.problem) != std::string::npos);
        CHECK(out.find("internal error") == std::string::npos);
    }
    // Nothing was written for any of them.
    CHECK_FALSE(std::filesystem::exists(dir + "/out.exr"));
    CHECK_FALSE(std::filesystem::exists(dir + "/out.png"));
}
