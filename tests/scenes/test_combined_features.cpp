// The features of the content issue together, in every estimator (docs/lights.md "Environment",
// docs/materials.md "Rough transmission", "Volume absorption", "Clearcoat", "Sheen"): a floor lit
// only by the sun-and-sky map (a 2000x sun in one texel of a 64x32 map), an absorbing rough glass
// sphere with a small emissive sphere inside it, a clearcoated sphere and a velvet (sheen) sphere.
// The camera looks down at the floor, so every pixel sees a surface (light tracing sees what the
// camera sees):
//  * PT, LT, BDPT balance and power agree per pixel and per 2x2 block (support/estimators.h:
//    Welch + binomial rule with its power check: per pixel a uniform 15% error, per block 8%);
//  * MIS: on >= 10^4 sampled paths, thousands ending on the map and thousands through the glass,
//    the coat or the sheen, the definition's weights sum to 1 and the production weights equal them;
//  * the wavefront mode is bit-identical to the megakernel.
#include "support/estimators.h"
#include "support/gltf_builder.h"
#include "support/image_stats.h"
#include "support/mis_paths.h"
#include "unit/test_env_map_maps.h"

#include "bdptref/gltf_loader.h"

#include <catch2/catch.hpp>

#include <algorithm>

using namespace bdptref;
using namespace bdptref::test;

namespace {

Scene combinedScene(int size) {
    Doc d;
    for (const char* e : {"KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_volume", "KHR_materials_clearcoat",
                          "KHR_materials_sheen", "KHR_materials_specular"})
        d.use(e);
    d.quad({-3, 0, 3}, {3, 0, 3}, {3, 0, -3}, {-3, 0, -3}, d.lambert({0.55, 0.5, 0.45}));
    const int glass = d.material(
        {{"pbrMetallicRoughness", {{"baseColorFactor", {1, 1, 1, 1}}, {"metallicFactor", 0}, {"roughnessFactor", 0.3}}},
         {"extensions",
          {{"KHR_materials_transmission", {{"transmissionFactor", 1.0}}},
           {"KHR_materials_ior", {{"ior", 1.5}}},
           {"KHR_materials_volume", {{"thicknessFactor", 1.0}, {"attenuationColor", {0.85, 0.6, 0.4}}, {"attenuationDistance", 0.8}}}}}});
    d.sphere({-0.8, 0.45, 0.0}, 0.45, glass, 12, 24);
    d.sphere({-0.8, 0.45, 0.0}, 0.08, d.lambert({0, 0, 0}, {30, 27, 24}), 6, 12);  // the emitter inside the glass
    const int coated = d.material({{"pbrMetallicRoughness", {{"baseColorFactor", {0.7, 0.15, 0.1, 1}}, {"metallicFactor", 0}, {"roughnessFactor", 1}}},
                                   {"extensions",
                                    {{"KHR_materials_specular", {{"specularFactor", 0}}},
                                     {"KHR_materials_clearcoat", {{"clearcoatFactor", 1.0}, {"clearcoatRoughnessFactor", 0.2}}}}}});
    d.sphere({0.45, 0.35, 0.45}, 0.35, coated, 12, 24);
    const int velvet = d.material({{"pbrMetallicRoughness", {{"baseColorFactor", {0.05, 0.08, 0.3, 1}}, {"metallicFactor", 0}, {"roughnessFactor", 1}}},
                                   {"extensions",
                                    {{"KHR_materials_specular", {{"specularFactor", 0}}},
                                     {"KHR_materials_sheen", {{"sheenColorFactor", {0.9, 0.7, 0.8}}, {"sheenRoughnessFactor", 0.4}}}}}});
    d.sphere({0.7, 0.35, -0.6}, 0.35, velvet, 12, 24);
    LoadOptions o;
    o.width = size;
    o.height = size;
    Scene s = loadGltfScene(d.write("combined-features.gltf"), o);
    s.camera = Camera::lookAt(Vec3(0.f, 3.0f, 1.8f), Vec3(0.f, 0.f, -0.1f), Vec3(0, 1, 0), 0.8f, size, size);
    s.setEnvironmentMap(sunAndSkyMap(64, 32, 0.7f, 2000.f), 1.f, "test map");
    s.finalize();
    return s;
}

}  // namespace

TEST_CASE("Combined features: PT, LT, BDPT balance and power agree per pixel under an HDR sun with rough absorbing glass, "
          "a light inside it, clearcoat and sheen",
          "[combined][agreement][envmap][roughglass][volume][clearcoat][sheen]") {
    const Scene scene = combinedScene(16);
    const auto films = renderEveryEstimator(scene, {512, 4096, 256, 256}, 5000, 29);
    const std::vector<std::pair<std::string, MomentImage>> pixels = momentsOfEach(films);
    std::vector<std::pair<std::string, MomentImage>> blocks;
    for (const auto& [name, film] : films) blocks.emplace_back(name + " 2x2", mergeBlocks(momentsOf(film), 2));
    checkPairwiseAgreement(pixels, 0.15);
    checkPairwiseAgreement(blocks, 0.08);
}

TEST_CASE("Combined features: MIS weights of sampled paths sum to 1 and equal the definition", "[combined][mis]") {
    const Scene scene = combinedScene(16);
    long onMap = 0, throughLayers = 0, throughGlass = 0;
    const MisPathCheck r = checkSampledPathWeights(scene, 8000, 4242u, 6, [&](const std::vector<PathVertex>& x, int) {
        onMap += x.back().infinite;
        bool layers = false, glass = false;
        for (const PathVertex& v : x) {
            if (!v.isOnSurface()) continue;
            const Material& m = scene.materials.at(v.material);
            layers = layers || m.clearcoat > 0.f || !isBlack(m.sheenColor);
            glass = glass || m.transmission > 0.f;
        }
        throughLayers += layers;
        throughGlass += glass;
    });
    INFO(r.summary() << "\npaths ending on the map " << onMap << ", through a coat or sheen " << throughLayers
                     << ", through the glass " << throughGlass);
    CHECK(r.passed());
    CHECK(r.paths >= 10000);
    CHECK(onMap >= 1000);
    CHECK(throughLayers >= 1000);
    CHECK(throughGlass >= 1000);
}

TEST_CASE("Combined features: the wavefront mode equals the megakernel bit for bit", "[combined][wavefront]") {
    EstimatorSetup base;
    base.spp = 2;
    base.maxDepth = 6;
    base.threads = 2;
    checkWavefrontIdenticalEveryEstimator(combinedScene(12), base);
}
