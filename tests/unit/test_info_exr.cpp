// `bdptref info FILE.exr` (docs/exr.md, "Header attributes"; docs/validate.md, "References"): how
// an image was made, read from its header. It once failed with "unknown scene file type".
#include "support/render_util.h"

#include <catch2/catch.hpp>

using namespace bdptref;
using namespace bdptref::test;

TEST_CASE("info on an EXR prints how the image was made", "[cli][info]") {
    const std::string dir = makeTempDir("info-exr");
    const std::string exr = dir + "/ref.exr";
    REQUIRE(runCli("render " + sourcePath("scenes/cornell-box.gltf") + " -o " + exr +
                   " --width 8 --height 6 --spp 3 --seed 17 --max-depth 2 --integrator bdpt --mis power --depth-layers "
                   "--no-preview -q") == 0);
    std::string out;
    REQUIRE(runCli("info " + exr, &out) == 0);
    INFO(out);
    CHECK_THAT(out, Catch::Contains("8x6 pixels, 2 parts"));
    CHECK_THAT(out, Catch::Contains("made by:      bdptref "));
    CHECK_THAT(out, Catch::Contains("status:       complete"));
    CHECK_THAT(out, Catch::Contains("integrator:   bdpt, megakernel, mis power beta 2"));
    CHECK_THAT(out, Catch::Contains("samples:      3 spp (requested 3), sample range 0:3"));
    CHECK_THAT(out, Catch::Contains("seed:         17"));
    CHECK_THAT(out, Catch::Contains("max depth:    2"));
    CHECK_THAT(out, Catch::Contains("cornell-box.gltf (hash "));
    CHECK_THAT(out, Catch::Contains("render time:  "));
    CHECK_THAT(out, Catch::Contains("command:      bdptref render ") && Catch::Contains("--seed 17"));
    CHECK_THAT(out, Catch::Contains("layers:       R,G,B; count;") && Catch::Contains("depth0..2") &&
                        Catch::Contains("depth0..2.variance") && Catch::Contains("variance"));
    CHECK_THAT(out, Catch::Contains("part:         exact"));

    // An EXR bdptref did not write: its size and layers, and that it has no settings to show.
    ExrImage img;
    img.width = img.height = 2;
    img.channels["R"] = img.channels["G"] = img.channels["B"] = std::vector<float>(4, 0.5f);
    writeImageChannels(dir + "/plain.exr", img);
    REQUIRE(runCli("info " + dir + "/plain.exr", &out) == 0);
    CHECK_THAT(out, Catch::Contains("not written by bdptref") && Catch::Contains("layers:       R,G,B"));
}
