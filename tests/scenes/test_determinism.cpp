// docs/contracts.md, contracts 2 (RNG) and 4 (film): a pixel sample is a pure function of (scene,
// settings, seed, pixel, sample index), and accumulation is order-independent of threads: 1 and 2
// threads give bit-identical films.
#include "support/render_util.h"

#include <catch2/catch.hpp>

using namespace bdptref;
using namespace bdptref::test;

TEST_CASE("Films are bit-identical for 1 and 2 threads", "[determinism]") {
    const Scene scene = loadTestScene("scenes/cornell-box.gltf", 40, 24);
    const Film a = renderFilm(scene, "path", 4, 8, 5, 1);
    const Film b = renderFilm(scene, "path", 4, 8, 5, 2);
    bool identical = true;
    for (int y = 0; y < a.height(); ++y)
        for (int x = 0; x < a.width(); ++x)
            identical = identical && a.sum(x, y) == b.sum(x, y) && a.sumSquares(x, y) == b.sumSquares(x, y) &&
                        a.count(x, y) == b.count(x, y);
    CHECK(identical);
    // And the image is not trivially black (the comparison would be vacuous).
    CHECK(pooledMean(a).mean.x > 0.01);
}

TEST_CASE("A different seed gives a different image, the same seed the same one", "[determinism]") {
    const Scene scene = loadTestScene("scenes/cornell-box.gltf", 16, 16);
    const Film a = renderFilm(scene, "path", 2, 8, 1);
    const Film b = renderFilm(scene, "path", 2, 8, 1);
    const Film c = renderFilm(scene, "path", 2, 8, 2);
    int same = 0, differ = 0;
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x) {
            same += a.sum(x, y) == b.sum(x, y);
            differ += a.sum(x, y) != c.sum(x, y);
        }
    CHECK(same == 256);
    CHECK(differ > 200);
}
