// The command-line tool as a user meets it: outputs, metadata, thread-independence of the EXR, the
// same pixels uncompressed, exit code 2 with a clear message for bad input, and Ctrl-C writing the
// partial image.
#include "bdptref/exr_io.h"
#include "support/render_util.h"

#include <catch2/catch.hpp>

#include <filesystem>

using namespace bdptref;
using namespace bdptref::test;
namespace fs = std::filesystem;

namespace {
const std::string kCornell = sourcePath("scenes/cornell-box.gltf");

// The two EXRs hold the same channels, bit for bit.
void requireSameChannels(const ExrImage& a, const ExrImage& b) {
    REQUIRE(a.channels.size() == b.channels.size());
    for (const auto& [name, pixels] : a.channels) {
        INFO(name);
        CHECK(pixels == b.channels.at(name));
    }
}
}  // namespace

TEST_CASE("render writes an EXR with beauty, variance, counts and metadata, plus a PNG", "[cli]") {
    const std::string dir = makeTempDir("cli-render");
    std::string out;
    const int rc = runCli("render " + kCornell + " -o " + dir + "/a.exr --spp 3 --width 16 --height 12 --max-depth 5 --seed 9 -q", &out);
    INFO(out);
    REQUIRE(rc == 0);
    REQUIRE(fs::exists(dir + "/a.png"));
    const ExrImage img = readImage(dir + "/a.exr");
    CHECK(img.width == 16);
    CHECK(img.height == 12);
    for (const char* c : {"R", "G", "B", "variance.R", "variance.G", "variance.B", "count"}) CHECK(img.has(c));
    CHECK(img.at("count", 3, 4) == 3.f);
    CHECK(img.attributes.at("bdptref:spp") == "3");
    CHECK(img.attributes.at("bdptref:seed") == "9");
    CHECK(img.attributes.at("bdptref:maxDepth") == "5");
    CHECK(img.attributes.at("bdptref:integrator") == "path");
    CHECK(img.attributes.at("bdptref:sceneHash").size() == 16);
    CHECK(img.attributes.count("bdptref:renderSeconds") == 1);
    CHECK(img.attributes.count("bdptref:version") == 1);
    // No temporary files are left behind.
    int files = 0;
    for (const auto& e : fs::directory_iterator(dir)) files += e.is_regular_file();
    CHECK(files == 2);
}

TEST_CASE("render accepts --env and the command-line camera options and they change the picture", "[cli]") {
    const std::string dir = makeTempDir("cli-options");
    const std::string sphere = sourcePath("scenes/env-sphere.glb");
    std::string out;
    REQUIRE(runCli("render " + sphere + " -o " + dir + "/env.exr --env 1,0.5,0.25 --spp 2 --width 8 --height 8 --max-depth 1 -q --no-preview", &out) == 0);
    const ExrImage env = readImage(dir + "/env.exr");
    // Convex albedo-0.5 sphere under a constant environment: rho * L per channel (scenes/README.md).
    CHECK(env.at("R", 4, 4) > 0.4f);
    CHECK(env.at("G", 4, 4) < env.at("R", 4, 4));
    CHECK(env.at("B", 4, 4) < env.at("G", 4, 4));
    REQUIRE(runCli("render " + sphere + " -o " + dir + "/cam.exr --env 1,1,1 --camera-pos 0,0,10 --camera-target 0,0,0 --fov 10 --spp 1 --width 8 --height 8 --max-depth 0 -q --no-preview", &out) == 0);
    const ExrImage cam = readImage(dir + "/cam.exr");
    CHECK(cam.at("R", 0, 0) == 1.f);  // the corner sees the environment past the sphere
    CHECK(cam.at("R", 4, 4) == 0.f);  // the centre sees the (non-emissive) sphere
    CHECK(cam.attributes.at("bdptref:camera") == "command line");
}

TEST_CASE("the EXR pixels are bit-identical for --threads 1 and --threads 2", "[cli][determinism]") {
    const std::string dir = makeTempDir("cli-threads");
    const std::string common = " --spp 4 --width 24 --height 16 --max-depth 6 -q --no-preview";
    REQUIRE(runCli("render " + kCornell + " -o " + dir + "/t1.exr --threads 1" + common) == 0);
    REQUIRE(runCli("render " + kCornell + " -o " + dir + "/t2.exr --threads 2" + common) == 0);
    requireSameChannels(readImage(dir + "/t1.exr"), readImage(dir + "/t2.exr"));
}

TEST_CASE("render with --exr-compression none writes the same channels bit for bit, uncompressed", "[cli]") {
    // validate's renders with strategy layers use it: ZIP took half the time of a 5-spp render.
    const std::string dir = makeTempDir("cli-compression");
    const std::string common = " --spp 2 --width 16 --height 12 --max-depth 4 --integrator bdpt --strategies -q --no-preview";
    REQUIRE(runCli("render " + kCornell + " -o " + dir + "/zip.exr" + common) == 0);
    REQUIRE(runCli("render " + kCornell + " -o " + dir + "/none.exr --exr-compression none" + common) == 0);
    const ExrImage a = readImage(dir + "/zip.exr"), b = readImage(dir + "/none.exr");
    CHECK(a.attributes.at("compression") == "zip");
    CHECK(b.attributes.at("compression") == "none");
    CHECK(fs::file_size(dir + "/none.exr") > fs::file_size(dir + "/zip.exr"));
    requireSameChannels(a, b);
    checkInputError("render " + kCornell + " -o " + dir + "/x.exr --exr-compression lzma", "--exr-compression");
}

TEST_CASE("bad input exits with code 2 and names the problem", "[cli][errors]") {
    const std::string dir = makeTempDir("cli-bad");
    struct Case { std::string args, expect; };
    const Case cases[] = {
        {"render " + dir + "/missing.gltf -o " + dir + "/x.exr", "missing.gltf"},
        {"render " + kCornell + " -o " + dir + "/x.exr --spp 0", "--spp"},
        {"render " + kCornell + " -o " + dir + "/x.exr --width 0", "--width"},
        {"render " + kCornell + " -o " + dir + "/x.exr --width 100000 --height 100000", "out of range"},
        {"render " + kCornell + " -o " + dir + "/x.exr --env 1,a,1", "--env"},
        {"render " + kCornell + " -o " + dir + "/x.exr --env -1,1,1", "--env"},
        {"render " + kCornell + " -o " + dir + "/no/such/folder/x.exr", "cannot write"},
        {"render " + kCornell + " -o " + dir + "/x.exr --integrator magic", "magic"},
        {"render " + kCornell + " -o " + dir + "/x.exr --max-depth -1", "--max-depth"},
        {"render " + kCornell + " -o " + dir + "/x.exr --camera-pos 0,0,0", "--camera-target"},
        {"render " + kCornell + " -o " + dir + "/x.exr --seed -5", "--seed"},
        {"render " + kCornell + " -o " + dir + "/x.exr --bogus-option", "bogus"},
        {"info " + dir + "/missing.glb", "missing.glb"},
    };
    for (const Case& c : cases) checkInputError(c.args, c.expect);
    CHECK_FALSE(fs::exists(dir + "/x.exr"));
}

TEST_CASE("--help explains every subcommand", "[cli]") {
    std::string out;
    CHECK(runCli("--help", &out) == 0);
    CHECK(out.find("render") != std::string::npos);
    CHECK(out.find("info") != std::string::npos);
    CHECK(runCli("render --help", &out) == 0);
    for (const char* opt : {"--spp", "--max-depth", "--seed", "--threads", "--env", "--integrator", "--width"})
        CHECK(out.find(opt) != std::string::npos);
}

TEST_CASE("info prints what was loaded", "[cli]") {
    std::string out;
    REQUIRE(runCli("info " + kCornell, &out) == 0);
    CHECK(out.find("triangles:") != std::string::npos);
    CHECK(out.find("lights:") != std::string::npos);
    CHECK(out.find("camera:") != std::string::npos);
}

namespace {
// Stops a long render with `signal` after 2 s: the EXR must hold the completed passes with their
// true count, and the exit code must be 128 + signal.
void checkInterruptedRender(const char* signal, int expectedExit) {
    const std::string dir = makeTempDir(std::string("cli-sig") + signal);
    const std::string exr = dir + "/partial.exr";
    // The signal is sent once the first pass is done (its progress line is on stderr), not after a
    // fixed sleep: a loaded machine may not have finished a pass in any fixed time.
    const std::string log = dir + "/stderr.txt";
    const std::string script = "sh -c '" + std::string(bdptref::test::bdptrefBinary()) + " render " + kCornell + " -o " + exr +
                               " --spp 1000000 --width 16 --height 16 --no-preview 2>" + log +
                               " & pid=$!; for i in $(seq 1200); do grep -q progress: " + log +
                               " && break; sleep 0.05; done; kill -" + signal + " $pid; wait $pid; echo rc=$?'";
    FILE* p = ::popen(script.c_str(), "r");
    REQUIRE(p);
    char buf[256] = {0};
    std::string out;
    while (std::fgets(buf, sizeof buf, p)) out += buf;
    ::pclose(p);
    INFO(out);
    CHECK(out.find("rc=" + std::to_string(expectedExit)) != std::string::npos);
    REQUIRE(fs::exists(exr));
    const ExrImage img = readImage(exr);
    CHECK(img.attributes.at("bdptref:status") == "interrupted");
    const int spp = std::stoi(img.attributes.at("bdptref:spp"));
    CHECK(spp > 0);
    CHECK(spp < 1000000);
    for (float c : img.channels.at("count")) CHECK(c == float(spp));
}
}  // namespace

TEST_CASE("SIGINT writes the completed passes with their true sample count and exits 130", "[cli][interrupt]") {
    checkInterruptedRender("INT", 130);
}

TEST_CASE("SIGTERM writes the completed passes with their true sample count and exits 143", "[cli][interrupt]") {
    checkInterruptedRender("TERM", 143);
}
