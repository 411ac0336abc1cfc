// KHR_materials_clearcoat and KHR_materials_sheen through the loader and every estimator
// (docs/materials.md, "Clearcoat" and "Sheen"):
//  * the loader reads the factors and the R / G channels of the coat textures, records the
//    feature, refuses out-of-range factors and two normal maps on different TEXCOORD sets, and
//    lists a coated emitter's unmodelled darkening among the ignored features;
//  * the coat's normal is the interpolated vertex normal under a base normal map, and its own
//    normal map's perturbation under a clearcoatNormalTexture;
//  * the sheen's factors and texture channels (RGB sRGB, A) and its errors;
//  * PT, LT, BDPT balance and power agree per pixel (support/estimators.h: Welch + binomial rule,
//    with its power check) on rough coats over Lambert and metal, a sheen over Lambert and a sheen
//    under a coat; PT and BDPT on delta coats (LT cannot see a delta coat's reflection);
//  * MIS: on >= 10^4 sampled paths, thousands through coated and sheen vertices, the definition's
//    weights sum to 1 and the production weights equal them;
//  * the wavefront mode is bit-identical to the megakernel.
#include "support/estimators.h"
#include "support/gltf_builder.h"
#include "support/mis_paths.h"
#include "support/render_util.h"

#include "bdptref/errors.h"
#include "bdptref/gltf_loader.h"
#include "scene/normal_map.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>

using namespace bdptref;
using namespace bdptref::test;

namespace {

// Loaded, not finalized (the caller adds a camera or the environment, then finalizes once).
Scene loadDoc(const Doc& d, const std::string& name, int size = 16) {
    LoadOptions o;
    o.width = size;
    o.height = size;
    return loadGltfScene(d.write(name), o);
}

Scene loadFinal(const Doc& d, const std::string& name) {
    Scene s = loadDoc(d, name);
    s.finalize();
    return s;
}

// A unit quad z = 0 facing +z with vertex normals +z and uv; `material` is the material's JSON.
Doc coatedQuad(const json& material) {
    Doc d;
    d.use("KHR_materials_clearcoat");
    const int mat = d.material(material);
    const int pos = d.floats({-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0}, "VEC3");
    const int nrm = d.floats({0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}, "VEC3");
    const int uv = d.floats({0, 1, 1, 1, 1, 0, 0, 0}, "VEC2");
    const int idx = d.indices(std::vector<uint16_t>{0, 1, 2, 0, 2, 3});
    d.node({{"mesh", d.mesh(Doc::prim(pos, idx, nrm, uv, 4, mat))}});
    return d;
}

json coatMaterial(const json& clearcoat) {
    return {{"pbrMetallicRoughness", {{"baseColorFactor", {0.6, 0.3, 0.2, 1}}, {"metallicFactor", 0}, {"roughnessFactor", 0.5}}},
            {"extensions", {{"KHR_materials_clearcoat", clearcoat}}}};
}

// The hit straight below world (x, y, 3) on the quad (the scene is in render space).
SurfaceHit hitAt(const Scene& s, double x, double y) {
    SurfaceHit h;
    REQUIRE(s.intersect(Ray{s.toRender(DVec3(x, y, 3.0)), Vec3(0, 0, -1)}, &h));
    return h;
}

}  // namespace

TEST_CASE("Clearcoat: the loader reads factors and texture channels, and refuses what it cannot render", "[clearcoat][gltf]") {
    SECTION("factors and the R / G channels of the coat textures") {
        Doc d = coatedQuad(json::object());
        // Texel 0: R 0.2, G 0.8 (B, A other values, so a wrong channel shows).
        const int tex = nearestTexture(d, 1, 1, {51, 204, 102, 255});
        d.j["materials"][0] = coatMaterial({{"clearcoatFactor", 0.9},
                                            {"clearcoatRoughnessFactor", 0.5},
                                            {"clearcoatTexture", {{"index", tex}}},
                                            {"clearcoatRoughnessTexture", {{"index", tex}}}});
        d.use("KHR_materials_clearcoat");
        const std::string file = d.write("cc-factors.gltf");
        const Scene s = loadFinal(d, "cc-factors.gltf");
        std::string out;
        CHECK(runCli("info " + file, &out) == 0);
        CHECK(out.find("clearcoat 0.9 x texture roughness 0.5 x texture") != std::string::npos);
        REQUIRE(s.materials.size() == 1);
        CHECK(s.materials[0].clearcoat == 0.9f);
        CHECK(s.materials[0].clearcoatRoughness == 0.5f);
        const SurfaceHit h = hitAt(s, 0.3f, -0.2f);
        const MaterialParams p = s.materialParams(h.material, h.triangle, h.bary);
        CHECK(p.clearcoat == Approx(0.9 * 0.2).epsilon(1e-5));
        CHECK(p.clearcoatRoughness == Approx(0.5 * 0.8).epsilon(1e-5));
        CHECK(std::count(s.info.featuresUsed.begin(), s.info.featuresUsed.end(), "KHR_materials_clearcoat") == 1);
        CHECK(s.info.extensionsIgnored.empty());
        CHECK(s.info.ignoredFeatures.empty());
    }
    SECTION("an out-of-range factor is refused with its name") {
        const Doc d = coatedQuad(coatMaterial({{"clearcoatFactor", 1.5}}));
        REQUIRE_THROWS_WITH(loadFinal(d, "cc-bad.gltf"), Catch::Contains("clearcoatFactor"));
        const Doc r = coatedQuad(coatMaterial({{"clearcoatFactor", 1.0}, {"clearcoatRoughnessFactor", "rough"}}));
        REQUIRE_THROWS_WITH(loadFinal(r, "cc-bad-type.gltf"), Catch::Contains("clearcoatRoughnessFactor"));
    }
    SECTION("two normal maps on different TEXCOORD sets are refused") {
        Doc d = coatedQuad(json::object());
        const int tex = nearestTexture(d, 1, 1, {200, 128, 255, 255});
        json m = coatMaterial({{"clearcoatFactor", 1.0}, {"clearcoatNormalTexture", {{"index", tex}, {"texCoord", 1}}}});
        m["normalTexture"] = {{"index", tex}};
        d.j["materials"][0] = m;
        REQUIRE_THROWS_WITH(loadFinal(d, "cc-two-sets.gltf"), Catch::Contains("TEXCOORD"));
    }
    SECTION("a coated emitter: its darkening is listed as ignored") {
        json m = coatMaterial({{"clearcoatFactor", 1.0}});
        m["emissiveFactor"] = {1, 1, 1};
        const Scene s = loadFinal(coatedQuad(m), "cc-emitter.gltf");
        REQUIRE(s.info.ignoredFeatures.size() == 1);
        CHECK(s.info.ignoredFeatures[0].find("clearcoat") != std::string::npos);
    }
}

TEST_CASE("Sheen: the loader reads the colour (sRGB RGB) and roughness (A) and refuses bad values", "[sheen][gltf]") {
    SECTION("factors and texture channels") {
        Doc d = coatedQuad(json::object());
        // Texel: sRGB (188, 188, 188) = linear 0.5029; A 0.6 (linear).
        const int tex = nearestTexture(d, 1, 1, {188, 188, 188, 153});
        json m = coatMaterial(json::object());
        m["extensions"].erase("KHR_materials_clearcoat");
        m["extensions"]["KHR_materials_sheen"] = {{"sheenColorFactor", {0.8, 0.4, 0.2}},
                                                  {"sheenRoughnessFactor", 0.5},
                                                  {"sheenColorTexture", {{"index", tex}}},
                                                  {"sheenRoughnessTexture", {{"index", tex}}}};
        d.j["materials"][0] = m;
        d.use("KHR_materials_sheen");
        const std::string file = d.write("sheen-factors.gltf");
        const Scene s = loadFinal(d, "sheen-factors.gltf");
        const SurfaceHit h = hitAt(s, 0.3, -0.2);
        const MaterialParams p = s.materialParams(h.material, h.triangle, h.bary);
        const double lin = srgbToLinear(188.f / 255.f);
        CHECK(p.sheenColor.r == Approx(0.8 * lin).epsilon(1e-4));
        CHECK(p.sheenColor.b == Approx(0.2 * lin).epsilon(1e-4));
        CHECK(p.sheenRoughness == Approx(0.5 * 0.6).epsilon(1e-4));
        CHECK(std::count(s.info.featuresUsed.begin(), s.info.featuresUsed.end(), "KHR_materials_sheen") == 1);
        CHECK(s.info.extensionsIgnored.empty());
        std::string out;
        CHECK(runCli("info " + file, &out) == 0);
        CHECK(out.find("sheen (0.8, 0.4, 0.2) x texture roughness 0.5 x texture") != std::string::npos);
    }
    SECTION("bad values are refused with their names") {
        json m = coatMaterial(json::object());
        m["extensions"]["KHR_materials_sheen"] = {{"sheenColorFactor", {0.8, 0.4}}};
        Doc d = coatedQuad(m);
        d.use("KHR_materials_sheen");
        REQUIRE_THROWS_WITH(loadFinal(d, "sheen-bad.gltf"), Catch::Contains("sheenColorFactor"));
        m["extensions"]["KHR_materials_sheen"] = {{"sheenColorFactor", {0.8, 0.4, 0.1}}, {"sheenRoughnessFactor", 2.0}};
        Doc r = coatedQuad(m);
        r.use("KHR_materials_sheen");
        REQUIRE_THROWS_WITH(loadFinal(r, "sheen-bad-roughness.gltf"), Catch::Contains("sheenRoughnessFactor"));
    }
}

TEST_CASE("Clearcoat: the coat's normal ignores the base's normal map and follows its own", "[clearcoat][normalmap]") {
    Doc d = coatedQuad(json::object());
    const int tilt = nearestTexture(d, 1, 1, {200, 128, 255, 255});   // tilts towards +x (tangent)
    const int other = nearestTexture(d, 1, 1, {128, 60, 255, 255});   // tilts towards -y
    json m = coatMaterial({{"clearcoatFactor", 1.0}});
    m["normalTexture"] = {{"index", tilt}};
    d.j["materials"][0] = m;
    {
        const Scene s = loadFinal(d, "cc-base-map.gltf");
        const SurfaceHit h = hitAt(s, 0.2f, 0.1f);
        CHECK(h.ns.x > 0.3f);  // the base's map tilts the shading normal
        const MaterialParams p = s.materialParams(h.material, h.triangle, h.bary);
        CHECK(p.clearcoatNormal == Vec3(0, 0, 1));  // the coat keeps the interpolated normal
    }
    d.j["materials"][0]["extensions"]["KHR_materials_clearcoat"]["clearcoatNormalTexture"] = {{"index", other}, {"scale", 0.8}};
    const Scene s = loadFinal(d, "cc-coat-map.gltf");
    const SurfaceHit h = hitAt(s, 0.2f, 0.1f);
    const MaterialParams p = s.materialParams(h.material, h.triangle, h.bary);
    REQUIRE(s.mesh.tangents.size() == s.mesh.positions.size());
    // The glTF formula with the coat's texel and scale in the vertex tangent frame
    // (applyNormalMap, tested in test_normal_map.cpp): tilted towards the bitangent only.
    const Vec4 tangent = s.mesh.tangents[s.mesh.indices[h.triangle].x];
    const Vec3 viaFormula = applyNormalMap(Vec3(0, 0, 1), Vec3(0, 0, 1), Vec3(tangent), tangent.w,
                                           Vec3(128.f / 255, 60.f / 255, 1.f), 0.8f);
    CHECK(p.clearcoatNormal.x == Approx(viaFormula.x).margin(1e-6));
    CHECK(p.clearcoatNormal.y == Approx(viaFormula.y).margin(1e-6));
    CHECK(p.clearcoatNormal.z == Approx(viaFormula.z).margin(1e-6));
    CHECK(std::abs(p.clearcoatNormal.y) > 0.3f);
    CHECK(std::abs(p.clearcoatNormal.x) < 0.01f);
    CHECK(h.ns.x > 0.3f);  // and the base keeps its own map
}

namespace {

// Four spheres on a grey floor before a grey wall (every pixel sees a surface, and light tracing
// sees what the camera sees) under a rectangular light and a point light: a coat over red Lambert,
// a coat over rough gold, a sheen over dark blue Lambert and a coat over a sheen over grey Lambert. `deltaCoats`: smooth coats
// (roughness 0), else rough ones (0.3 and 0.15).
Scene coatedSpheres(int size, bool deltaCoats) {
    Doc d;
    d.use("KHR_materials_clearcoat");
    d.use("KHR_materials_specular");
    d.quad({-3, 0, 3}, {3, 0, 3}, {3, 0, -3}, {-3, 0, -3}, d.lambert({0.5, 0.5, 0.5}));
    d.quad({-3, 0, -1.2}, {3, 0, -1.2}, {3, 4, -1.2}, {-3, 4, -1.2}, d.lambert({0.4, 0.45, 0.5}));
    const int red = d.material({{"pbrMetallicRoughness", {{"baseColorFactor", {0.7, 0.15, 0.1, 1}}, {"metallicFactor", 0}, {"roughnessFactor", 1}}},
                                {"extensions",
                                 {{"KHR_materials_specular", {{"specularFactor", 0}}},
                                  {"KHR_materials_clearcoat", {{"clearcoatFactor", 1.0}, {"clearcoatRoughnessFactor", deltaCoats ? 0.0 : 0.3}}}}}});
    const int gold = d.material({{"pbrMetallicRoughness", {{"baseColorFactor", {0.95, 0.7, 0.35, 1}}, {"metallicFactor", 1}, {"roughnessFactor", 0.45}}},
                                 {"extensions",
                                  {{"KHR_materials_clearcoat", {{"clearcoatFactor", 0.8}, {"clearcoatRoughnessFactor", deltaCoats ? 0.0 : 0.15}}}}}});
    d.use("KHR_materials_sheen");
    const int velvet = d.material({{"pbrMetallicRoughness", {{"baseColorFactor", {0.05, 0.08, 0.3, 1}}, {"metallicFactor", 0}, {"roughnessFactor", 1}}},
                                   {"extensions",
                                    {{"KHR_materials_specular", {{"specularFactor", 0}}},
                                     {"KHR_materials_sheen", {{"sheenColorFactor", {0.9, 0.7, 0.8}}, {"sheenRoughnessFactor", 0.4}}}}}});
    const int both = d.material({{"pbrMetallicRoughness", {{"baseColorFactor", {0.4, 0.4, 0.4, 1}}, {"metallicFactor", 0}, {"roughnessFactor", 0.8}}},
                                 {"extensions",
                                  {{"KHR_materials_sheen", {{"sheenColorFactor", {0.3, 0.9, 0.4}}, {"sheenRoughnessFactor", 0.7}}},
                                   {"KHR_materials_clearcoat", {{"clearcoatFactor", 0.6}, {"clearcoatRoughnessFactor", deltaCoats ? 0.0 : 0.2}}}}}});
    d.sphere({-0.55, 0.5, 0}, 0.5, red, 12, 24);
    d.sphere({0.6, 0.45, 0.2}, 0.45, gold, 12, 24);
    d.sphere({-1.5, 0.4, -0.5}, 0.4, velvet, 12, 24);
    d.sphere({1.6, 0.4, -0.4}, 0.4, both, 12, 24);
    d.quad({-0.6, 2.5, -0.6}, {0.6, 2.5, -0.6}, {0.6, 2.5, 0.6}, {-0.6, 2.5, 0.6}, d.lambert({0, 0, 0}, {4, 4, 4}));
    d.punctual({{"type", "point"}, {"color", {1, 1, 1}}, {"intensity", 3.0}}, {{"translation", {1.5, 1.5, 1.5}}});
    Scene s = loadDoc(d, deltaCoats ? "cc-spheres-delta.gltf" : "cc-spheres-rough.gltf", size);
    s.camera = Camera::lookAt(Vec3(0, 1.5f, 3.2f), Vec3(0, 0.4f, 0), Vec3(0, 1, 0), 0.95f, size, size);
    s.finalize();
    return s;
}

bool coatedVertex(const Scene& scene, const PathVertex& v) {
    return v.isOnSurface() && scene.materials.at(v.material).clearcoat > 0.f;
}
bool sheenVertex(const Scene& scene, const PathVertex& v) {
    return v.isOnSurface() && !isBlack(scene.materials.at(v.material).sheenColor);
}

}  // namespace

TEST_CASE("Clearcoat and sheen: PT, LT, BDPT balance and power agree per pixel on rough coats and sheens",
          "[clearcoat][sheen][agreement]") {
    const Scene scene = coatedSpheres(16, false);
    // The comparisons must detect a uniform 15% error (the coat's highlight alone is larger).
    checkPairwiseAgreement(momentsOfEach(renderEveryEstimator(scene, {256, 1024, 128, 128}, 1200)), 0.15);
}

TEST_CASE("Clearcoat and sheen: PT and BDPT balance and power agree per pixel on delta coats", "[clearcoat][sheen][agreement]") {
    const Scene scene = coatedSpheres(16, true);
    std::vector<std::pair<std::string, Film>> films;
    uint32_t seed = 1300;
    for (const EstimatorSetup& e : everyEstimator()) {
        if (e.integrator == "lt") continue;  // a delta coat's reflection is out of LT's reach
        EstimatorSetup s = e;
        s.spp = e.integrator == "path" ? 256 : 128;
        s.seed = seed += 13;
        films.emplace_back(estimatorName(s), renderEstimator(scene, s));
    }
    checkPairwiseAgreement(momentsOfEach(films), 0.15);
}

TEST_CASE("Clearcoat and sheen: MIS weights of sampled paths through coated and sheen vertices sum to 1 and equal the definition",
          "[clearcoat][sheen][mis]") {
    for (const bool delta : {false, true}) {
        const Scene scene = coatedSpheres(16, delta);
        long throughCoat = 0, throughSheen = 0;
        const MisPathCheck r = checkSampledPathWeights(scene, 8000, delta ? 71u : 73u, 5, [&](const std::vector<PathVertex>& x, int) {
            throughCoat += std::any_of(x.begin(), x.end(), [&](const PathVertex& v) { return coatedVertex(scene, v); });
            throughSheen += std::any_of(x.begin(), x.end(), [&](const PathVertex& v) { return sheenVertex(scene, v); });
        });
        INFO((delta ? "delta coats: " : "rough coats: ") << r.summary() << "\npaths through a coated vertex " << throughCoat
                                                         << ", through a sheen vertex " << throughSheen);
        CHECK(r.passed());
        CHECK(r.paths >= 10000);
        CHECK(throughCoat >= 2000);
        CHECK(throughSheen >= 1000);
    }
}

TEST_CASE("Clearcoat and sheen: the wavefront mode equals the megakernel bit for bit", "[clearcoat][sheen][wavefront]") {
    EstimatorSetup base;
    base.spp = 2;
    base.maxDepth = 5;
    base.threads = 2;
    checkWavefrontIdenticalEveryEstimator(coatedSpheres(12, false), base);
    checkWavefrontIdenticalEveryEstimator(coatedSpheres(12, true), base);
}
