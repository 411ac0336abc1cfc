// glTF scene graph beyond plain nodes: every problem of a file reported in one run, skinned
// meshes in their rest pose, EXT_mesh_gpu_instancing, and merging of coincident copies.

#include "bdptref/errors.h"
#include "bdptref/gltf_loader.h"

#include "support/gltf_builder.h"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <string>
#include <vector>

using bdptref::InputError;
using bdptref::LoadOptions;
using bdptref::Scene;
using bdptref::Vec3;
using json = nlohmann::json;
using namespace bdptref::test;

namespace {

Scene load(const std::string& path) {
    LoadOptions o;
    o.width = 32;
    o.height = 32;
    return bdptref::loadGltfScene(path, o);
}

std::string loadError(const std::string& path) {
    try {
        (void)load(path);
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

bool near(const Vec3& a, const Vec3& b, float eps = 1e-5f) { return glm::length(a - b) <= eps; }

int bytesAccessor(Doc& d, const std::vector<unsigned char>& v, int ct, size_t count, const char* type) {
    return d.accessor(d.view(v.data(), v.size()), ct, count, type);
}

}  // namespace

TEST_CASE("gltf: every problem of a file is reported in one run", "[gltf][errors]") {
    Doc d;
    d.use("KHR_made_up_a", true);
    d.use("KHR_made_up_b", true);
    d.triangleNode({{"rotation", {0, 0, 0, 2}}});                     // problem 3: not a unit quaternion
    d.node({{"mesh", 7}});                                            // problem 4: no such mesh
    const int bad = d.material({{"alphaMode", "SOMETIMES"}});         // problem 5: invalid alphaMode
    d.node({{"mesh", d.mesh(Doc::prim(d.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3"), -1, -1, -1, 4, bad))}});
    d.triangleNode();                                                 // fine
    const std::string msg = loadError(d.write("many-problems.gltf"));
    INFO(msg);
    CHECK(msg.find("5 problems") != std::string::npos);
    CHECK(msg.find("KHR_made_up_a") != std::string::npos);
    CHECK(msg.find("KHR_made_up_b") != std::string::npos);
    CHECK(msg.find("rotation quaternion is not unit length") != std::string::npos);
    CHECK(msg.find("mesh 7 does not exist") != std::string::npos);
    CHECK(msg.find("invalid alphaMode 'SOMETIMES'") != std::string::npos);
}

TEST_CASE("gltf: a skinned mesh is posed by its joints' node transforms", "[gltf][skin]") {
    Doc d;
    // Two joints: joint 0 translated by +10 x, joint 1 rotated 90 degrees about z and moved +5 y.
    const int j0 = d.node({{"translation", {10, 0, 0}}}, true);
    const double s = std::sqrt(0.5);
    const int j1 = d.node({{"rotation", {0, 0, s, s}}, {"translation", {0, 5, 0}}}, true);
    // Inverse bind matrices: joint 0 identity, joint 1 a translation by -1 x (column-major).
    const std::vector<float> ibm = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1,
                                    1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -1, 0, 0, 1};
    const int ibmAcc = d.accessor(d.view(ibm.data(), ibm.size() * 4), kF32, 2, "MAT4");
    d.j["skins"] = json::array({json{{"joints", {j0, j1}}, {"inverseBindMatrices", ibmAcc}}});
    const int pos = d.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3");
    // Vertex 0 fully on joint 0, vertex 1 fully on joint 1, vertex 2 half and half (u8 joints, float weights).
    const int joints = bytesAccessor(d, {0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0}, kU8, 3, "VEC4");
    const int weights = d.floats({1, 0, 0, 0, 1, 0, 0, 0, 0.5f, 0.5f, 0, 0}, "VEC4");
    json prim = Doc::prim(pos);
    prim["attributes"]["JOINTS_0"] = joints;
    prim["attributes"]["WEIGHTS_0"] = weights;
    // The skinned node's own transform must be ignored (spec): give it a large one.
    d.node({{"mesh", d.mesh(prim)}, {"skin", 0}, {"translation", {100, 100, 100}}});
    const Scene sc = load(d.write("skin.gltf"));
    REQUIRE(sc.mesh.positions.size() == 3);
    // v0 = (0,0,0) by joint 0: (10,0,0).
    CHECK(near(sc.mesh.positions[0], Vec3(10, 0, 0)));
    // v1 = (1,0,0): inverse bind -> (0,0,0), rotate -> (0,0,0), translate -> (0,5,0).
    CHECK(near(sc.mesh.positions[1], Vec3(0, 5, 0)));
    // v2 = (0,1,0): joint 0 gives (10,1,0); joint 1: (-1,1,0) rotated 90 about z -> (-1,-1,0), + (0,5,0) -> (-1,4,0).
    CHECK(near(sc.mesh.positions[2], 0.5f * Vec3(10, 1, 0) + 0.5f * Vec3(-1, 4, 0)));
}

TEST_CASE("gltf: skin problems are input errors", "[gltf][skin]") {
    Doc d;
    const int j0 = d.node(json::object(), true);
    d.j["skins"] = json::array({json{{"joints", {j0}}}});
    const int pos = d.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3");
    json prim = Doc::prim(pos);
    prim["attributes"]["JOINTS_0"] = bytesAccessor(d, {0, 0, 0, 0, 3, 0, 0, 0, 0, 0, 0, 0}, kU8, 3, "VEC4");
    prim["attributes"]["WEIGHTS_0"] = d.floats({1, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0}, "VEC4");
    d.node({{"mesh", d.mesh(prim)}, {"skin", 0}});
    const std::string msg = loadError(d.write("skin-bad.gltf"));
    INFO(msg);
    CHECK(msg.find("joint 3 at vertex 1 is out of range") != std::string::npos);
    CHECK(msg.find("vertex 2 has skin weights summing to 0") == std::string::npos);  // first problem of the primitive
}

TEST_CASE("gltf: EXT_mesh_gpu_instancing places one copy per instance, like N nodes would", "[gltf][instancing]") {
    const std::vector<float> t = {0, 0, 0, 5, 0, 0, 0, 0, -3};
    const double s = std::sqrt(0.5);
    const std::vector<float> r = {0, 0, 0, 1, 0, 0, float(s), float(s), 0, 0, 0, 1};
    const std::vector<float> sc = {1, 1, 1, 2, 2, 2, 1, 1, 1};
    Doc inst;
    inst.use("EXT_mesh_gpu_instancing");
    const int pos = inst.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3");
    const int tA = inst.floats(t, "VEC3"), rA = inst.floats(r, "VEC4"), sA = inst.floats(sc, "VEC3");
    inst.node({{"mesh", inst.mesh(Doc::prim(pos))},
               {"translation", {1, 2, 3}},
               {"extensions", {{"EXT_mesh_gpu_instancing", {{"attributes", {{"TRANSLATION", tA}, {"ROTATION", rA}, {"SCALE", sA}}}}}}}});
    const Scene a = load(inst.write("instanced.gltf"));

    Doc flat;  // the same three placements written as child nodes
    const int pos2 = flat.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3");
    const int m = flat.mesh(Doc::prim(pos2));
    std::vector<int> kids;
    for (int i = 0; i < 3; ++i)
        kids.push_back(flat.node({{"mesh", m},
                                  {"translation", {t[3 * i], t[3 * i + 1], t[3 * i + 2]}},
                                  {"rotation", {r[4 * i], r[4 * i + 1], r[4 * i + 2], r[4 * i + 3]}},
                                  {"scale", {sc[3 * i], sc[3 * i + 1], sc[3 * i + 2]}}},
                                 false));
    flat.node({{"translation", {1, 2, 3}}, {"children", kids}});
    const Scene b = load(flat.write("flat.gltf"));
    REQUIRE(a.mesh.positions.size() == 9);
    REQUIRE(b.mesh.positions.size() == 9);
    for (size_t i = 0; i < 9; ++i) CHECK(a.mesh.positions[i] == b.mesh.positions[i]);  // bit-identical
    CHECK(a.mesh.indices == b.mesh.indices);
    CHECK(near(a.mesh.positions[3], Vec3(1 + 5, 2, 3)));
}

TEST_CASE("gltf: a million coincident instances load quickly as one surface", "[gltf][instancing]") {
    Doc d;
    d.use("EXT_mesh_gpu_instancing");
    const int pos = d.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3");
    const size_t n = 1000000;
    std::vector<float> t(3 * n, 0.f);
    t[3 * (n - 1)] = 2.f;  // the last instance elsewhere: two distinct placements in all
    const int tA = d.floats(t, "VEC3");
    d.node({{"mesh", d.mesh(Doc::prim(pos))}, {"extensions", {{"EXT_mesh_gpu_instancing", {{"attributes", {{"TRANSLATION", tA}}}}}}}});
    const Scene s = load(d.write("million.glb.gltf"));
    CHECK(s.mesh.indices.size() == 2);
    bool warned = false;
    for (const std::string& w : s.info.warnings) warned = warned || w.find("999998 mesh copies") != std::string::npos;
    CHECK(warned);
}
