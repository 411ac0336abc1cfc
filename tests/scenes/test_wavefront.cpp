// The wavefront mode (docs/wavefront.md) renders the same image as the megakernel, bit for bit:
// beauty sums and sums of squares, the light (splat) image and every per-(s,t) layer, for PT, LT
// and BDPT (balance and power), on the Cornell box and on mis-zoo with an environment (delta
// BSDFs, punctual lights, an infinite light). Small pools and queue capacities force many pool
// passes and early flushes: the image must not change (nothing is dropped or reordered).
#include "support/estimators.h"
#include "support/render_util.h"

#include "bdptref/exr_io.h"
#include "bdptref/integrator.h"
#include "bdptref/renderer.h"
#include "bdptref/wavefront.h"

#include <catch2/catch.hpp>

#include <fstream>
#include <iterator>

using namespace bdptref;
using namespace bdptref::test;

namespace {

// The settings these tests share: 2 spp, max depth 6, 2 threads, seed 7.
EstimatorSetup wavefrontSetup() {
    EstimatorSetup s;
    s.spp = 2;
    s.maxDepth = 6;
    s.threads = 2;
    s.seed = 7;
    return s;
}

}  // namespace

TEST_CASE("Wavefront equals megakernel bit for bit on the Cornell box", "[wavefront]") {
    const Scene scene = loadTestScene("scenes/cornell-box.gltf", 24, 24);
    checkWavefrontIdenticalEveryEstimator(scene, wavefrontSetup());
}

TEST_CASE("Wavefront equals megakernel on mis-zoo with an environment (delta BSDFs, punctual and infinite lights)", "[wavefront]") {
    const Scene scene = loadTestScene("scenes/mis-zoo.gltf", 24, 16, Rgb(0.3f, 0.35f, 0.4f));
    EstimatorSetup s = wavefrontSetup();
    s.maxDepth = 5;
    checkWavefrontIdenticalEveryEstimator(scene, s);
}

TEST_CASE("Wavefront equals megakernel through an orthographic camera", "[wavefront][camera]") {
    const Scene scene = loadTestSceneOrthographic("scenes/mis-zoo.gltf", 24, 16, 1.6f, Rgb(0.3f, 0.35f, 0.4f));
    EstimatorSetup s = wavefrontSetup();
    s.maxDepth = 5;
    checkWavefrontIdenticalEveryEstimator(scene, s);
}

TEST_CASE("Wavefront equals megakernel on the glTF features scene (normal map, MASK and BLEND, emissive texture)",
          "[wavefront][gltf-features]") {
    const Scene scene = loadTestScene("scenes/gltf-features.gltf", 24, 24);
    EstimatorSetup s = wavefrontSetup();
    s.maxDepth = 5;
    checkWavefrontIdenticalEveryEstimator(scene, s);
}

TEST_CASE("Tiny pools and queues flush early and change nothing", "[wavefront]") {
    const Scene scene = loadTestScene("scenes/mis-zoo.gltf", 20, 20, Rgb(0.2f));
    EstimatorSetup s = wavefrontSetup();
    s.maxDepth = 4;
    s.wavefrontOptions.poolSize = 37;  // not a multiple of the tile or warp size: pool passes split tiles
    s.wavefrontOptions.shadowQueueCapacity = 16;
    s.wavefrontOptions.connectionQueueCapacity = 50;
    for (const char* integrator : {"path", "bdpt"}) {
        s.integrator = integrator;
        s.layers = std::string(integrator) != "path";
        INFO("integrator " << integrator);
        GpuReport r;
        checkWavefrontIdentical(scene, s, &r);
        uint64_t flushes = 0;
        for (const auto& [key, st] : r.stages) {
            flushes += st.flushes;
            if (st.capacity > 0) CHECK(st.maxAtLaunch <= st.capacity);  // a queue never held more than it can
        }
        CHECK(flushes > 0);  // the small queues did overflow ...
        CHECK(r.poolPasses == uint64_t(s.spp) * ((400 + 36) / 37));
        // ... and every camera path still traced its first ray.
        CHECK(r.raysByDepth.at("camera").at(0) == uint64_t(400 * s.spp));
    }
}

TEST_CASE("Wavefront images do not depend on the thread count", "[wavefront]") {
    const Scene scene = loadTestScene("scenes/cornell-box.gltf", 16, 16);
    EstimatorSetup s = wavefrontSetup();
    s.wavefront = true;
    s.wavefrontOptions.poolSize = 64;
    s.threads = 1;
    GpuReport r1, r2;
    const Film a = renderEstimator(scene, s, {}, &r1);
    s.threads = 2;
    const Film b = renderEstimator(scene, s, {}, &r2);
    const FilmDifference d = filmDifference(a, b, s.maxDepth);
    CHECK(d.beauty == 0);
    CHECK(d.light == 0);
    // The figures are deterministic too (queue lengths do not depend on which thread appended).
    CHECK(r1.wavefrontActiveLanes == r2.wavefrontActiveLanes);
    CHECK(r1.connections.size() == r2.connections.size());
    CHECK(r1.trafficBytes == r2.trafficBytes);
}

TEST_CASE("GPU report figures are consistent", "[wavefront]") {
    const Scene scene = loadTestScene("scenes/cornell-box.gltf", 16, 16);
    EstimatorSetup s = wavefrontSetup();
    s.maxDepth = 3;
    s.wavefront = true;
    GpuReport r;
    renderEstimator(scene, s, {}, &r);
    // SIMT efficiencies are fractions; the wavefront launches whole queues, so beats the megakernel here.
    CHECK(r.simtEfficiencyMegakernel() > 0.0);
    CHECK(r.simtEfficiencyMegakernel() <= 1.0);
    CHECK(r.simtEfficiencyWavefront() <= 1.0);
    CHECK(r.simtEfficiencyWavefront() > r.simtEfficiencyMegakernel());
    // Connections: unoccluded <= with a shadow ray or none needed; every (s,t) respects the max depth.
    uint64_t evaluated = 0;
    for (const auto& [st, c] : r.connections) {
        CHECK(st.first + st.second - 2 <= s.maxDepth);
        CHECK(c.contributed <= c.evaluated);
        CHECK(c.shadowRays <= c.evaluated);
        evaluated += c.evaluated;
    }
    CHECK(evaluated == r.stages.at({"connect", -1}).items);
    // Memory: a path never uses more than its static buffers; 1080p needs more than the pool.
    CHECK(r.bytesPerPathPeak <= r.bytesPerPathStatic);
    CHECK(r.bufferBytesFor(1920, 1080) >= uint64_t(1920 * 1080) * r.bytesPerPathStatic);
    CHECK(r.trafficBytesPerSample() > 0.0);
}

TEST_CASE("render --mode wavefront writes the same EXR pixels and a GPU report, bad options exit 2", "[wavefront][cli]") {
    const std::string dir = makeTempDir("wavefront-cli");
    const std::string common = "render " + sourcePath("scenes/cornell-box.gltf") +
                               " --width 16 --height 16 --spp 2 --max-depth 4 --integrator bdpt --no-preview --threads 2";
    std::string out;
    REQUIRE(runCli(common + " -q -o " + dir + "/mega.exr", &out) == 0);
    REQUIRE(runCli(common + " --mode wavefront --wavefront-pool 40 --gpu-report " + dir + "/gpu.json -o " + dir + "/wave.exr", &out) == 0);
    CHECK(out.find("simulated SIMT efficiency") != std::string::npos);  // the stderr summary
    const ExrImage a = readImage(dir + "/mega.exr"), b = readImage(dir + "/wave.exr");
    REQUIRE(a.channels.size() == b.channels.size());
    for (const auto& [name, pixels] : a.channels) {
        INFO(name);
        CHECK(pixels == b.channels.at(name));
    }
    std::string json;
    {
        std::ifstream f(dir + "/gpu.json");
        json.assign(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
    }
    CHECK(json.find("\"poolSize\": 40") != std::string::npos);
    CHECK(json.find("\"bufferBytes1920x1080\"") != std::string::npos);
    CHECK(json.find("\"connection_shadow\"") != std::string::npos);

    CHECK(runCli(common + " --mode warp -o " + dir + "/x.exr", &out) == 2);
    CHECK(out.find("--mode") != std::string::npos);
    CHECK(runCli(common + " --wavefront-pool 64 -o " + dir + "/x.exr", &out) == 2);
    CHECK(out.find("--mode wavefront") != std::string::npos);
    CHECK(runCli(common + " --mode wavefront --wavefront-pool -3 -o " + dir + "/x.exr", &out) == 2);
    CHECK(out.find("--wavefront-pool") != std::string::npos);
}
