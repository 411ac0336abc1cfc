// `bdptref render` and `compare` as a user runs them, on the papercuts of issue 12: a crop of a
// huge image is held in memory as the crop only (EXR data window) and gives the same pixels as
// the full render; a request that cannot fit is refused up front with its size; --time 0 and
// --checkpoint-every 0 are refused; compare refuses images whose statistics are unusable.
// (--resume from the header alone: test_cli_ground_truth.cpp, also tagged [rendercli].)
#include "bdptref/checkpoint.h"
#include "bdptref/exr_io.h"
#include "support/render_util.h"

#include <catch2/catch.hpp>

#include <sys/wait.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <limits>

using namespace bdptref;
using namespace bdptref::test;
namespace fs = std::filesystem;

namespace {

const std::string kCornell = sourcePath("scenes/cornell-box.gltf");

// AddressSanitizer reserves terabytes of address space for its shadow memory at start-up, so a
// sanitized binary cannot start under `ulimit -v` at all: there the limit is left out (the
// Release suite, which CI also runs, checks it).
#if defined(__SANITIZE_ADDRESS__)
constexpr bool kAddressSpaceLimitUsable = false;
#else
constexpr bool kAddressSpaceLimitUsable = true;
#endif

// runCli under an address-space limit (ulimit -v, KiB): a film of the full image could not even
// be allocated under it.
int runCliWithMemoryLimit(const std::string& args, long kib, std::string* output) {
    const std::string limit = kAddressSpaceLimitUsable ? "ulimit -v " + std::to_string(kib) + "; " : "";
    const std::string cmd = limit + std::string(bdptref::test::bdptrefBinary()) + " " + args + " 2>&1";
    FILE* p = ::popen(cmd.c_str(), "r");
    if (!p) return -1;
    std::array<char, 4096> buf;
    size_t k;
    while ((k = std::fread(buf.data(), 1, buf.size(), p)) > 0) output->append(buf.data(), k);
    const int status = ::pclose(p);
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

}  // namespace

TEST_CASE("a 4x4 crop of a 20000x20000 image renders in little memory, and the EXR's data window is the crop",
          "[rendercli][crop]") {
    const std::string dir = makeTempDir("rendercli-bigcrop");
    std::string out;
    const auto start = std::chrono::steady_clock::now();
    // 1 GiB of address space: the full film alone would need 30 GiB (80 bytes per pixel).
    const int rc = runCliWithMemoryLimit("render " + kCornell + " --width 20000 --height 20000 --crop 9998,9997,10002,10001 "
                                         "--spp 2 --max-depth 2 -q -o " + dir + "/big.exr",
                                         1024L * 1024L, &out);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    INFO(out);
    REQUIRE(rc == 0);
    CHECK(seconds < 60.0);  // it was 19 s for a 2048^2 image before; a 4x4 film takes well under 1 s
    const ExrImage img = readImage(dir + "/big.exr");
    CHECK(img.width == 4);
    CHECK(img.height == 4);
    CHECK(img.window == FilmWindow{20000, 20000, 9998, 9997, 4, 4});
    CHECK(img.channels.at("count") == std::vector<float>(16, 2.f));
    const FilmFile f = readFilmExr(dir + "/big.exr");  // the exact state reads back with its window
    CHECK(f.film.window() == img.window);
    CHECK(f.film.minCount() == 2);
    // The preview is the window too.
    const ExrImage png = readImage(dir + "/big.png");
    CHECK(png.width == 4);
    CHECK(png.height == 4);
}

TEST_CASE("crop pixels equal the same pixels of the uncropped render, bit for bit", "[rendercli][crop]") {
    // The path tracer's pixels do not depend on the window (camera rays are keyed by the full-image
    // pixel); for bdpt/lt the window changes the camera importance (docs/camera.md), so only the
    // expected values agree there.
    const std::string dir = makeTempDir("rendercli-crop-same");
    for (const char* mode : {"megakernel", "wavefront"}) {
        INFO(mode);
        const std::string common = std::string(" --width 16 --height 12 --spp 3 --max-depth 4 --seed 3 -q --no-preview --mode ") + mode;
        REQUIRE(runCli("render " + kCornell + common + " -o " + dir + "/full.exr") == 0);
        REQUIRE(runCli("render " + kCornell + common + " --crop 3,2,13,9 -o " + dir + "/crop.exr") == 0);
        const ExrImage full = readImage(dir + "/full.exr"), crop = readImage(dir + "/crop.exr");
        REQUIRE(crop.window == FilmWindow{16, 12, 3, 2, 10, 7});
        REQUIRE(full.window == FilmWindow::full(16, 12));
        const FilmFile ff = readFilmExr(dir + "/full.exr"), fc = readFilmExr(dir + "/crop.exr");
        int differing = 0;
        for (int y = 0; y < 7; ++y)
            for (int x = 0; x < 10; ++x) {
                for (const char* c : {"R", "G", "B", "variance.R", "variance.G", "variance.B", "count"})
                    differing += crop.at(c, x, y) != full.at(c, x + 3, y + 2);
                differing += fc.film.sum(x, y) != ff.film.sum(x + 3, y + 2);
                differing += fc.film.sumSquares(x, y) != ff.film.sumSquares(x + 3, y + 2);
            }
        CHECK(differing == 0);
    }
}

TEST_CASE("a render that cannot fit in memory is refused up front with its estimated size", "[rendercli][memory]") {
    const std::string dir = makeTempDir("rendercli-toobig");
    // 4e8 pixels with 594 strategy layers: ~88 TiB, more than any machine this runs on.
    checkInputError("render " + kCornell + " --width 20000 --height 20000 --integrator bdpt --strategies --max-depth 32 "
                    "--spp 1 -q -o " + dir + "/x.exr",
                    "needs about");
    CHECK_FALSE(fs::exists(dir + "/x.exr"));
    std::string out;
    if (!kAddressSpaceLimitUsable) return;  // the rest needs `ulimit -v` (see kAddressSpaceLimitUsable)
    // Under a 1 GiB limit, a plain 20000x20000 film (30 GiB) is refused the same way, naming the limit.
    const int rc = runCliWithMemoryLimit("render " + kCornell + " --width 20000 --height 20000 --spp 1 -q -o " + dir + "/y.exr",
                                         1024L * 1024L, &out);
    INFO(out);
    CHECK(rc == 2);
    CHECK(out.find("GiB") != std::string::npos);
    CHECK(out.find("ulimit -v") != std::string::npos);
    CHECK(out.find("bad_alloc") == std::string::npos);
    CHECK_FALSE(fs::exists(dir + "/y.exr"));
}

TEST_CASE("render refuses --time 0 and --checkpoint-every 0 like negative values", "[rendercli][errors]") {
    const std::string dir = makeTempDir("rendercli-zero");
    const std::string r = "render " + kCornell + " --width 8 --height 8 -q -o " + dir + "/x.exr";
    checkInputError(r + " --time 0", "--time must be a positive");
    checkInputError(r + " --checkpoint-every 0", "--checkpoint-every must be a positive");
    checkInputError(r + " --time -1", "--time must be a positive");
    // Checked before the scene is read: a missing scene is not what is reported.
    checkInputError("render " + dir + "/missing.gltf -o " + dir + "/x.exr --time 0", "--time");
    CHECK_FALSE(fs::exists(dir + "/x.exr"));
}

TEST_CASE("compare refuses images with negative or non-finite variances, or variances without samples",
          "[rendercli][compare]") {
    const std::string dir = makeTempDir("rendercli-compare-bad");
    const int w = 4, h = 3;
    const size_t n = size_t(w) * size_t(h);
    // A well-formed image: mean 1, variance 0.01, 16 samples everywhere.
    auto write = [&](const std::string& name, const std::string& channel, size_t pixel, float value) {
        std::vector<ExrLayer> layers;
        for (const char* c : {"R", "G", "B"}) layers.push_back({c, std::vector<float>(n, 1.f)});
        for (const char* c : {"variance.R", "variance.G", "variance.B"}) layers.push_back({c, std::vector<float>(n, 0.01f)});
        layers.push_back({"count", std::vector<float>(n, 16.f)});
        for (ExrLayer& l : layers)
            if (l.name == channel) l.pixels[pixel] = value;
        writeLayersExr(dir + "/" + name, w, h, layers, ExrMetadata{});
    };
    write("good.exr", "", 0, 0.f);
    write("negvar.exr", "variance.G", 5, -0.5f);
    write("nanvar.exr", "variance.B", 7, std::numeric_limits<float>::quiet_NaN());
    write("infmean.exr", "R", 2, std::numeric_limits<float>::infinity());
    write("nocount.exr", "count", 4, 0.f);
    const std::string good = dir + "/good.exr";
    std::string out;
    REQUIRE(runCli("compare " + good + " " + good, &out) == 0);  // the control
    // Pixel 5 of a 4-wide image is (1, 1).
    checkInputError("compare " + good + " " + dir + "/negvar.exr", "reference image " + dir + "/negvar.exr: pixel (1, 1) channel variance.G");
    checkInputError("compare " + dir + "/negvar.exr " + good, "test image " + dir + "/negvar.exr: pixel (1, 1)");
    checkInputError("compare " + good + " " + dir + "/nanvar.exr", "pixel (3, 1) channel variance.B");
    checkInputError("compare " + good + " " + dir + "/infmean.exr", "pixel (2, 0) channel R is not finite");
    checkInputError("compare " + good + " " + dir + "/nocount.exr", "with count 0");
}

TEST_CASE("compare and merge refuse crop renders of different windows", "[rendercli][crop]") {
    const std::string dir = makeTempDir("rendercli-windows");
    const std::string common = " --width 16 --height 12 --max-depth 2 -q --no-preview";
    REQUIRE(runCli("render " + kCornell + common + " --spp 2 --crop 0,0,8,6 -o " + dir + "/a.exr") == 0);
    REQUIRE(runCli("render " + kCornell + common + " --spp 2 --crop 8,6,16,12 -o " + dir + "/b.exr") == 0);
    checkInputError("compare " + dir + "/a.exr " + dir + "/b.exr", "data window");
    REQUIRE(runCli("render " + kCornell + common + " --crop 0,0,8,6 --sample-range 2:4 -o " + dir + "/a2.exr") == 0);
    // The same window merges; a different one is refused (the settings name the crop).
    std::string out;
    CHECK(runCli("merge " + dir + "/a.exr " + dir + "/a2.exr -o " + dir + "/m.exr", &out) == 0);
    CHECK(readImage(dir + "/m.exr").window == FilmWindow{16, 12, 0, 0, 8, 6});
    REQUIRE(runCli("render " + kCornell + common + " --crop 8,6,16,12 --sample-range 2:4 -o " + dir + "/b2.exr") == 0);
    checkInputError("merge " + dir + "/a.exr " + dir + "/b2.exr -o " + dir + "/m2.exr", "crop: 8,6,16,12 vs 0,0,8,6");
}
