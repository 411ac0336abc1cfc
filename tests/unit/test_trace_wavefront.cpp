// `bdptref trace --mode wavefront` (docs/trace-and-mis.md): one pixel sample computed by the
// wavefront scheduler's stages and read back from their buffers.
//
//  * The wavefront trace equals the megakernel trace field for field, bit for bit: the JSON of
//    both (every vertex of both subpaths, every (s, t) with its status, reason, unoccluded and
//    weighted contribution, MIS weight, fresh endpoint, full path, densities, definition weights,
//    L and splats; floats written exactly) is byte-identical apart from settings.mode, on 12
//    pixels x 2 samples of the Cornell box and of mis-zoo with an environment (delta BSDFs,
//    punctual lights, an infinite light), for lt, bdpt balance and bdpt power, with default queues
//    and with tiny ones that make the connect and shadow stages flush early. The stage records
//    agree with it entry by entry (the queue holds exactly the evaluated strategies; occluded <=>
//    connected with a shadow ray that failed; finish's weight and accumulate's value are the
//    trace's).
//  * The traced values are what a 1-spp wavefront render puts in the film: every pixel of a
//    render (crop window and small tiles on mis-zoo) rebuilt from wavefront traces - each pixel's
//    L plus the splats of all pixels' light subpaths, summed in the renderer's tile order - has
//    bit-identical film sums and light image.
//  * The command: `--mode wavefront` prints the megakernel's JSON plus a "wavefront" object.
// The path tracer has no wavefront trace (its bounce trace is the megakernel's, test_trace_path.cpp;
// its two strategies' layers are bit-identical in both modes, test_wavefront.cpp): not covered.
#include "support/render_util.h"

#include "bdptref/integrator.h"
#include "bdptref/path_io.h"
#include "bdptref/renderer.h"
#include "bdptref/scene.h"
#include "bdptref/trace.h"
#include "bdptref/wavefront.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>

using namespace bdptref;
using namespace bdptref::test;
using Json = nlohmann::ordered_json;

namespace {

const Rgb kZooEnv(0.3f, 0.35f, 0.4f);  // as test_trace_mis.cpp: the environment through the ceiling opening

struct Mode {
    const char* integrator;
    MisHeuristic heuristic;
};
const Mode kModes[] = {{"lt", MisHeuristic::Balance}, {"bdpt", MisHeuristic::Balance}, {"bdpt", MisHeuristic::Power}};

TraceSettings traceSettings(const Mode& m, int maxDepth, bool fullPaths) {
    TraceSettings ts;
    ts.integrator = m.integrator;
    ts.seed = 5;
    ts.bdpt.maxDepth = maxDepth;
    ts.bdpt.mis.heuristic = m.heuristic;
    ts.fullPaths = fullPaths;
    return ts;
}

// The first place two JSON values differ ("" when equal), for a readable failure.
std::string firstDifference(const Json& a, const Json& b, const std::string& where) {
    if (a.type() != b.type()) return where + ": type";
    if (a.is_object()) {
        for (auto it = a.begin(); it != a.end(); ++it) {
            if (!b.contains(it.key())) return where + "." + it.key() + ": missing";
            const std::string d = firstDifference(it.value(), b[it.key()], where + "." + it.key());
            if (!d.empty()) return d;
        }
        return a.size() == b.size() ? "" : where + ": extra keys";
    }
    if (a.is_array()) {
        for (size_t i = 0; i < std::min(a.size(), b.size()); ++i) {
            const std::string d = firstDifference(a[i], b[i], where + "[" + std::to_string(i) + "]");
            if (!d.empty()) return d;
        }
        return a.size() == b.size() ? "" : where + ": length";
    }
    return a.dump() == b.dump() ? "" : where + ": " + a.dump() + " vs " + b.dump();
}

bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }
bool sameBits(const Rgb& a, const Rgb& b) { return std::memcmp(&a, &b, sizeof a) == 0; }

}  // namespace

TEST_CASE("wavefront trace: equals the megakernel trace field for field", "[trace][wavefront]") {
    struct Case {
        std::string scene;
        Rgb env;
    };
    const Case cases[] = {{"scenes/cornell-box.gltf", Rgb(0.f)}, {"scenes/mis-zoo.gltf", kZooEnv}};
    const int width = 24, height = 18, maxDepth = 6;
    long contributed = 0, occluded = 0, splats = 0, deltaVertex = 0, queueEntries = 0, flushedSamples = 0;
    for (const Case& c : cases) {
        const Scene scene = loadTestScene(c.scene, width, height, c.env);
        for (const Mode& m : kModes) {
            const TraceSettings ts = traceSettings(m, maxDepth, true);
            for (int py = 2; py < height; py += 5)
                for (int px = 1; px < width; px += 6)
                    for (uint64_t sample = 0; sample < 2; ++sample) {
                        const TracedSample mega = traceSample(scene, ts, px, py, sample);
                        // Odd samples through tiny queues: connect and shadow flush early, many times.
                        WavefrontOptions tiny;
                        tiny.connectionQueueCapacity = 3;
                        tiny.shadowQueueCapacity = 2;
                        const TracedSample wave = traceSampleWavefront(scene, ts, px, py, sample, sample % 2 ? &tiny : nullptr);
                        INFO(c.scene << " " << m.integrator << " heuristic " << int(m.heuristic) << " pixel (" << px << ", "
                                     << py << ") sample " << sample);
                        CHECK(wave.mode == "wavefront");
                        Json a = traceToJson(mega, scene, nullptr), b = traceToJson(wave, scene, nullptr);
                        CHECK(b["settings"]["mode"] == "wavefront");
                        b["settings"]["mode"] = "megakernel";
                        CHECK(firstDifference(a, b, "trace") == "");
                        CHECK(a.dump() == b.dump());  // every float exactly (-0 and 0 differ in the text)

                        // The stage records against the trace: the queue holds exactly the evaluated strategies.
                        size_t evaluated = 0;
                        for (const TracedConnection& tc : mega.connections) {
                            if (tc.status == ConnectionStatus::DepthLimit || tc.status == ConnectionStatus::DepthZeroRule) continue;
                            ++evaluated;
                            const WavefrontQueueRecord* r = nullptr;
                            for (const WavefrontQueueRecord& q : wave.connectionQueue)
                                if (q.s == tc.s && q.t == tc.t) r = &q;
                            REQUIRE(r);
                            CHECK(r->visible == (tc.status == ConnectionStatus::Contributed));
                            CHECK((r->connected && r->shadowRay && !r->visible) == (tc.status == ConnectionStatus::Occluded));
                            if (r->visible) {
                                CHECK(sameBits(r->unoccluded, tc.unweighted));
                                CHECK(sameBits(r->weight, tc.weight));
                                CHECK(sameBits(r->weighted, tc.weighted));
                            }
                            contributed += tc.status == ConnectionStatus::Contributed;
                            occluded += tc.status == ConnectionStatus::Occluded;
                            deltaVertex += tc.status == ConnectionStatus::DeltaVertex;
                        }
                        CHECK(wave.connectionQueue.size() == evaluated);
                        for (size_t k = 0; k < wave.connectionQueue.size(); ++k) CHECK(wave.connectionQueue[k].slot == k);
                        queueEntries += long(evaluated);
                        flushedSamples += sample % 2 == 1 && evaluated > size_t(tiny.connectionQueueCapacity);
                        splats += long(wave.splats.size());
                    }
        }
    }
    // Not vacuous: contributions, occlusions, splats and delta vertices all occur.
    CHECK(contributed > 200);
    CHECK(occluded > 20);
    CHECK(splats > 50);
    CHECK(deltaVertex > 10);
    CHECK(queueEntries > 1000);
    CHECK(flushedSamples > 20);  // samples whose connections did not fit the tiny queue
}

TEST_CASE("wavefront trace: the traced samples rebuild a 1-spp wavefront render bit for bit", "[trace][wavefront]") {
    struct Case {
        std::string scene;
        Rgb env;
        Mode mode;
        int width, height, maxDepth, tile;
        int crop[4];  // x0, y0, x1, y1 (all zero: none)
    };
    const Case cases[] = {
        {"scenes/cornell-box.gltf", Rgb(0.f), {"bdpt", MisHeuristic::Balance}, 12, 9, 5, 16, {0, 0, 0, 0}},
        {"scenes/mis-zoo.gltf", kZooEnv, {"bdpt", MisHeuristic::Power}, 20, 16, 6, 5, {3, 2, 17, 13}},
        {"scenes/mis-zoo.gltf", kZooEnv, {"lt", MisHeuristic::Balance}, 16, 12, 6, 4, {0, 0, 0, 0}},
    };
    long nonZeroL = 0, splatsLanded = 0;
    for (const Case& c : cases) {
        Scene scene = loadTestScene(c.scene, c.width, c.height, c.env);
        if (c.crop[2] > 0) scene.camera = scene.camera.withCrop(c.crop[0], c.crop[1], c.crop[2], c.crop[3]);
        const TraceSettings ts = traceSettings(c.mode, c.maxDepth, false);
        IntegratorSettings is;
        is.maxDepth = c.maxDepth;
        is.mis = ts.bdpt.mis;
        const auto integrator = makeIntegrator(c.mode.integrator, is);
        WavefrontScheduler wavefront(c.mode.integrator, is, WavefrontOptions{});
        RenderOptions ro;
        ro.spp = 1;
        ro.seed = ts.seed;
        ro.tileSize = c.tile;
        ro.scheduler = &wavefront;
        Film film(c.width, c.height);
        renderImage(scene, *integrator, ro, film);

        // The pass rebuilt from wavefront traces, in the renderer's order (tiles over the crop
        // window, pixels row-major in a tile; splats summed in that order in float).
        const Camera& cam = scene.camera;
        const int x0 = cam.cropX0(), y0 = cam.cropY0(), x1 = cam.cropX1(), y1 = cam.cropY1();
        std::vector<Rgb> passL(size_t(c.width) * size_t(c.height), Rgb(0.f)), passLight(passL.size(), Rgb(0.f));
        std::vector<Splat> splats;
        const int tilesX = (x1 - x0 + c.tile - 1) / c.tile, tilesY = (y1 - y0 + c.tile - 1) / c.tile;
        for (int t = 0; t < tilesX * tilesY; ++t) {
            const int tx0 = x0 + (t % tilesX) * c.tile, ty0 = y0 + (t / tilesX) * c.tile;
            for (int y = ty0; y < std::min(ty0 + c.tile, y1); ++y)
                for (int x = tx0; x < std::min(tx0 + c.tile, x1); ++x) {
                    const TracedSample tr = traceSampleWavefront(scene, ts, x, y, 0);
                    passL[size_t(y) * size_t(c.width) + size_t(x)] = tr.L;
                    splats.insert(splats.end(), tr.splats.begin(), tr.splats.end());
                }
        }
        for (const Splat& sp : splats) {
            const int px = int(std::floor(sp.raster.x)), py = int(std::floor(sp.raster.y));
            if (px < x0 || px >= x1 || py < y0 || py >= y1) continue;
            passLight[size_t(py) * size_t(c.width) + size_t(px)] += sp.value;
            ++splatsLanded;
        }
        long mismatches = 0;
        for (int y = y0; y < y1; ++y)
            for (int x = x0; x < x1; ++x) {
                const size_t p = size_t(y) * size_t(c.width) + size_t(x);
                nonZeroL += !isBlack(passL[p]);
                REQUIRE(film.count(x, y) == 1);
                if (film.sum(x, y) != DVec3(passL[p] + passLight[p]) || film.lightMean(x, y) != DVec3(passLight[p])) {
                    ++mismatches;
                    UNSCOPED_INFO(c.scene << " " << c.mode.integrator << " pixel (" << x << ", " << y << "): film "
                                          << film.sum(x, y).x << " traces " << double(passL[p].x + passLight[p].x));
                }
            }
        INFO(c.scene << " " << c.mode.integrator);
        CHECK(mismatches == 0);
    }
    CHECK(nonZeroL > 100);
    CHECK(splatsLanded > 100);
}

TEST_CASE("wavefront trace command: the megakernel's JSON plus the stage records", "[trace][wavefront][cli]") {
    const std::string dir = makeTempDir("trace-wavefront");
    const std::string args = "trace " + sourcePath("scenes/mis-zoo.gltf") +
                             " --pixel 15,12 --sample 2 --seed 4 --width 20 --height 16 --max-depth 5 --env 0.3,0.35,0.4";
    std::string out;
    for (const char* integrator : {"bdpt", "lt"}) {
        INFO(integrator);
        const std::string common = args + " --integrator " + integrator;
        REQUIRE(runCli(common + " -o " + dir + "/m.json", &out) == 0);
        REQUIRE(runCli(common + " --mode wavefront -o " + dir + "/w.json", &out) == 0);
        std::ifstream fm(dir + "/m.json"), fw(dir + "/w.json");
        const Json m = Json::parse(fm);
        Json w = Json::parse(fw);
        CHECK(m["settings"]["integrator"] == integrator);
        CHECK(w["settings"]["mode"] == "wavefront");
        REQUIRE(w.contains("wavefront"));
        const Json& queue = w["wavefront"]["connectionQueue"];
        size_t evaluated = 0, visible = 0;
        for (const Json& c : m["connections"]) {
            evaluated += c["status"] != "depth-limit" && c["status"] != "depth-0-rule";
            visible += c["status"] == "contributed";
        }
        CHECK(queue.size() == evaluated);
        size_t weighted = 0;
        for (const Json& e : queue) weighted += e.contains("weighted");
        CHECK(weighted == visible);
        CHECK(visible > 0);
        CHECK(w["wavefront"]["accumulate"]["L"] == m["total"]["L"]);
        w.erase("wavefront");
        w["settings"]["mode"] = "megakernel";
        CHECK(firstDifference(m, w, "trace") == "");
    }
}
