// `bdptref render --depth-layers` as a user runs it (docs/exr.md "Channels", docs/compare.md
// "Localising a bug by path depth"):
//  * the EXR has depth<d>.{R,G,B} and depth<d>.variance.{R,G,B} for d = 0..max-depth, beside the
//    strategy layers when --strategies is given too (the path tracer's s = 0 and s = 1 only hold
//    light), and the float layers add up to R,G,B;
//  * the exact state of the layers survives writing and reading bit for bit, so --resume gives
//    the same layers as an uninterrupted render and `merge` of sample-range parts those of the
//    single render (bit for bit here: the parts after the first hold one pass each, so the merge
//    adds the same doubles in the same order);
//  * the wavefront mode writes the same file contents;
//  * `compare --layer depth2` flags a test image whose depth-2 layer is 10% too bright and passes
//    the unedited one, while depths 1 and 3 of the edited image still pass: the depth is found;
//  * impossible requests are refused with exit 2 and a message naming the option.
#include "bdptref/checkpoint.h"
#include "bdptref/exr_io.h"
#include "support/render_util.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

using namespace bdptref;
using namespace bdptref::test;
namespace fs = std::filesystem;

namespace {

const std::string kCornell = sourcePath("scenes/cornell-box.gltf");
const char* const kRgb[3] = {"R", "G", "B"};

std::string small(const std::string& integrator, int maxDepth, int seed) {
    return " --width 12 --height 10 --max-depth " + std::to_string(maxDepth) + " --integrator " + integrator + " --seed " +
           std::to_string(seed) + " -q --no-preview";
}

// The depth layers of two films: same depth, passes and non-finite count, sums and squares bit for bit.
void requireSameDepthLayers(const Film& a, const Film& b) {
    REQUIRE(a.depths().maxDepth() == b.depths().maxDepth());
    CHECK(a.depths().passes() == b.depths().passes());
    CHECK(a.depths().nonFiniteValues() == b.depths().nonFiniteValues());
    CHECK(a.depths().sums() == b.depths().sums());
    CHECK(a.depths().sumSquares() == b.depths().sumSquares());
}

}  // namespace

TEST_CASE("render --depth-layers writes depth<d> and depth<d>.variance channels for d = 0..max-depth, with --strategies too",
          "[cli][depthlayers][exr]") {
    const std::string dir = makeTempDir("depth-channels");
    for (const std::string integrator : {"path", "lt", "bdpt"}) {
        INFO(integrator);
        const std::string exr = dir + "/" + integrator + ".exr";
        const std::string strategies = " --strategies";
        REQUIRE(runCli("render " + kCornell + " -o " + exr + " --spp 4 --depth-layers" + strategies + small(integrator, 3, 2)) == 0);
        const ExrImage img = readImage(exr);
        for (int d = 0; d <= 3; ++d)
            for (const char* c : kRgb) {
                CHECK(img.has("depth" + std::to_string(d) + "." + c));
                CHECK(img.has("depth" + std::to_string(d) + ".variance." + c));
            }
        CHECK_FALSE(img.has("depth4.R"));
        CHECK(img.has("s1t2.weighted.R"));
        // The path tracer's strategies: emitter hits (s = 0) and next events (s = 1), nothing else.
        if (integrator == "path")
            for (const char* layer : {"s2t1.unweighted.G", "s2t2.weighted.R", "s3t1.unweighted.B"}) {
                INFO(layer);
                double sum = 0;
                for (float v : img.channels.at(layer)) sum += double(v);
                CHECK(sum == 0.0);
            }
        // The float layers add up to the beauty (float rounding of the means).
        double worst = 0;
        for (int c = 0; c < 3; ++c)
            for (size_t i = 0; i < img.channels.at("R").size(); ++i) {
                double sum = 0;
                for (int d = 0; d <= 3; ++d) sum += img.channels.at("depth" + std::to_string(d) + "." + kRgb[c])[i];
                const double beauty = img.channels.at(kRgb[c])[i];
                worst = std::max(worst, std::abs(sum - beauty) / std::max(1e-6, beauty));
            }
        CHECK(worst < 1e-5);
        CHECK(img.attributes.at(kAttrSettings).find("depthLayers=on") != std::string::npos);
        CHECK(img.attributes.at("bdptref:commandLine").find(" --depth-layers") != std::string::npos);
        // The exact state: read back, the layers' means are the float channels.
        const FilmFile f = readFilmExr(exr);
        REQUIRE(f.film.depths().maxDepth() == 3);
        CHECK(f.film.depths().passes() == 4);
        CHECK(float(f.film.depths().mean(2, 5, 7).y) == img.at("depth2.G", 5, 7));
        CHECK(float(f.film.depths().varianceOfMean(1, 3, 4).z) == img.at("depth1.variance.B", 3, 4));
        // The wavefront mode writes the same pixels and layers.
        const std::string wave = dir + "/" + integrator + "-wavefront.exr";
        REQUIRE(runCli("render " + kCornell + " -o " + wave + " --spp 4 --depth-layers --mode wavefront --wavefront-pool 32" +
                       strategies + small(integrator, 3, 2)) == 0);
        checkSameImageChannels(exr, wave);
        requireSameDepthLayers(f.film, readFilmExr(wave).film);
    }
    // Without the option: no depth channels, and the header's settings have no depthLayers key
    // (so files written before the option existed keep resuming and merging).
    REQUIRE(runCli("render " + kCornell + " -o " + dir + "/plain.exr --spp 2" + small("path", 3, 2)) == 0);
    const ExrImage plain = readImage(dir + "/plain.exr");
    CHECK_FALSE(plain.has("depth0.R"));
    CHECK(plain.attributes.at(kAttrSettings).find("depthLayers") == std::string::npos);
    CHECK_FALSE(readFilmExr(dir + "/plain.exr").film.depths().enabled());
}

TEST_CASE("render --depth-layers --resume and merge keep the depth layers exactly", "[cli][depthlayers][groundtruth]") {
    const std::string dir = makeTempDir("depth-resume");
    std::string out;
    for (const std::string integrator : {"path", "bdpt"}) {
        INFO(integrator);
        const std::string s = small(integrator, 4, 5) + " --depth-layers";
        const std::string p = dir + "/" + integrator;
        REQUIRE(runCli("render " + kCornell + " -o " + p + "-whole.exr --spp 5" + s, &out) == 0);
        // Interrupted after 2 passes, resumed from the header alone (the layers come from it too).
        REQUIRE(runCli("render " + kCornell + " -o " + p + "-part.exr --spp 2" + s, &out) == 0);
        REQUIRE(runCli("render --resume " + p + "-part.exr -o " + p + "-part.exr --spp 5 -q --no-preview", &out) == 0);
        checkSameImageChannels(p + "-whole.exr", p + "-part.exr");
        FilmFile whole = readFilmExr(p + "-whole.exr");
        requireSameDepthLayers(whole.film, readFilmExr(p + "-part.exr").film);
        // Sample-range parts 0:3, 3:4, 4:5 merged (given out of order).
        for (const char* r : {"0:3", "3:4", "4:5"})
            REQUIRE(runCli("render " + kCornell + " -o " + p + "-r" + std::string(r, 1) + ".exr --sample-range " + r + s, &out) == 0);
        REQUIRE(runCli("merge " + p + "-r4.exr " + p + "-r0.exr " + p + "-r3.exr -o " + p + "-merged.exr -q", &out) == 0);
        FilmFile merged = readFilmExr(p + "-merged.exr");
        CHECK(merged.film.samples().text() == "0:5");
        requireSameDepthLayers(whole.film, merged.film);
        CHECK(merged.film.accumulators().sum == whole.film.accumulators().sum);
    }
    // A part without depth layers does not merge with one that has them; a checkpoint without them
    // cannot be resumed with them.
    REQUIRE(runCli("render " + kCornell + " -o " + dir + "/plain.exr --sample-range 5:6" + small("path", 4, 5), &out) == 0);
    checkInputError("merge " + dir + "/path-r0.exr " + dir + "/path-r3.exr " + dir + "/path-r4.exr " + dir + "/plain.exr -o " +
                        dir + "/bad.exr",
                    "depthLayers");
    checkInputError("render --resume " + dir + "/plain.exr -o " + dir + "/bad.exr --sample-range 5:7 --depth-layers -q", "--depth-layers");
    CHECK_FALSE(fs::exists(dir + "/bad.exr"));
}

TEST_CASE("compare --layer depth2 finds the depth of a bias in one depth layer", "[cli][depthlayers][compare]") {
    // Two correct path-traced renders (different seeds); in the test image the depth-2 layer is
    // made 10% brighter (mean x 1.1, variance of the mean x 1.21) and the beauty gets that 10% too.
    const std::string dir = makeTempDir("depth-compare");
    const std::string common = " --integrator path --depth-layers --spp 256 --width 32 --height 32 --max-depth 4 -q --no-preview";
    REQUIRE(runCli("render " + kCornell + " -o " + dir + "/t.exr --seed 3" + common) == 0);
    REQUIRE(runCli("render " + kCornell + " -o " + dir + "/r.exr --seed 4" + common) == 0);
    ExrImage wrong = readImage(dir + "/t.exr");
    for (int c = 0; c < 3; ++c) {
        std::vector<float>& layer = wrong.channels.at(std::string("depth2.") + kRgb[c]);
        std::vector<float>& beauty = wrong.channels.at(kRgb[c]);
        for (size_t i = 0; i < layer.size(); ++i) {
            beauty[i] += 0.1f * layer[i];
            layer[i] *= 1.1f;
        }
        for (float& v : wrong.channels.at(std::string("depth2.variance.") + kRgb[c])) v *= 1.21f;
    }
    writeImageChannels(dir + "/wrong.exr", wrong);
    int rc = -1;
    std::string out;
    for (int d = 0; d <= 4; ++d) {  // control: every depth of the correct pair agrees
        rc = runCli("compare " + dir + "/t.exr " + dir + "/r.exr --layer depth" + std::to_string(d), &out);
        INFO("depth " << d << ": " << out);
        CHECK(rc == 0);
    }
    rc = runCli("compare " + dir + "/wrong.exr " + dir + "/r.exr --layer depth2", &out);
    INFO(out);
    CHECK(rc == 1);
    CHECK(out.find("INCONSISTENT") != std::string::npos);
    for (int d : {1, 3}) {  // the neighbouring depths of the edited image are untouched
        rc = runCli("compare " + dir + "/wrong.exr " + dir + "/r.exr --layer depth" + std::to_string(d), &out);
        INFO("depth " << d << ": " << out);
        CHECK(rc == 0);
    }
    // A layer the file does not have is named.
    checkInputError("compare " + dir + "/t.exr " + dir + "/r.exr --layer depth5", "depth5");
}

TEST_CASE("render --depth-layers: refused requests and the help text", "[cli][depthlayers][rendercli]") {
    const std::string dir = makeTempDir("depth-refused");
    checkInputError("render " + kCornell + " -o " + dir + "/x.exr --depth-layers --max-depth 300 --spp 1 -q", "--depth-layers");
    // 4e8 pixels with 257 depth layers: ~5 TB of accumulators, refused up front naming the layers.
    checkInputError("render " + kCornell + " --width 20000 --height 20000 --depth-layers --max-depth 256 --spp 1 -q -o " + dir +
                        "/x.exr",
                    "depth layers");
    CHECK_FALSE(fs::exists(dir + "/x.exr"));
    std::string out;
    REQUIRE(runCli("render --help", &out) == 0);
    CHECK(out.find("--depth-layers") != std::string::npos);
    CHECK(out.find("depth<D>.variance") != std::string::npos);
    CHECK(out.find("compare --layer depth<D>") != std::string::npos);
}
