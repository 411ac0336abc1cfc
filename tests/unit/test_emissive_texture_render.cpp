// Emissive textures through the estimators (docs/lights.md, "Emissive textures"), on a small scene
// lit only by an emissive-textured area light (a checkerboard of bright and black texels, bilinear,
// facing down over a floor and in front of a wall; the camera sees the emitter and what it lights):
//  * PT, LT, BDPT-balance and BDPT-power agree per pixel (the Welch + binomial rule of
//    tests/support/image_stats.h, as tests/scenes/test_bdpt_agreement.cpp), and each comparison
//    detects a uniform 5% error in either image (its power, measured on these very renders);
//  * the MIS weights of >= 1e4 sampled paths sum to 1 and the production weight equals the
//    definition's (tests/unit/test_mis.cpp's rule and tolerance, tests/support/mis_tolerance.h);
//  * the wavefront mode renders bit-identically to the megakernel (tests/scenes/test_wavefront.cpp).
#include "support/estimators.h"
#include "support/gltf_builder.h"
#include "support/mis_paths.h"
#include "support/render_util.h"

#include "bdptref/gltf_loader.h"
#include "bdptref/light.h"
#include "bdptref/scene.h"

#include <catch2/catch.hpp>

using namespace bdptref;
using namespace bdptref::test;

namespace {

// 16 x 16 pixels; the emitter (y = 1, facing down) carries a 4 x 4 checkerboard, bright texels
// (255, 230, 180) and black ones, bilinear filtered, emissive factor 1 times strength 8.
Scene checkerLitScene() {
    Doc d;
    std::vector<uint16_t> texels;
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i)
            for (uint16_t v : {uint16_t(255), uint16_t(230), uint16_t(180)}) texels.push_back((i + j) % 2 ? uint16_t(0) : v);
    const int tex = pngTexture(d, 4, 4, 3, texels, false);
    const int lamp = d.lambert({0, 0, 0}, {1, 1, 1}, 8.0);
    d.j["materials"][size_t(lamp)]["emissiveTexture"] = {{"index", tex}};
    texturedQuad(d, {{{-0.6, 1, -0.6}, {0.6, 1, -0.6}, {0.6, 1, 0.6}, {-0.6, 1, 0.6}}}, {{{0, 0}, {1, 0}, {1, 1}, {0, 1}}}, lamp);
    // Floor (facing +y) and wall (facing +z) fill the whole image, so every pixel is t-tested.
    d.quad({-3, 0, -1}, {-3, 0, 3}, {3, 0, 3}, {3, 0, -1}, d.lambert({0.6, 0.6, 0.6}));
    d.quad({-3, 0, -1}, {3, 0, -1}, {3, 3, -1}, {-3, 3, -1}, d.lambert({0.7, 0.4, 0.3}));
    LoadOptions o;
    o.width = o.height = 16;
    Scene s = loadGltfScene(d.write("emissive-checker.gltf"), o);
    s.camera = Camera::lookAt(Vec3(0, 0.35f, 2.2f), Vec3(0, 0.55f, 0), Vec3(0, 1, 0), 1.0f, 16, 16);
    s.finalize();
    return s;
}

}  // namespace

TEST_CASE("Emissive texture: PT LT BDPT-balance and BDPT-power agree per pixel on a scene lit by a textured light",
          "[emissive-texture][agreement]") {
    const Scene scene = checkerLitScene();
    REQUIRE(scene.lights.size() == 2);
    REQUIRE(scene.lights[0].emissiveTexture.valid());
    checkPairwiseAgreement(momentsOfEach(renderEveryEstimator(scene, {1024, 1024, 512, 512}, 3000)), 0.05);
}

TEST_CASE("Emissive texture: MIS weights of sampled paths on a textured light sum to 1 and equal the definition",
          "[emissive-texture][mis]") {
    const Scene scene = checkerLitScene();
    long onBlack = 0;
    const MisPathCheck r = checkSampledPathWeights(scene, 6000, 777u, 5, [&](const std::vector<PathVertex>& x, int) {
        const Light& l = scene.lights[size_t(x.back().light)];
        onBlack += isBlack(areaEmission(l, scene.textures, x.back().bary));
    });
    INFO(r.summary());
    CHECK(r.paths >= 10000);
    CHECK(r.s0 > 100);
    CHECK(r.s1 > 100);
    CHECK(r.t1 > 100);
    CHECK(onBlack == 0);  // a path ending on a black texel carries nothing and is never connected
    CHECK(r.passed());
}

TEST_CASE("Emissive texture: wavefront equals megakernel bit for bit on a scene lit by a textured light",
          "[emissive-texture][wavefront]") {
    EstimatorSetup s;
    s.spp = 2;
    s.threads = 2;
    checkWavefrontIdenticalEveryEstimator(checkerLitScene(), s);
}
