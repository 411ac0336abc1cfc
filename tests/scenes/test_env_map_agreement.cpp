// Environment maps in every estimator (docs/lights.md, "Environment"), on a floor with a diffuse
// and a glossy box lit only by the sun-and-sky map (a 2000x sun in one texel of a 64x32 map):
//  * PT, LT, BDPT-balance and BDPT-power agree per pixel and per 2x2 block (tests/support/
//    estimators.h: Welch's t-test per pixel, binomial bound on the rejections; renders with
//    different seeds); the per-pixel comparisons detect a uniform 10% error in either image, the
//    block comparisons 5%;
//  * MIS: on >= 10^4 sampled full paths ending on the map (s = 0 escapes, s = 1 next-event
//    connections, s >= 2 emission from the map's disk), the definition's weights sum to 1 (1e-9)
//    for the balance, power and uniform heuristics and the production weight equals the
//    definition's within the float32 bound of tests/support/mis_tolerance.h (support/mis_paths.h);
//  * trace shows environment vertices with the map's densities (pmf x pdf of the stored direction)
//    and the definition's weights of its contributions sum to 1;
//  * the wavefront mode renders the same image bit for bit as the megakernel (PT, LT, BDPT
//    balance and power, strategy layers included: support/estimators.h).
#include "scenes/test_env_map_scenes.h"
#include "support/estimators.h"
#include "support/image_stats.h"
#include "support/mis_paths.h"

#include "bdptref/trace.h"

#include <catch2/catch.hpp>

using namespace bdptref;
using namespace bdptref::test;

TEST_CASE("Environment map: PT LT BDPT-balance and BDPT-power agree per pixel on a sun-and-sky lit scene",
          "[envmap][agreement]") {
    const Scene scene = sunSkyBoxesScene(20, 16);
    // PT, LT, BDPT balance, BDPT power; seeds 3000 + 31 i.
    const auto films = renderEveryEstimator(scene, {512, 8192, 256, 256}, 3000, 31);
    const std::vector<std::pair<std::string, MomentImage>> pixels = momentsOfEach(films);
    std::vector<std::pair<std::string, MomentImage>> blocks;
    for (const auto& [name, film] : films) blocks.emplace_back(name + " 2x2", mergeBlocks(momentsOf(film), 2));
    // Per pixel the comparisons must see a uniform 10% error; per 2x2 block (80 blocks) 5%. Light
    // tracing from a map whose disk covers the whole floor is too noisy per pixel for 5% at a
    // bearable sample count, but not per block.
    checkPairwiseAgreement(pixels, 0.10);
    checkPairwiseAgreement(blocks, 0.05);
}

TEST_CASE("Environment map: MIS weights of sampled paths sum to 1 and equal the definition (every strategy)",
          "[envmap][mis]") {
    const Scene scene = sunSkyBoxesScene(16, 16);
    long emission = 0, environmentPaths = 0;
    const MisPathCheck r = checkSampledPathWeights(scene, 9000, 77u, 4, [&](const std::vector<PathVertex>& x, int s) {
        environmentPaths += x.back().infinite;  // the map is the only light
        emission += s >= 2;
    });
    INFO(r.summary());
    CHECK(r.passed());
    CHECK(r.paths >= 10000);
    CHECK(environmentPaths == r.paths);
    CHECK(r.s0 >= 1000);   // escapes onto the map
    CHECK(r.s1 >= 1000);   // next-event samples of the map
    CHECK(emission >= 1000);  // light subpaths from the map's disk
    CHECK(r.t1 >= 500);
}

TEST_CASE("Environment map: the wavefront mode equals the megakernel bit for bit", "[envmap][wavefront]") {
    const Scene scene = sunSkyBoxesScene(16, 12);
    EstimatorSetup base;
    base.spp = 2;
    base.maxDepth = 5;
    base.threads = 2;
    checkWavefrontIdenticalEveryEstimator(scene, base);
}

TEST_CASE("Environment map: trace shows map vertices with their densities", "[envmap][trace]") {
    const Scene scene = sunSkyBoxesScene(16, 16);
    const EnvironmentMap& map = scene.environmentMaps.at(0);
    const double pmf = double(scene.lightSampler().pmf(0));
    TraceSettings ts;
    ts.bdpt.maxDepth = 4;
    long lightStarts = 0, escapes = 0, nee = 0, contributions = 0;
    for (uint64_t k = 0; k < 200; ++k) {
        const TracedSample t = traceSample(scene, ts, int(k % 16), int((k / 16) % 16), k);
        if (!t.lightPath.empty()) {
            // The light subpath starts on the map: its origin density is pmf x pdf(direction),
            // the direction stored (towards the map) in ng.
            const PathVertex& v = t.lightPath[0];
            CHECK(v.infinite);
            CHECK(v.pdfFwd == pmf * double(map.pdf(v.ng)));
            ++lightStarts;
        }
        for (const PathVertex& v : t.cameraPath)
            if (v.infinite) {
                ++escapes;
                CHECK(v.light == scene.environmentLight());
            }
        for (const TracedConnection& c : t.connections) {
            if (c.status != ConnectionStatus::Contributed) continue;
            ++contributions;
            if (c.s == 1) {
                REQUIRE(c.hasSampled);
                CHECK(c.sampled.infinite);
                CHECK(c.sampled.pdfFwd == pmf * double(map.pdf(c.sampled.ng)));
                CHECK(c.densities.lightNextEvent == Approx(pmf * double(map.pdf(c.sampled.ng))).epsilon(1e-12));
                ++nee;
            }
            double sum = 0.0;
            for (double w : c.definitionWeights) sum += w;
            CHECK(sum == Approx(1.0).epsilon(1e-9));
        }
    }
    CHECK(lightStarts >= 150);
    CHECK(escapes >= 50);
    CHECK(nee >= 100);
    CHECK(contributions >= 300);
}
