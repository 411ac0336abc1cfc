// Textures through the glTF loader (src/scene/gltf_materials.cpp, docs/materials.md "Textures"):
// KHR_texture_transform lands texels where the extension says, its texCoord override, sampler
// validation, and the transmission / specular textures. Every expected texel is derived by hand
// in the comments (not by re-running the loader's formula).

#include "bdptref/errors.h"
#include "bdptref/gltf_loader.h"
#include "bdptref/material.h"

#include "support/gltf_builder.h"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <cmath>
#include <string>
#include <vector>

using bdptref::InputError;
using bdptref::Scene;
using bdptref::Vec2;
using json = nlohmann::json;
using namespace bdptref::test;

namespace {

constexpr double kPi = 3.14159265358979323846;

Scene load(const std::string& path) {
    bdptref::LoadOptions o;
    o.width = o.height = 16;
    return bdptref::loadGltfScene(path, o);
}

void requireInputError(const std::string& path, const std::string& phrase) {
    INFO("file: " << path << "\nexpected phrase: " << phrase);
    try {
        (void)load(path);
        FAIL("no InputError was thrown");
    } catch (const InputError& e) {
        const std::string msg = e.what();
        INFO("message: " << msg);
        CHECK(msg.find(path) != std::string::npos);
        CHECK(msg.find(phrase) != std::string::npos);
    }
}

// A 4x4 linear (metallic-roughness) image, nearest filtered, whose texel (i, j) has
// G = 40 j + 20 and B = 40 i + 20: roughness and metallic then name the texel that was read.
// One triangle with uv (0,0), (1,0), (0,1), so barycentrics (b1, b2) are uv = (b1, b2); a second
// set TEXCOORD_1 = uv / 4 + (0.5, 0.5) for the texCoord override.
Doc indexTextureDoc(const json& textureInfo, const char* wrap = nullptr) {
    Doc d;
    std::vector<uint16_t> px;
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) px.insert(px.end(), {0, uint16_t(40 * j + 20), uint16_t(40 * i + 20)});
    d.j["images"] = json::array({json{{"uri", "data:image/png;base64," + base64(makePng(4, 4, 3, 8, px))}}});
    json sampler = {{"magFilter", 9728}};
    if (wrap) sampler["wrapS"] = sampler["wrapT"] = 33071;  // CLAMP_TO_EDGE
    d.j["samplers"] = json::array({sampler});
    d.j["textures"] = json::array({json{{"source", 0}, {"sampler", 0}}});
    const int mat = d.material({{"pbrMetallicRoughness", {{"metallicRoughnessTexture", textureInfo}}}});
    const int pos = d.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3");
    const int uv0 = d.floats({0, 0, 1, 0, 0, 1}, "VEC2");
    const int uv1 = d.floats({0.5f, 0.5f, 0.75f, 0.5f, 0.5f, 0.75f}, "VEC2");
    json prim = Doc::prim(pos, -1, -1, uv0, 4, mat);
    prim["attributes"]["TEXCOORD_1"] = uv1;
    d.node({{"mesh", d.mesh(prim)}});
    d.use("KHR_texture_transform");
    return d;
}

// The texel (i, j) the material reads at surface uv (u, v) (= barycentrics (u, v)).
std::pair<int, int> texelAt(const Scene& s, float u, float v) {
    const bdptref::MaterialParams p = s.materialParams(0, 0, Vec2(u, v));
    const double i = (p.metallic * 255.0 - 20.0) / 40.0, j = (p.roughness * 255.0 - 20.0) / 40.0;
    INFO("uv " << u << "," << v << ": metallic " << p.metallic << " roughness " << p.roughness);
    REQUIRE(std::abs(i - std::round(i)) < 1e-3);  // exactly one texel, no blend
    REQUIRE(std::abs(j - std::round(j)) < 1e-3);
    return {int(std::round(i)), int(std::round(j))};
}

}  // namespace

TEST_CASE("KHR_texture_transform: the extension's own example lands in the lower-left quadrant, turned clockwise",
          "[texture][gltf]") {
    // The extension's example: offset (0, 1), rotation pi/2, scale (0.5, 0.5) "utilizes only the lower
    // left quadrant of the source image, rotated clockwise 90 degrees". So surface uv (u, v) reads image
    // point (v/2, 1 - u/2): texel (floor(4 * v/2), floor(4 * (1 - u/2))) = (floor(2v), floor(4 - 2u)).
    const Doc d = indexTextureDoc(
        {{"index", 0}, {"extensions", {{"KHR_texture_transform", {{"offset", {0, 1}}, {"rotation", kPi / 2}, {"scale", {0.5, 0.5}}}}}}});
    const Scene s = load(d.write("tt-example.gltf"));
    CHECK(s.info.extensionsIgnored.empty());
    CHECK(texelAt(s, 0.1f, 0.2f) == std::make_pair(0, 3));  // (0.4, 3.8)
    CHECK(texelAt(s, 0.6f, 0.3f) == std::make_pair(0, 2));  // (0.6, 2.8)
    CHECK(texelAt(s, 0.2f, 0.7f) == std::make_pair(1, 3));  // (1.4, 3.6)
    CHECK(texelAt(s, 0.7f, 0.1f) == std::make_pair(0, 2));  // (0.2, 2.6)
    CHECK(texelAt(s, 0.05f, 0.9f) == std::make_pair(1, 3)); // (1.8, 3.9)
}

TEST_CASE("KHR_texture_transform: scale before rotation before offset, and the texCoord override", "[texture][gltf]") {
    SECTION("offset and anisotropic scale, REPEAT") {
        // uv' = (2u + 0.25, v / 2): texel (floor(8u + 1) mod 4, floor(2v)).
        const Doc d = indexTextureDoc({{"index", 0}, {"extensions", {{"KHR_texture_transform", {{"offset", {0.25, 0}}, {"scale", {2, 0.5}}}}}}});
        const Scene s = load(d.write("tt-offset-scale.gltf"));
        CHECK(texelAt(s, 0.05f, 0.1f) == std::make_pair(1, 0));  // (1.4, 0.2)
        CHECK(texelAt(s, 0.3f, 0.6f) == std::make_pair(3, 1));   // (3.4, 1.2)
        CHECK(texelAt(s, 0.4f, 0.55f) == std::make_pair(0, 1));  // (4.2 -> 0, 1.1)
    }
    SECTION("rotation with anisotropic scale: S is applied first") {
        // rotation pi/2, scale (0.5, 1), offset (0, 1): uv' = (v, 1 - u/2) -> texel (floor(4v), floor(4 - 2u)).
        // Scaling after the rotation would give (v/2, 1 - u) instead: texel (floor(2v), floor(4 - 4u)).
        const Doc d = indexTextureDoc(
            {{"index", 0}, {"extensions", {{"KHR_texture_transform", {{"offset", {0, 1}}, {"rotation", kPi / 2}, {"scale", {0.5, 1}}}}}}});
        const Scene s = load(d.write("tt-rs-order.gltf"));
        CHECK(texelAt(s, 0.1f, 0.8f) == std::make_pair(3, 3));  // (3.2, 3.8)
        CHECK(texelAt(s, 0.6f, 0.3f) == std::make_pair(1, 2));  // (1.2, 2.8)
    }
    SECTION("texCoord in the extension overrides the textureInfo's") {
        // TEXCOORD_1 = uv / 4 + (0.5, 0.5); with offset (0.25, 0): texel (floor(u + 3), floor(v + 2)).
        const Doc d = indexTextureDoc(
            {{"index", 0}, {"texCoord", 0}, {"extensions", {{"KHR_texture_transform", {{"offset", {0.25, 0}}, {"texCoord", 1}}}}}});
        const Scene s = load(d.write("tt-texcoord.gltf"));
        CHECK(s.materials[0].metallicRoughnessTexture.texCoord == 1);
        CHECK(texelAt(s, 0.2f, 0.3f) == std::make_pair(3, 2));
        CHECK(texelAt(s, 0.0f, 0.0f) == std::make_pair(3, 2));
    }
    SECTION("no extension: identity") {
        const Scene s = load(indexTextureDoc({{"index", 0}}).write("tt-none.gltf"));
        CHECK(texelAt(s, 0.3f, 0.6f) == std::make_pair(1, 2));
        CHECK(texelAt(s, 0.9f, 0.05f) == std::make_pair(3, 0));
    }
}

TEST_CASE("KHR_texture_transform: malformed values are input errors", "[texture][gltf][malformed]") {
    SECTION("scale of 3 numbers") {
        const Doc d = indexTextureDoc({{"index", 0}, {"extensions", {{"KHR_texture_transform", {{"scale", {1, 1, 1}}}}}}});
        requireInputError(d.write("tt-bad-scale.gltf"), "metallicRoughnessTexture: KHR_texture_transform.scale must be an array of 2 numbers");
    }
    SECTION("rotation not a number") {
        const Doc d = indexTextureDoc({{"index", 0}, {"extensions", {{"KHR_texture_transform", {{"rotation", "90deg"}}}}}});
        requireInputError(d.write("tt-bad-rotation.gltf"), "KHR_texture_transform.rotation is not a number");
    }
    SECTION("offset beyond single precision") {
        const Doc d = indexTextureDoc({{"index", 0}, {"extensions", {{"KHR_texture_transform", {{"offset", {1e300, 0}}}}}}});
        requireInputError(d.write("tt-bad-offset.gltf"), "KHR_texture_transform.offset[0] is not finite");
    }
    SECTION("texCoord override the primitive lacks") {
        const Doc d = indexTextureDoc({{"index", 0}, {"extensions", {{"KHR_texture_transform", {{"texCoord", 2}}}}}});
        requireInputError(d.write("tt-bad-texcoord.gltf"), "texCoord 2 but the primitive has no TEXCOORD_2");
    }
    SECTION("negative texCoord override") {
        const Doc d = indexTextureDoc({{"index", 0}, {"extensions", {{"KHR_texture_transform", {{"texCoord", -1}}}}}});
        requireInputError(d.write("tt-neg-texcoord.gltf"), "KHR_texture_transform.texCoord must be a non-negative integer");
    }
}

TEST_CASE("Samplers: minFilter is validated (and not used), magFilter NEAREST selects nearest", "[texture][gltf]") {
    SECTION("every valid minFilter loads and does not change the lookup") {
        for (int f : {9728, 9729, 9984, 9985, 9986, 9987}) {
            Doc d = indexTextureDoc({{"index", 0}});
            d.j["samplers"][0]["minFilter"] = f;
            const Scene s = load(d.write("minfilter-" + std::to_string(f) + ".gltf"));
            INFO("minFilter " << f);
            CHECK(s.textures.at(0).nearest);
            CHECK(texelAt(s, 0.3f, 0.6f) == std::make_pair(1, 2));
        }
    }
    SECTION("an invalid minFilter is an input error") {
        Doc d = indexTextureDoc({{"index", 0}});
        d.j["samplers"][0]["minFilter"] = 9730;
        requireInputError(d.write("minfilter-bad.gltf"), "sampler 0 has invalid minFilter 9730");
    }
}

TEST_CASE("KHR_materials_transmission and KHR_materials_specular textures multiply their factors", "[texture][gltf]") {
    // 2x1 RGBA8, nearest: texel 0 = (51, 128, 255, 102), texel 1 = (255, 0, 64, 255). One image for
    // all three slots: R -> transmission (linear), A -> specular (linear), RGB -> specularColor (sRGB).
    Doc d;
    d.j["images"] = json::array({json{{"uri", "data:image/png;base64," + base64(makePng(2, 1, 4, 8, {51, 128, 255, 102, 255, 0, 64, 255}))}}});
    d.j["samplers"] = json::array({json{{"magFilter", 9728}}});
    d.j["textures"] = json::array({json{{"source", 0}, {"sampler", 0}}});
    const json info = {{"index", 0}};
    const int mat = d.material({{"pbrMetallicRoughness", {{"roughnessFactor", 0.0}, {"metallicFactor", 0.0}}},
                                {"extensions",
                                 {{"KHR_materials_transmission", {{"transmissionFactor", 0.8}, {"transmissionTexture", info}}},
                                  {"KHR_materials_specular",
                                   {{"specularFactor", 0.5},
                                    {"specularColorFactor", {1.0, 0.5, 2.0}},
                                    {"specularTexture", info},
                                    {"specularColorTexture", info}}}}}});
    const int pos = d.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3");
    const int uv = d.floats({0, 0, 1, 0, 0, 1}, "VEC2");
    d.node({{"mesh", d.mesh(Doc::prim(pos, -1, -1, uv, 4, mat))}});
    const Scene s = load(d.write("transmission-specular-tex.gltf"));
    const bdptref::Material& m = s.materials.at(0);
    REQUIRE(m.transmissionTexture.valid());
    REQUIRE(m.specularTexture.valid());
    REQUIRE(m.specularColorTexture.valid());
    CHECK(s.textures.at(size_t(m.specularColorTexture.texture)).data == s.textures.at(size_t(m.specularTexture.texture)).data);

    auto srgb = [](int v) { return bdptref::srgbToLinear(float(v / 255.0)); };
    const bdptref::MaterialParams left = s.materialParams(0, 0, Vec2(0.2f, 0.3f));  // u < 0.5: texel 0
    CHECK(left.transmission == Approx(0.8 * 51 / 255.0));
    CHECK(left.specular == Approx(0.5 * 102 / 255.0));
    CHECK(left.specularColor.r == Approx(1.0 * srgb(51)));
    CHECK(left.specularColor.g == Approx(0.5 * srgb(128)));
    CHECK(left.specularColor.b == Approx(2.0 * srgb(255)));
    const bdptref::MaterialParams right = s.materialParams(0, 0, Vec2(0.7f, 0.2f));  // texel 1
    CHECK(right.transmission == Approx(0.8));
    CHECK(right.specular == Approx(0.5));
    CHECK(right.specularColor.g == 0.f);
    CHECK(right.specularColor.b == Approx(2.0 * srgb(64)));
    CHECK(right.roughness == 0.f);  // smooth glass: allowed with a transmission texture
}

TEST_CASE("KHR_materials_unlit: refused when required, ignored with a warning (lit fallback) otherwise", "[texture][gltf]") {
    Doc d = indexTextureDoc({{"index", 0}});
    d.j["materials"][0]["extensions"] = {{"KHR_materials_unlit", json::object()}};
    d.use("KHR_materials_unlit");
    const Scene s = load(d.write("unlit.gltf"));
    REQUIRE(s.info.extensionsIgnored.size() == 1);
    CHECK(s.info.extensionsIgnored[0] == "KHR_materials_unlit");
    bool warned = false;
    for (const std::string& w : s.info.warnings) warned = warned || w.find("'KHR_materials_unlit' is not implemented") != std::string::npos;
    CHECK(warned);
    d.use("KHR_materials_unlit", true);
    requireInputError(d.write("unlit-required.gltf"), "extension 'KHR_materials_unlit' is required by the file but not implemented");
}
