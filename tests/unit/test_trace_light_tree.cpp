// `bdptref trace` and `bdptref mis` with the light tree (--light-sampler tree; docs/mis.md, "Light
// tree in BDPT"; docs/trace-and-mis.md): a traced path records the sampler in its "mis" object, and
// `mis` reads it back, so it computes the render's weights for the same path; it never silently
// falls back to the power sampler's s = 1 density.
#include "bdptref/path_io.h"
#include "bdptref/trace.h"
#include "support/render_util.h"

#include <catch2/catch.hpp>

#include <fstream>
#include <map>
#include <sstream>

using namespace bdptref;
using namespace bdptref::test;
using Json = nlohmann::ordered_json;

namespace {

Json readJson(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return Json::parse(ss.str());
}

}  // namespace

TEST_CASE("mis command with the light tree: a traced path gives the render's weights", "[trace][cli][lighttree]") {
    const std::string dir = makeTempDir("trace-mis-tree");
    const std::string zoo = sourcePath("scenes/mis-zoo.gltf");
    const std::string common = " --width 24 --height 24 --env 0.3,0.35,0.4 --seed 3 --max-depth 6 --light-sampler tree";
    std::string out;
    const std::string trace = dir + "/trace.json";
    REQUIRE(runCli("trace " + zoo + " --pixel 12,12 --sample 7" + common + " -o " + trace, &out) == 0);
    const Json j = readJson(trace);
    std::map<int, int> kinds;  // s = 0, s = 1, t = 1, others: one path of each
    int checked = 0, differsWithPower = 0;
    for (const Json& c : j["connections"]) {
        if (c["status"] != "contributed") continue;
        const int s = c["s"].get<int>(), t = c["t"].get<int>();
        const int kind = s == 0 ? 0 : s == 1 ? 1 : t == 1 ? 2 : 3;
        if (kinds[kind]++ >= 1) continue;
        const std::string path = dir + "/path-" + std::to_string(s) + "-" + std::to_string(t) + ".json";
        std::ofstream(path) << formatJson(c["path"]);
        CHECK(c["path"]["mis"]["lightSampler"] == "tree");
        REQUIRE(runCli("mis " + path + " --json > " + dir + "/w.json", &out) == 0);
        const Json w = readJson(dir + "/w.json");
        CHECK(w["form"] == "scene");
        CHECK(w["mis"]["lightSampler"] == "tree");
        REQUIRE(w["strategies"].size() == c["definitionWeights"].size());
        for (size_t k = 0; k < w["strategies"].size(); ++k)
            CHECK(w["strategies"][k]["weight"].get<double>() == c["definitionWeights"][k].get<double>());
        CHECK(w["sum"].get<double>() == Approx(1.0).margin(1e-12));
        // The recursive form from the path alone gives the weight the render's connection computed.
        CHECK(w["strategies"][size_t(s)]["recursiveWeight"].get<double>() == c["weight"].get<double>());
        // Overriding the sampler changes the weights: the option is read, not ignored.
        REQUIRE(runCli("mis " + path + " --light-sampler power --json > " + dir + "/wp.json", &out) == 0);
        const Json wp = readJson(dir + "/wp.json");
        CHECK_FALSE(wp["mis"].contains("lightSampler"));
        bool differs = false;
        for (size_t k = 0; k < w["strategies"].size(); ++k)
            differs = differs || wp["strategies"][k]["weight"].get<double>() != w["strategies"][k]["weight"].get<double>();
        differsWithPower += differs;
        ++checked;
    }
    INFO(j["connections"].dump());
    CHECK(checked >= 3);
    CHECK(kinds[0] > 0);  // an s = 0 path (the emitter hit)
    CHECK(kinds[1] > 0);  // next-event estimation
    CHECK(differsWithPower >= 1);
    checkInputError("trace " + zoo + " --pixel 1,1 --integrator lt --light-sampler tree", "light tracing has no shading point");
    checkInputError("trace " + zoo + " --pixel 1,1 --light-sampler bvh", "--light-sampler: expected power or tree");
    checkInputError("mis " + trace + " --strategy 0,2 --light-sampler bvh", "--light-sampler: expected power or tree");
}
