// `bdptref mis` shows the volume absorption of a path (KHR_materials_volume; docs/trace-and-mis.md,
// docs/materials.md "Volume absorption"):
//  * on a path traced through an absorbing rough glass box, `mis --json` lists exactly the
//    segments inside the box (decided here by geometry: the segment's midpoint lies inside the
//    box), each with exp(-sigma d) computed here from the vertex positions and the material's
//    attenuationColor / attenuationDistance, and with the value `trace` recorded; the text form
//    prints them and the line on why the MIS weights do not depend on them; the weights are the
//    trace's definition weights all the same;
//  * a recorded transmittance that the scene does not give (an edited value, one on a segment the
//    scene does not absorb, and every one when the scene loses its absorption) is a warning;
//  * the library's misWeightsOfPathFile gives the same segments.
#include "bdptref/bdptref.h"
#include "support/gltf_builder.h"
#include "support/render_util.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <sstream>

using namespace bdptref;
using namespace bdptref::test;
using Json = nlohmann::ordered_json;

namespace {

// The absorbing box and its medium (world coordinates, y up).
constexpr std::array<double, 3> kBoxLo{-0.35, 0.5, -0.35}, kBoxHi{0.35, 1.1, 0.35};
constexpr std::array<double, 3> kColor{0.8, 0.5, 0.25};
constexpr double kDistance = 0.6;
constexpr int kSize = 16;
const char* const kCamera = " --camera-pos 0,2.2,2.4 --camera-target 0,0.6,0 --fov 40";

// Floor, the absorbing rough glass box (material "absorber") and a wide area light above.
std::string writeScene(const std::string& name, bool absorbing) {
    Doc d;
    d.quad({-4, 0, 4}, {4, 0, 4}, {4, 0, -4}, {-4, 0, -4}, d.lambert({0.6, 0.6, 0.6}));
    d.use("KHR_materials_transmission");
    d.use("KHR_materials_ior");
    Json ext{{"KHR_materials_transmission", {{"transmissionFactor", 1.0}}}, {"KHR_materials_ior", {{"ior", 1.5}}}};
    if (absorbing) {
        d.use("KHR_materials_volume");
        ext["KHR_materials_volume"] = {{"thicknessFactor", 1.0}, {"attenuationColor", {kColor[0], kColor[1], kColor[2]}},
                                       {"attenuationDistance", kDistance}};
    }
    const int glass = d.material({{"name", "absorber"},
                                  {"pbrMetallicRoughness", {{"baseColorFactor", {1, 1, 1, 1}}, {"metallicFactor", 0}, {"roughnessFactor", 0.3}}},
                                  {"extensions", ext}});
    d.box(kBoxLo, kBoxHi, glass);
    d.quad({-2.5, 3, -2.5}, {2.5, 3, -2.5}, {2.5, 3, 2.5}, {-2.5, 3, 2.5}, d.lambert({0, 0, 0}, {1, 1, 1}, 3.0));
    return d.write(name);
}

enum class Where { Inside, Outside, Ambiguous };

// Inside the (convex) box iff the segment's midpoint is; a midpoint on the boundary is ambiguous.
Where segmentPlace(const DVec3& a, const DVec3& b) {
    const DVec3 m = 0.5 * (a + b);
    constexpr double eps = 1e-4;
    bool inside = true, near = false;
    for (int c = 0; c < 3; ++c) {
        const double lo = kBoxLo[size_t(c)], hi = kBoxHi[size_t(c)];
        inside = inside && m[c] > lo + eps && m[c] < hi - eps;
        near = near || (m[c] > lo - eps && m[c] < hi + eps && (std::abs(m[c] - lo) <= eps || std::abs(m[c] - hi) <= eps));
    }
    return inside ? Where::Inside : near ? Where::Ambiguous : Where::Outside;
}

DVec3 point(const Json& v) { return DVec3(v["p"][0].get<double>(), v["p"][1].get<double>(), v["p"][2].get<double>()); }

std::string readText(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

struct Found {
    int x = -1, y = -1, sample = -1, s = -1, t = -1;
};

// A contributing connection whose path has a segment inside the box and one outside, none on its
// boundary; searched with the library's replay of the command's sample (same scene options).
Found findPathThroughBox(const std::string& file) {
    SceneReference ref;
    ref.file = file;
    ref.width = ref.height = kSize;
    ref.cameraPos = "0,2.2,2.4";
    ref.cameraTarget = "0,0.6,0";
    ref.fov = 40;
    const Scene scene = loadSceneFile(ref);
    TraceSettings ts;
    ts.seed = 7;
    ts.bdpt.maxDepth = 6;
    for (int k = 0; k < 64; ++k)
        for (int y = 4; y < 12; ++y)
            for (int x = 4; x < 12; ++x) {
                const TracedSample tr = traceSample(scene, ts, x, y, uint64_t(k));
                for (const TracedConnection& c : tr.connections) {
                    if (c.status != ConnectionStatus::Contributed || c.path.empty() || c.path.back().infinite) continue;
                    int inside = 0, outside = 0, ambiguous = 0;
                    for (size_t i = 0; i + 1 < c.path.size(); ++i) {
                        const Where w = segmentPlace(scene.toWorld(c.path[i].p), scene.toWorld(c.path[i + 1].p));
                        inside += w == Where::Inside;
                        outside += w == Where::Outside;
                        ambiguous += w == Where::Ambiguous;
                    }
                    if (inside >= 1 && outside >= 1 && ambiguous == 0) return Found{x, y, k, c.s, c.t};
                }
            }
    return Found{};
}

}  // namespace

TEST_CASE("mis: the transmittance of exactly the segments inside an absorbing box, exp(-sigma d), and why the weights ignore it",
          "[trace][cli][volume]") {
    const std::string dir = makeTempDir("mis-absorption");
    const std::string scene = writeScene("mis-absorbing-box.gltf", true);
    const Found f = findPathThroughBox(scene);
    REQUIRE(f.s >= 0);
    const std::string st = std::to_string(f.s) + "," + std::to_string(f.t);
    const std::string trace = "trace " + scene + kCamera + " --width 16 --height 16 --seed 7 --max-depth 6 --pixel " +
                              std::to_string(f.x) + "," + std::to_string(f.y) + " --sample " + std::to_string(f.sample);
    std::string out;
    const std::string pathFile = dir + "/p.json", whole = dir + "/trace.json";
    REQUIRE(runCli(trace + " --path " + st + " -o " + pathFile, &out) == 0);
    REQUIRE(runCli(trace + " -o " + whole, &out) == 0);
    REQUIRE(runCli("mis " + pathFile + " --json > " + dir + "/w.json", &out) == 0);
    INFO(out);
    const Json path = Json::parse(readText(pathFile)), w = Json::parse(readText(dir + "/w.json"));
    const Json& vs = path["vertices"];
    INFO(path.dump() << "\n" << w.dump());

    // The expected list, from geometry and the glTF's numbers alone.
    std::vector<int> insideFrom;
    for (size_t i = 0; i + 1 < vs.size(); ++i)
        if (segmentPlace(point(vs[i]), point(vs[i + 1])) == Where::Inside) insideFrom.push_back(int(i));
    REQUIRE(!insideFrom.empty());
    REQUIRE(insideFrom.size() + 1 < vs.size());  // and some segment outside
    REQUIRE(w.contains("absorption"));
    const Json& segs = w["absorption"]["segments"];
    REQUIRE(segs.size() == insideFrom.size());
    for (size_t k = 0; k < segs.size(); ++k) {
        const int from = insideFrom[k];
        CHECK(segs[k]["from"] == from);
        CHECK(segs[k]["to"] == from + 1);
        CHECK(segs[k]["materialName"] == "absorber");
        const double d = glm::length(point(vs[size_t(from) + 1]) - point(vs[size_t(from)]));
        CHECK(segs[k]["length"].get<double>() == Approx(d).epsilon(1e-6));
        for (size_t c = 0; c < 3; ++c) {
            const double sigma = -std::log(kColor[c]) / kDistance;
            CHECK(segs[k]["transmittance"][c].get<double>() == Approx(std::exp(-sigma * d)).epsilon(1e-5));
            // trace recorded the same value on the vertex the segment reached
            CHECK(segs[k]["recorded"][c].get<double>() == segs[k]["transmittance"][c].get<double>());
        }
    }
    // Outside segments: no entry, and the path records none either (transmittance 1).
    for (size_t i = 1; i < vs.size(); ++i)
        if (std::find(insideFrom.begin(), insideFrom.end(), int(i) - 1) == insideFrom.end()) CHECK(!vs[i].contains("transmittance"));
    CHECK(w["absorption"]["misWeights"].get<std::string>().find("do not depend") != std::string::npos);

    // The weights are the trace's definition weights regardless.
    const Json t = Json::parse(readText(whole));
    bool compared = false;
    for (const Json& c : t["connections"])
        if (c["s"] == f.s && c["t"] == f.t) {
            REQUIRE(c["definitionWeights"].size() == w["strategies"].size());
            for (size_t k = 0; k < w["strategies"].size(); ++k)
                CHECK(w["strategies"][k]["weight"].get<double>() == c["definitionWeights"][k].get<double>());
            compared = true;
        }
    CHECK(compared);

    // The text form: the segments, the reason line, no warning.
    REQUIRE(runCli("mis " + pathFile, &out) == 0);
    CHECK(out.find("volume absorption") != std::string::npos);
    CHECK(out.find("x" + std::to_string(insideFrom[0]) + "-x" + std::to_string(insideFrom[0] + 1)) != std::string::npos);
    CHECK(out.find("the MIS weights do not depend on it") != std::string::npos);
    CHECK(out.find("warning") == std::string::npos);

    // The library gives the same segments.
    std::vector<SegmentAbsorption> lib;
    misWeightsOfPathFile(pathFile, {}, -1, -1, &lib);
    REQUIRE(lib.size() == segs.size());
    for (size_t k = 0; k < lib.size(); ++k) {
        CHECK(lib[k].from == insideFrom[k]);
        CHECK(lib[k].recorded);
        CHECK(double(lib[k].transmittance.g) == segs[k]["transmittance"][1].get<double>());
    }
}

TEST_CASE("mis: a recorded transmittance the scene does not give is a warning", "[trace][cli][volume]") {
    const std::string dir = makeTempDir("mis-absorption-warn");
    const std::string scene = writeScene("mis-absorbing-box-w.gltf", true);
    const std::string clear = writeScene("mis-clear-box.gltf", false);
    const Found f = findPathThroughBox(scene);
    REQUIRE(f.s >= 0);
    std::string out;
    const std::string pathFile = dir + "/p.json";
    REQUIRE(runCli("trace " + scene + kCamera + " --width 16 --height 16 --seed 7 --max-depth 6 --pixel " + std::to_string(f.x) +
                       "," + std::to_string(f.y) + " --sample " + std::to_string(f.sample) + " --path " + std::to_string(f.s) +
                       "," + std::to_string(f.t) + " -o " + pathFile,
                   &out) == 0);
    Json path = Json::parse(readText(pathFile));
    int absorbedTo = -1, clearTo = -1;  // a vertex reached through the medium, and one not
    for (size_t i = 1; i < path["vertices"].size(); ++i) {
        if (path["vertices"][i].contains("transmittance")) absorbedTo = int(i);
        else clearTo = int(i);
    }
    REQUIRE(absorbedTo > 0);
    REQUIRE(clearTo > 0);

    // Unchanged: no warning about it.
    REQUIRE(runCli("mis " + pathFile, &out) == 0);
    CHECK(out.find("is not the scene's transmittance") == std::string::npos);
    // The same path in the scene without the volume: every recorded value is a warning, and
    // nothing is absorbed.
    REQUIRE(runCli("mis " + pathFile + " --scene " + clear + " --json", &out) == 0);
    CHECK(out.find("vertices[" + std::to_string(absorbedTo) + "].transmittance") != std::string::npos);
    CHECK(out.find("(no absorption)") != std::string::npos);
    CHECK(out.find("\"absorption\"") == std::string::npos);

    // Edited values: one on an absorbed segment, one on a segment the scene does not absorb.
    path["vertices"][size_t(absorbedTo)]["transmittance"] = Json::array({0.5, 0.5, 0.5});
    path["vertices"][size_t(clearTo)]["transmittance"] = Json::array({0.9, 0.9, 0.9});
    std::ofstream(dir + "/edited.json") << path.dump();
    REQUIRE(runCli("mis " + dir + "/edited.json", &out) == 0);
    INFO(out);
    const std::string absorbedSegment = "x" + std::to_string(absorbedTo - 1) + "-x" + std::to_string(absorbedTo);
    const std::string clearSegment = "x" + std::to_string(clearTo - 1) + "-x" + std::to_string(clearTo);
    CHECK(out.find("warning: vertices[" + std::to_string(absorbedTo) + "].transmittance (0.5, 0.5, 0.5) is not the scene's "
                   "transmittance of the segment " + absorbedSegment) != std::string::npos);
    CHECK(out.find("transmittance of the segment " + clearSegment + ", (1, 1, 1) (no absorption)") != std::string::npos);
    CHECK(out.find("(recorded 0.5 0.5 0.5)") != std::string::npos);  // the table shows what the file said
}
