// `bdptref trace` / `bdptref mis` and their library API (docs/trace-and-mis.md), and the RNG test
// vectors of docs/rng.md.
//
//  * A traced pixel sample is exactly what the renderer adds to the film: every pixel of a
//    1-spp BDPT render (two scenes, two heuristics, a crop window, several tiles) is rebuilt bit for
//    bit from traceSample() - its camera-side L plus the splats of every pixel's light subpath,
//    summed in the renderer's tile order - and so is the light image.
//  * The trace JSON of the command is valid, has both subpaths, is deterministic (byte-identical
//    on two runs) and carries the same numbers as the library.
//  * `mis` on a traced path gives bit-for-bit the trace's definition weights, which sum to 1; the
//    densities form (the path converted to explicit per-vertex densities, evaluated with the
//    production density functions) gives the same weights within the float32 bound of
//    tests/unit/test_mis.cpp, on every contributing path of hundreds of samples with delta
//    vertices and every light type, and a JSON round trip of the densities changes nothing.
//  * Bad input exits with 2 and a message.
//  * The Philox test vectors printed in docs/rng.md are what PixelSampler draws (the test parses
//    the document, so the two cannot drift; BDPTREF_PRINT_RNG_VECTORS=1 prints the table).
#include "bdptref/errors.h"
#include "bdptref/gltf_loader.h"
#include "bdptref/integrator.h"
#include "bdptref/path_io.h"
#include "bdptref/renderer.h"
#include "bdptref/rng.h"
#include "bdptref/scene.h"
#include "bdptref/trace.h"
#include "support/render_util.h"

#include "support/mis_tolerance.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>

using namespace bdptref;
using namespace bdptref::test;
using Json = nlohmann::ordered_json;

namespace {

const std::string kCornell = sourcePath("scenes/cornell-box.gltf");
const std::string kZoo = sourcePath("scenes/mis-zoo.gltf");
const Rgb kZooEnv(0.3f, 0.35f, 0.4f);  // as test_mis.cpp: the environment through the ceiling opening

MisSettings misOf(MisHeuristic h) {
    MisSettings m;
    m.heuristic = h;
    m.beta = 2.0;
    return m;
}

std::string readFile(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

Json readJson(const std::string& path) { return Json::parse(readFile(path)); }

// One pass of renderImage rebuilt from traced samples: the renderer's tile order (tiles row by
// row over the crop window, pixels row-major inside a tile), splats summed in that order in float.
void replayPass(const Scene& scene, const TraceSettings& ts, uint64_t sample, int tile, std::vector<Rgb>& passL,
                std::vector<Rgb>& passLight, long* splatsLanded) {
    const Camera& cam = scene.camera;
    const int width = cam.width(), x0 = cam.cropX0(), y0 = cam.cropY0(), x1 = cam.cropX1(), y1 = cam.cropY1();
    passL.assign(size_t(width) * size_t(cam.height()), Rgb(0.f));
    passLight.assign(passL.size(), Rgb(0.f));
    std::vector<Splat> splats;
    const int tilesX = (x1 - x0 + tile - 1) / tile, tilesY = (y1 - y0 + tile - 1) / tile;
    for (int t = 0; t < tilesX * tilesY; ++t) {
        const int tx0 = x0 + (t % tilesX) * tile, ty0 = y0 + (t / tilesX) * tile;
        for (int y = ty0; y < std::min(ty0 + tile, y1); ++y)
            for (int x = tx0; x < std::min(tx0 + tile, x1); ++x) {
                const TracedSample tr = traceSample(scene, ts, x, y, sample);
                passL[size_t(y) * size_t(width) + size_t(x)] = tr.L;
                splats.insert(splats.end(), tr.splats.begin(), tr.splats.end());
            }
    }
    for (const Splat& sp : splats) {
        const int px = int(std::floor(sp.raster.x)), py = int(std::floor(sp.raster.y));
        if (px < x0 || px >= x1 || py < y0 || py >= y1) continue;
        passLight[size_t(py) * size_t(width) + size_t(px)] += sp.value;
        ++*splatsLanded;
    }
}

// Production and definition weights are compared within the float32 bound of
// support/mis_tolerance.h: here the definition (double directions) against the production
// density functions behind pathDensitiesFromScene (float directions).

}  // namespace

TEST_CASE("trace: the replayed samples rebuild a 1-spp BDPT render bit for bit", "[trace]") {
    struct Case {
        std::string scene;
        Rgb env;
        int width, height, maxDepth, tile;
        MisHeuristic heuristic;
        int crop[4];  // x0, y0, x1, y1 (all zero: none)
    };
    const Case cases[] = {
        {"scenes/cornell-box.gltf", Rgb(0.f), 12, 9, 5, 16, MisHeuristic::Balance, {0, 0, 0, 0}},
        {"scenes/mis-zoo.gltf", kZooEnv, 20, 16, 6, 5, MisHeuristic::Power, {3, 2, 17, 13}},
    };
    long splatsLanded = 0, nonZeroL = 0;
    for (const Case& c : cases) {
        Scene scene = loadTestScene(c.scene, c.width, c.height, c.env);
        if (c.crop[2] > 0) scene.camera = scene.camera.withCrop(c.crop[0], c.crop[1], c.crop[2], c.crop[3]);
        const uint32_t seed = 7;
        IntegratorSettings is;
        is.maxDepth = c.maxDepth;
        is.mis = misOf(c.heuristic);
        const auto bdpt = makeIntegrator("bdpt", is);
        RenderOptions ro;
        ro.spp = 1;
        ro.seed = seed;
        ro.tileSize = c.tile;
        Film film(c.width, c.height);
        renderImage(scene, *bdpt, ro, film);

        TraceSettings ts;
        ts.seed = seed;
        ts.bdpt.maxDepth = c.maxDepth;
        ts.bdpt.mis = is.mis;
        ts.fullPaths = false;
        std::vector<Rgb> passL, passLight;
        replayPass(scene, ts, 0, c.tile, passL, passLight, &splatsLanded);
        long mismatches = 0;
        for (int y = scene.camera.cropY0(); y < scene.camera.cropY1(); ++y)
            for (int x = scene.camera.cropX0(); x < scene.camera.cropX1(); ++x) {
                const size_t p = size_t(y) * size_t(c.width) + size_t(x);
                const DVec3 expected = DVec3(passL[p] + passLight[p]);  // what the renderer adds: one float sum
                nonZeroL += !isBlack(passL[p]);
                REQUIRE(film.count(x, y) == 1);
                if (film.sum(x, y) != expected || film.lightMean(x, y) != DVec3(passLight[p])) {
                    ++mismatches;
                    UNSCOPED_INFO(c.scene << " pixel (" << x << ", " << y << "): film " << film.sum(x, y).x << " replay "
                                          << expected.x << "; light " << film.lightMean(x, y).x << " vs " << passLight[p].x);
                }
            }
        INFO(c.scene);
        CHECK(mismatches == 0);
    }
    // Not vacuous: camera-side values and splats from other pixels' light subpaths both occur.
    CHECK(nonZeroL > 100);
    CHECK(splatsLanded > 100);
}

TEST_CASE("trace: the replay is deterministic and its recorded weights are consistent", "[trace]") {
    const Scene scene = loadTestScene("scenes/mis-zoo.gltf", 24, 24, kZooEnv);
    TraceSettings ts;
    ts.seed = 3;
    ts.bdpt.maxDepth = 6;
    const TracedSample a = traceSample(scene, ts, 11, 7, 5), b = traceSample(scene, ts, 11, 7, 5);
    CHECK(formatJson(traceToJson(a, scene, nullptr)) == formatJson(traceToJson(b, scene, nullptr)));

    // Over many samples: the definition weights of every contributing path sum to 1, the strategy
    // that produced it is valid, and the production weight equals its definition weight within
    // the float32 bound (the property test_mis.cpp checks, here on the recorded data).
    long contributions = 0, failures = 0;
    for (int k = 0; k < 150; ++k) {
        const TracedSample tr = traceSample(scene, ts, (k * 7) % 24, (k * 5) % 24, uint64_t(k));
        for (const TracedConnection& c : tr.connections) {
            if (c.status != ConnectionStatus::Contributed) continue;
            ++contributions;
            double sum = 0.0;
            for (double w : c.definitionWeights) sum += w;
            const double def = c.definitionWeights[size_t(c.s)];
            const bool ok = std::abs(sum - 1.0) <= 1e-9 && c.strategies[size_t(c.s)].valid &&
                            std::abs(c.weight - def) <= def * test::misRelativeTolerance(c.path, 1.0);
            if (!ok && failures++ < 5)
                UNSCOPED_INFO("sample " << k << " (s,t) = (" << c.s << "," << c.t << "): sum " << sum << " production "
                                        << c.weight << " definition " << def);
        }
    }
    CHECK(failures == 0);
    CHECK(contributions > 200);
}

TEST_CASE("trace: every connection without a contribution is diagnosed, through perspective and orthographic cameras", "[trace][camera]") {
    // The diagnosis re-derives why connectStrategy returned nothing; for t = 1 it must test the
    // camera vertex the connection used: the pinhole, or the film point an orthographic camera
    // projects the light vertex onto (not the camera's position).
    struct Case {
        const char* name;
        Scene scene;
        const char* cameraWord;  // what the reasons of t = 1 must name
        const char* wrongWord;   // and must not
    };
    Case cases[] = {{"perspective", loadTestScene("scenes/mis-zoo.gltf", 16, 16, kZooEnv), "the pinhole", "the film point"},
                    {"orthographic", loadTestSceneOrthographic("scenes/mis-zoo.gltf", 16, 16, 1.6f, kZooEnv), "the film point", "pinhole"}};
    for (Case& c : cases) {
        TraceSettings ts;
        ts.seed = 5;
        ts.bdpt.maxDepth = 5;
        ts.fullPaths = false;
        long unexplained = 0, occludedT1 = 0, failedT1 = 0, wrongWord = 0, namedCamera = 0;
        for (int k = 0; k < 400; ++k) {
            const TracedSample tr = traceSample(c.scene, ts, (k * 7) % 16, (k * 5) % 16, uint64_t(k));
            for (const TracedConnection& tc : tr.connections) {
                unexplained += tc.status == ConnectionStatus::Unexplained;
                if (tc.t != 1 || tc.status == ConnectionStatus::Contributed || tc.status == ConnectionStatus::DepthLimit) continue;
                ++failedT1;
                occludedT1 += tc.status == ConnectionStatus::Occluded;
                wrongWord += tc.reason.find(c.wrongWord) != std::string::npos;
                namedCamera += tc.reason.find(c.cameraWord) != std::string::npos;
            }
        }
        INFO(c.name << ": t = 1 without contribution " << failedT1 << ", occluded " << occludedT1 << ", naming the camera vertex "
                    << namedCamera << ", unexplained connections " << unexplained);
        CHECK(unexplained == 0);
        CHECK(wrongWord == 0);
        CHECK(occludedT1 > 20);  // not vacuous: blocked connections to the camera vertex are diagnosed
        CHECK(namedCamera >= occludedT1);
    }
}

TEST_CASE("trace command: valid JSON with both subpaths, deterministic, the library's numbers", "[trace][cli]") {
    const std::string dir = makeTempDir("trace-json");
    const std::string args = "trace " + kCornell + " --pixel 5,4 --sample 2 --seed 11 --width 16 --height 12 --max-depth 4 --mis power";
    std::string out;
    REQUIRE(runCli(args + " -o " + dir + "/a.json", &out) == 0);
    REQUIRE(runCli(args + " --mode megakernel --integrator bdpt -o " + dir + "/b.json", &out) == 0);
    const std::string textA = readFile(dir + "/a.json");
    CHECK(textA == readFile(dir + "/b.json"));
    const Json j = Json::parse(textA);
    CHECK(j["format"] == "bdptref-trace");
    CHECK(j["settings"]["pixel"] == Json::array({5, 4}));
    CHECK(j["settings"]["mis"]["heuristic"] == "power");
    REQUIRE(j["cameraSubpath"].size() >= 2);
    REQUIRE(j["lightSubpath"].size() >= 1);
    CHECK(j["cameraSubpath"][0]["type"] == "camera");
    CHECK(j["lightSubpath"][0]["type"] == "light");
    for (const char* key : {"index", "type", "p", "ng", "ns", "wo", "bary", "uv", "beta", "pdfFwd", "pdfRev", "dVCM", "dVC", "delta", "infinite"})
        CHECK(j["cameraSubpath"][1].contains(key));
    CHECK(j["cameraSubpath"][1].contains("materialName"));
    CHECK(j["lightSubpath"][0]["lightType"] == "area");

    // The same sample through the library: the JSON carries exactly its numbers.
    const Scene scene = loadTestScene("scenes/cornell-box.gltf", 16, 12);
    TraceSettings ts;
    ts.seed = 11;
    ts.bdpt.maxDepth = 4;
    ts.bdpt.mis = misOf(MisHeuristic::Power);
    const TracedSample tr = traceSample(scene, ts, 5, 4, 2);
    REQUIRE(j["cameraSubpath"].size() == tr.cameraPath.size());
    REQUIRE(j["lightSubpath"].size() == tr.lightPath.size());
    for (size_t i = 0; i < tr.cameraPath.size(); ++i) {
        CHECK(j["cameraSubpath"][i]["p"][0].get<double>() == scene.toWorld(tr.cameraPath[i].p).x);  // world coordinates
        // The recursive MIS quantities the connections used (docs/mis.md, "The recursive form").
        CHECK(j["cameraSubpath"][i]["dVCM"].get<double>() == tr.cameraPath[i].dVCM);
        CHECK(j["cameraSubpath"][i]["dVC"].get<double>() == tr.cameraPath[i].dVC);
    }
    CHECK(j["total"]["L"][0].get<double>() == double(tr.L.x));
    CHECK(j["total"]["splats"].size() == tr.splats.size());
    REQUIRE(j["connections"].size() == tr.connections.size());
    int contributed = 0;
    for (const Json& c : j["connections"]) {
        if (c["status"] != "contributed") {
            CHECK(!c["reason"].get<std::string>().empty());
            continue;
        }
        ++contributed;
        CHECK(c.contains("unweighted"));
        CHECK(c.contains("weight"));
        CHECK(c["path"]["format"] == "bdptref-path");
        CHECK(c["definitionWeights"].size() == size_t(c["s"].get<int>() + c["t"].get<int>()));
    }
    CHECK(contributed > 0);

    // --no-paths drops the per-connection paths; --compact is one line.
    REQUIRE(runCli(args + " --no-paths --compact -o " + dir + "/c.json", &out) == 0);
    const std::string textC = readFile(dir + "/c.json");
    CHECK(std::count(textC.begin(), textC.end(), '\n') == 1);
    CHECK(textC.find("\"path\"") == std::string::npos);
}

TEST_CASE("mis command: a traced path gives the trace's definition weights, summing to 1", "[trace][cli]") {
    const std::string dir = makeTempDir("trace-mis");
    const std::string common = " --width 24 --height 24 --env 0.3,0.35,0.4 --seed 3 --max-depth 6 --mis power";
    std::string out;
    const std::string trace = dir + "/trace.json";
    REQUIRE(runCli("trace " + kZoo + " --pixel 12,12 --sample 7" + common + " -o " + trace, &out) == 0);
    const Json j = readJson(trace);
    // The contributing connections, one of each kind (s = 0, s = 1, t = 1, others; with
    // and without strategies that cannot sample the path): every CLI run costs ~0.25 s of start-up.
    std::map<std::pair<int, bool>, int> kinds;
    int checked = 0, withInvalid = 0;
    for (const Json& c : j["connections"]) {
        if (c["status"] != "contributed") continue;
        const int s = c["s"].get<int>(), t = c["t"].get<int>();
        const bool hasInvalid = !c["cannotSample"].empty();
        const int kind = s == 0 ? 0 : s == 1 ? 1 : t == 1 ? 2 : 3;
        if (kinds[{kind, hasInvalid}]++ >= 1) continue;
        const std::string st = std::to_string(s) + "," + std::to_string(t);
        const std::string path = dir + "/path-" + std::to_string(s) + "-" + std::to_string(t) + ".json";
        if (checked == 0) {
            // `trace --path S,T` prints exactly the connection's path object of the full trace.
            REQUIRE(runCli("trace " + kZoo + " --pixel 12,12 --sample 7" + common + " --path " + st + " -o " + path, &out) == 0);
            CHECK(readJson(path) == c["path"]);
        } else {
            std::ofstream(path) << formatJson(c["path"]);
        }
        // Scene form: bit-identical to the trace's definition weights, and they sum to 1.
        REQUIRE(runCli("mis " + path + " --json > " + dir + "/w.json", &out) == 0);
        const Json w = readJson(dir + "/w.json");
        CHECK(w["form"] == "scene");
        CHECK(w["mis"]["heuristic"] == "power");
        REQUIRE(w["strategies"].size() == c["definitionWeights"].size());
        for (size_t k = 0; k < w["strategies"].size(); ++k) {
            CHECK(w["strategies"][k]["weight"].get<double>() == c["definitionWeights"][k].get<double>());
            if (!w["strategies"][k]["valid"].get<bool>()) {
                ++withInvalid;
                CHECK(!w["strategies"][k]["reason"].get<std::string>().empty());
            }
        }
        CHECK(w["sum"].get<double>() == Approx(1.0).margin(1e-12));
        CHECK(w["producedBy"]["s"] == s);
        // The recursive form from the path alone: per-vertex dVCM/dVC, and for the strategy that
        // produced the path the weight the trace's connection computed from its subpaths.
        CHECK(w["recursive"].size() == w["strategies"].size());
        CHECK(w["strategies"][size_t(s)]["recursiveWeight"].get<double>() == c["weight"].get<double>());
        if (checked == 0) {
            // The whole trace with --strategy picks the same path; the text form lists the sum.
            REQUIRE(runCli("mis " + trace + " --strategy " + st + " --json > " + dir + "/w2.json", &out) == 0);
            CHECK(readJson(dir + "/w2.json") == w);
            REQUIRE(runCli("mis " + path, &out) == 0);
            CHECK(out.find("sum:") != std::string::npos);
        }
        ++checked;
    }
    INFO(j["connections"].dump());
    CHECK(checked >= 3);
    CHECK(kinds[{0, false}] + kinds[{0, true}] > 0);  // an s = 0 path (the emitter hit)
    CHECK(kinds[{2, false}] + kinds[{2, true}] > 0);  // a t = 1 path (splatted)
    CHECK(withInvalid > 0);  // some strategies cannot sample some of these paths (with reasons)
}

TEST_CASE("mis: the explicit-density form gives the scene form's weights", "[trace]") {
    const Scene scene = loadTestScene("scenes/mis-zoo.gltf", 24, 24, kZooEnv);
    TraceSettings ts;
    ts.seed = 20250401u;
    ts.bdpt.maxDepth = 8;
    long paths = 0, failures = 0, deltaPaths = 0, invalid = 0;
    long endOn[5] = {0, 0, 0, 0, 0};
    for (int h = 0; h < 3; ++h) {
        ts.bdpt.mis = misOf(h == 0 ? MisHeuristic::Balance : h == 1 ? MisHeuristic::Power : MisHeuristic::Uniform);
        for (int k = 0; k < 200; ++k) {
            const TracedSample tr = traceSample(scene, ts, (k * 11) % 24, (k * 7) % 24, uint64_t(k));
            for (const TracedConnection& c : tr.connections) {
                if (c.status != ConnectionStatus::Contributed) continue;
                ++paths;
                ++endOn[int(scene.lights[size_t(c.path.back().light)].type)];
                for (const PathVertex& v : c.path) deltaPaths += v.delta;
                // Scene form -> densities (pathDensitiesFromScene) -> JSON -> densities form.
                const PathDescription d = pathFromJson(Json::parse(formatJson(pathToJson(c.path, &c.densities, &scene, nullptr, nullptr, c.s))));
                REQUIRE(d.hasDensities);
                REQUIRE(d.hasSceneVertices);
                const std::vector<double> viaJson = misWeightsFromDensities(d.densities, ts.bdpt.mis);
                const std::vector<double> direct = misWeightsFromDensities(c.densities, ts.bdpt.mis);
                // The scene form read back from the same JSON: the definition on identical vertices.
                const std::vector<double> defFromJson = misWeightsDefinition(scene, verticesInRenderSpace(d, scene), ts.bdpt.mis);
                const double tol = test::misRelativeTolerance(c.path, ts.bdpt.mis.exponent());
                double sum = 0.0;
                bool ok = viaJson == direct && defFromJson == c.definitionWeights;
                for (size_t s = 0; s < direct.size(); ++s) {
                    const double def = c.definitionWeights[s];
                    sum += direct[s];
                    ok = ok && (def > 0.0) == (direct[s] > 0.0) && std::abs(direct[s] - def) <= def * tol;
                    invalid += def == 0.0;
                }
                ok = ok && std::abs(sum - 1.0) <= 1e-9;
                if (!ok && failures++ < 5) {
                    std::ostringstream o;
                    o.precision(12);
                    o << "(s,t) = (" << c.s << "," << c.t << "):";
                    for (size_t s = 0; s < direct.size(); ++s) o << " [" << c.definitionWeights[s] << " vs " << direct[s] << "]";
                    UNSCOPED_INFO(o.str());
                }
            }
        }
    }
    INFO("paths " << paths << ", with delta vertices " << deltaPaths << ", invalid strategies " << invalid
                  << "; ends on area/point/spot/directional/environment " << endOn[0] << "/" << endOn[1] << "/" << endOn[2]
                  << "/" << endOn[3] << "/" << endOn[4]);
    CHECK(failures == 0);
    // Not vacuous: delta vertices, invalid strategies, and every light type.
    CHECK(paths > 2000);
    CHECK(deltaPaths > 500);
    CHECK(invalid > 1000);
    for (long e : endOn) CHECK(e > 10);
}

TEST_CASE("mis: densities form on the worked example of docs/mis.md", "[trace]") {
    // Camera, Lambertian floor, area light (docs/mis.md, "Worked examples"): p->(x1) = 1/4,
    // p<-(x1) = p->(x2) = 1/(4 pi), light endpoint 4/3 for both s = 1 and s >= 2.
    const double pi = 3.14159265358979323846;
    PathDensities d;
    d.vertices = {{1.0, 0.0, false}, {0.25, 1.0 / (4.0 * pi), false}, {1.0 / (4.0 * pi), 4.0 / 3.0, false}};
    d.lightNextEvent = 4.0 / 3.0;
    const std::vector<double> balance = misWeightsFromDensities(d, misOf(MisHeuristic::Balance));
    CHECK(balance[0] == Approx(0.0433116).epsilon(1e-5));
    CHECK(balance[1] == Approx(0.7256931).epsilon(1e-6));
    CHECK(balance[2] == Approx(0.2309953).epsilon(1e-6));
    const std::vector<double> power = misWeightsFromDensities(d, misOf(MisHeuristic::Power));
    CHECK(power[1] == Approx(0.9050730).epsilon(1e-6));
    const std::vector<double> uniform = misWeightsFromDensities(d, misOf(MisHeuristic::Uniform));
    for (double w : uniform) CHECK(w == Approx(1.0 / 3.0));

    // A delta vertex forbids the connections that touch it; a delta light forbids s = 0.
    d.vertices = {{1.0, 0.0, false}, {0.25, 0.0, true}, {0.0, 0.5, false}, {0.1, 2.0, false}};
    d.lightNextEvent = 2.0;
    d.deltaLight = true;
    const std::vector<StrategyVerdict> v = analyseMisDensities(d, misOf(MisHeuristic::Balance));
    CHECK_FALSE(v[0].valid);  // delta light
    CHECK(v[0].reason.find("delta light") != std::string::npos);
    CHECK(v[1].valid);        // next-event estimation at x2
    CHECK_FALSE(v[2].valid);  // connects x1 (delta) - x2
    CHECK_FALSE(v[3].valid);  // connects the pinhole - x1 (delta)
    CHECK(v[1].weight == 1.0);

    // Bad input is an InputError.
    d.vertices[2].light = -1.0;
    CHECK_THROWS_AS(misWeightsFromDensities(d, MisSettings{}), InputError);
    d.vertices.resize(1);
    CHECK_THROWS_AS(misWeightsFromDensities(d, MisSettings{}), InputError);
}

TEST_CASE("trace and mis: bad input exits with 2 and a message", "[trace][cli]") {
    const std::string dir = makeTempDir("trace-bad");
    auto write = [&](const std::string& name, const std::string& text) {
        std::ofstream(dir + "/" + name) << text;
        return dir + "/" + name;
    };
    struct Bad {
        std::string args, message;
    };
    const std::string v0 = R"({"pdfCamera": 1})", v1 = R"({"pdfCamera": 0.5, "pdfLight": 2, "pdfNextEvent": 1})";
    const Bad bad[] = {
        {"mis " + dir + "/missing.json", "cannot open"},
        {"mis " + write("malformed.json", "{\"vertices\": [1, 2"), "not valid JSON"},
        {"mis " + write("one.json", "{\"vertices\": [" + v0 + "]}"), "at least 2 vertices"},
        {"mis " + write("negative.json", R"({"vertices": [{"pdfCamera": 1}, {"pdfCamera": -0.5, "pdfLight": 2, "pdfNextEvent": 1}]})"),
         "must be >= 0"},
        {"mis " + write("nothing.json", R"({"vertices": [{}, {}]})"), "neither scene references"},
        {"trace " + kCornell + " --pixel 3,5 --mode gpu", "--mode: expected 'megakernel' or 'wavefront'"},
    };
    for (const Bad& b : bad) checkInputError(b.args, b.message);
    // The library raises the same errors (the command turns every InputError into exit code 2).
    const Scene scene = loadTestScene("scenes/cornell-box.gltf", 8, 8);
    const PathDescription noScene =
        readPathFile(write("noscene.json", R"({"vertices": [{"type": "camera", "p": [0,0,0]}, {"type": "light", "p": [0,0,1], "light": 99}]})"));
    CHECK(noScene.hasSceneVertices);
    CHECK_FALSE(noScene.hasDensities);
    CHECK_THROWS_WITH(validateScenePath(scene, noScene.vertices), Catch::Contains("light 99 does not exist"));
    CHECK_THROWS_WITH(traceSample(scene, TraceSettings{}, 300, 5, 0), Catch::Contains("outside"));
    CHECK_THROWS_WITH(readPathFile(write("trace.json", R"({"format": "bdptref-trace", "connections": []})")),
                      Catch::Contains("--strategy"));
    CHECK_THROWS_WITH(readPathFile(dir + "/trace.json", 1, 2), Catch::Contains("no connection (1,2)"));
    CHECK_THROWS_WITH(pathFromJson(Json::parse(R"({"vertices": [{"type": "camera", "p": [0,0]}, {"pdfCamera": 1}]})")),
                      Catch::Contains("vertices[0].p"));
    CHECK_THROWS_WITH(pathFromJson(Json::parse(R"({"vertices": [{"type": "surface", "p": [0,0,0], "ng": [0,0,1]}, {}]})")),
                      Catch::Contains("needs \"material\""));

    // The well-formed densities path works.
    std::string out;
    CHECK(runCli("mis " + write("ok.json", "{\"vertices\": [" + v0 + ", " + v1 + "]}"), &out) == 0);
    INFO(out);
    CHECK(out.find("densities form") != std::string::npos);
}

// ---- the example of docs/trace-and-mis.md, verbatim ---------------------------------------------
TEST_CASE("GPU port example: the port's vertices and MIS weights match the reference", "[trace]") {
    // The reference scene exactly as `bdptref render scenes/cornell-box.gltf --width 64 --height 64`.
    LoadOptions lo;
    lo.width = lo.height = 64;
    Scene scene = loadGltfScene(kCornell, lo);
    scene.camera = scene.camera.withResolution(64, 64);
    scene.finalize();
    TraceSettings settings;  // seed 0, balance heuristic
    settings.bdpt.maxDepth = 5;
    const TracedSample ref = traceSample(scene, settings, 3, 5, /*sample*/ 0);

    // 1. The port's camera subpath of the same pixel sample (stand-in: the reference's own),
    //    in render space: a port's world positions go through scene.toRender first.
    const std::vector<PathVertex> gpuCameraPath = ref.cameraPath;
    CHECK(firstDivergentVertex(ref.cameraPath, gpuCameraPath, 1e-4f) == -1);

    // 2. The port's MIS weights from the densities its own walk used (stand-in: the reference's
    //    densities of each contributing path), against the reference's definition weights; 1e-3
    //    leaves room for a float32 port (test_mis.cpp bounds the float error of the densities).
    for (const TracedConnection& c : ref.connections) {
        if (c.status != ConnectionStatus::Contributed) continue;
        const std::vector<double> w = misWeightsFromDensities(c.densities, settings.bdpt.mis);
        for (size_t s = 0; s < w.size(); ++s) CHECK(w[s] == Approx(c.definitionWeights[s]).epsilon(1e-3).margin(1e-9));
    }
}

TEST_CASE("docs/trace-and-mis.md shows the GPU port example test verbatim", "[trace]") {
    auto between = [](const std::string& text, const std::string& from, const std::string& to) {
        const size_t a = text.find(from);
        const size_t b = a == std::string::npos ? a : text.find(to, a);
        return b == std::string::npos ? std::string() : text.substr(a, b - a);
    };
    const std::string test = between(readFile(sourcePath("tests/unit/test_trace_mis.cpp")), "TEST_CASE(\"GPU port example", "\n}\n");
    const std::string doc = between(readFile(sourcePath("docs/trace-and-mis.md")), "TEST_CASE(\"GPU port example", "\n}\n");
    REQUIRE(!test.empty());
    CHECK(doc == test);
}

// ---- RNG test vectors (docs/rng.md, "Test vectors") -------------------------------------------

namespace {

struct VectorRow {
    uint32_t seed, pixel;
    uint64_t sample;
    RngStream stream;
    uint32_t dimension;
    PhiloxCounter block;
    float u0, u1;
};

std::string formatRow(uint32_t seed, uint32_t pixel, uint64_t sample, RngStream stream, uint32_t dimension) {
    const PixelSampler ps(seed, pixel, sample);
    const PhiloxCounter b = ps.block(stream, dimension);
    char buf[256];
    std::snprintf(buf, sizeof buf, "| %u | %u | %" PRIu64 " | %s | %u | %08x %08x %08x %08x | %.9g | %.9g |", seed, pixel, sample,
                  stream == RngStream::Camera ? "camera" : "light", dimension, b[0], b[1], b[2], b[3],
                  double(uintToUnitFloat(b[0])), double(uintToUnitFloat(b[1])));
    return buf;
}

}  // namespace

TEST_CASE("RNG test vectors: docs/rng.md prints what PixelSampler draws", "[trace][rng]") {
    // The expected rows (seed 0, pixel (3, 5) of a 64-wide image, sample 0, dimensions 0..5 of both
    // streams; and a sample index above 2^32 with a non-zero seed).
    std::vector<std::string> expected;
    const uint32_t pixel = pixelIndex(3, 5, 64);
    REQUIRE(pixel == 323u);
    for (RngStream st : {RngStream::Camera, RngStream::Light})
        for (uint32_t d = 0; d < 6; ++d) expected.push_back(formatRow(0, pixel, 0, st, d));
    for (RngStream st : {RngStream::Camera, RngStream::Light})
        for (uint32_t d = 0; d < 3; ++d) expected.push_back(formatRow(1234, pixel, (uint64_t(1) << 32) + 1, st, d));
    if (std::getenv("BDPTREF_PRINT_RNG_VECTORS"))
        for (const std::string& r : expected) std::printf("%s\n", r.c_str());

    // Parse the table rows of the section from the document and recompute each one.
    const std::string doc = readFile(sourcePath("docs/rng.md"));
    const size_t section = doc.find("## Test vectors");
    REQUIRE(section != std::string::npos);
    std::istringstream lines(doc.substr(section));
    std::string line;
    std::vector<std::string> rows;
    while (std::getline(lines, line)) {
        unsigned long long seed = 0, pix = 0, sample = 0, dimension = 0;
        char stream[16] = {0};
        if (std::sscanf(line.c_str(), "| %llu | %llu | %llu | %15s | %llu |", &seed, &pix, &sample, stream, &dimension) != 5) continue;
        const std::string s(stream);
        REQUIRE((s == "camera" || s == "light"));
        const std::string recomputed = formatRow(uint32_t(seed), uint32_t(pix), uint64_t(sample),
                                                 s == "camera" ? RngStream::Camera : RngStream::Light, uint32_t(dimension));
        INFO("docs/rng.md row:  " << line << "\nPixelSampler gives: " << recomputed);
        CHECK(line == recomputed);
        rows.push_back(line);
    }
    // Every expected row is in the document (it cannot silently lose the vectors).
    for (const std::string& e : expected) {
        INFO("missing from docs/rng.md: " << e);
        CHECK(std::find(rows.begin(), rows.end(), e) != rows.end());
    }

    // Independent of PixelSampler's own plumbing: dimension 0 of the camera stream is the raw
    // Philox block of counter (0, 0, 0, 0) under key (323, 0), and its floats are the film jitter
    // that traceSample records for pixel (3, 5).
    const PhiloxCounter raw = philox4x32_10({0u, 0u, 0u, 0u}, {323u, 0u});
    CHECK(PixelSampler(0, 323, 0).block(RngStream::Camera, 0) == raw);
    const Scene scene = loadTestScene("scenes/cornell-box.gltf", 64, 64);
    TraceSettings ts;
    ts.bdpt.maxDepth = 2;
    const TracedSample tr = traceSample(scene, ts, 3, 5, 0);
    CHECK(tr.raster.x == 3.f + uintToUnitFloat(raw[0]));
    CHECK(tr.raster.y == 5.f + uintToUnitFloat(raw[1]));
    CHECK(tr.lightChoice == uintToUnitFloat(philox4x32_10({0u, 0u, 0u, 1u}, {323u, 0u})[0]));
}
