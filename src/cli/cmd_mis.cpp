// `bdptref mis`: the MIS weight of every strategy of a full path given as JSON
// (docs/trace-and-mis.md). Scene form: misWeightsDefinition on the vertices with the scene;
// densities form: misWeightsFromDensities on explicit per-vertex densities.
#include "bdptref/errors.h"
#include "bdptref/path_io.h"
#include "bdptref/scene.h"
#include "bdptref/trace.h"
#include "cli/commands.h"
#include "cli/scene_options.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>

namespace bdptref::cli {

namespace {

struct MisArgs {
    std::string file, scene, form = "auto", mis = "balance", strategy;
    double misBeta = 2.0;
    int width = 0, height = 0;
    bool json = false;
    CLI::Option* misOpt = nullptr;
    CLI::Option* betaOpt = nullptr;
};

int run(const MisArgs& a) {
    int s = -1, t = -1;
    if (!a.strategy.empty()) {
        std::stringstream ss(a.strategy);
        char comma = 0;
        std::string rest;
        if (!(ss >> s >> comma >> t) || comma != ',' || (ss >> rest) || s < 0 || t < 1)
            throw InputError("--strategy: expected S,T with S >= 0 and T >= 1, got '" + a.strategy + "'");
    }
    if (a.form != "auto" && a.form != "scene" && a.form != "densities")
        throw InputError("--form: expected auto, scene or densities, got '" + a.form + "'");
    if (a.width < 0 || a.height < 0) throw InputError("--width/--height must be positive");
    PathDescription d = readPathFile(a.file, s, t);

    MisSettings mis = d.hasMis ? d.mis : MisSettings{};
    if (a.misOpt->count() > 0) mis.heuristic = parseMisHeuristic(a.mis);
    if (a.betaOpt->count() > 0) {
        if (!(a.misBeta > 0.0 && a.misBeta <= 16.0)) throw InputError("--mis-beta must be in (0, 16]");
        mis.beta = a.misBeta;
    }

    const bool sceneAvailable = !a.scene.empty() || d.hasScene;
    std::string form = a.form;
    if (form == "auto") {
        if (d.hasSceneVertices && sceneAvailable) form = "scene";
        else if (d.hasDensities) form = "densities";
        else if (d.hasSceneVertices)
            throw InputError("the path has scene references but no scene: give --scene FILE (or record \"scene\" in the JSON), "
                             "or give every vertex \"pdfCamera\"/\"pdfLight\" (docs/trace-and-mis.md)");
        else
            throw InputError("the path has neither scene references (\"type\" and \"p\" on every vertex) nor densities "
                             "(\"pdfCamera\", \"pdfLight\" on every vertex, \"pdfNextEvent\" on the last): see docs/trace-and-mis.md");
    }
    if (form == "scene" && !d.hasSceneVertices) throw InputError("--form scene: every vertex needs \"type\" and \"p\"");
    if (form == "scene" && !sceneAvailable) throw InputError("--form scene: give --scene FILE (the path records no scene)");
    if (form == "densities" && !d.hasDensities)
        throw InputError("--form densities: every vertex needs \"pdfCamera\" and \"pdfLight\" (x0 may omit them) and the "
                         "last one \"pdfNextEvent\"");

    std::vector<StrategyVerdict> verdicts;
    std::string source;
    if (form == "scene") {
        SceneOptions so;
        so.scenePath = a.scene.empty() ? d.scene.file : a.scene;
        if (d.hasScene) {
            so.width = d.scene.width;
            so.height = d.scene.height;
            so.env = d.scene.env;
            so.cameraPos = d.scene.cameraPos;
            so.cameraTarget = d.scene.cameraTarget;
            so.cameraUp = d.scene.cameraUp.empty() ? "0,1,0" : d.scene.cameraUp;
            so.fovDegrees = d.scene.fov;
        }
        if (a.width > 0) so.width = a.width;
        if (a.height > 0) so.height = a.height;
        Scene scene = loadScene(so);
        if (d.hasScene) applyCropWindow(scene, d.scene.crop);
        if (d.hasScene && !d.scene.contentHash.empty() && d.scene.contentHash != scene.info.contentHash)
            std::fprintf(stderr, "bdptref: warning: '%s' is not the scene the path was traced in (content hash %s, recorded %s)\n",
                         so.scenePath.c_str(), scene.info.contentHash.c_str(), d.scene.contentHash.c_str());
        // The file's positions are world coordinates; the scene works in render space.
        const std::vector<PathVertex> vertices = verticesInRenderSpace(d, scene);
        validateScenePath(scene, vertices);
        const DVec3 eye = scene.toWorld(scene.camera.position()), x0 = d.worldPositions[0];
        if (glm::length(x0 - eye) > 1e-4 * std::max(1.0, glm::length(eye)))
            std::fprintf(stderr,
                         "bdptref: warning: vertex 0 (%g, %g, %g) is not at the scene camera's position (%g, %g, %g): the "
                         "camera's direction density is evaluated from vertex 0 with the scene's camera\n",
                         x0.x, x0.y, x0.z, eye.x, eye.y, eye.z);
        verdicts = analyseMisScene(scene, vertices, mis);
        source = so.scenePath;
    } else {
        verdicts = analyseMisDensities(d.densities, mis);
    }

    const int n = int(verdicts.size());
    double sum = 0.0;
    for (const StrategyVerdict& v : verdicts) sum += v.weight;
    if (a.json) {
        nlohmann::ordered_json o;
        o["form"] = form;
        if (!source.empty()) o["scene"] = source;
        o["vertices"] = n;
        o["depth"] = n - 2;
        o["mis"] = misToJson(mis);
        o["producedBy"] = d.s >= 0 ? nlohmann::ordered_json{{"s", d.s}, {"t", n - d.s}} : nlohmann::ordered_json();
        nlohmann::ordered_json st = nlohmann::ordered_json::array();
        for (const StrategyVerdict& v : verdicts) {
            nlohmann::ordered_json e{{"s", v.s}, {"t", v.t}, {"weight", v.weight}, {"valid", v.valid}};
            if (!v.valid) e["reason"] = v.reason;
            if (form == "densities" && v.valid && std::isfinite(v.logDensity)) e["logDensity"] = v.logDensity;
            st.push_back(e);
        }
        o["strategies"] = st;
        o["sum"] = sum;
        std::fputs(formatJson(o).c_str(), stdout);
        return 0;
    }
    std::printf("path: %d vertices (depth %d); %s form%s%s; heuristic %s", n, n - 2, form.c_str(),
                source.empty() ? "" : ", scene ", source.c_str(), misHeuristicName(mis.heuristic).c_str());
    if (mis.heuristic == MisHeuristic::Power) std::printf(" (beta %g)", mis.beta);
    std::printf("\n%5s %5s  %-22s %s\n", "s", "t", "weight", "");
    for (const StrategyVerdict& v : verdicts) {
        std::printf("%5d %5d  %-22.17g ", v.s, v.t, v.weight);
        if (!v.valid) std::printf("cannot sample: %s", v.reason.c_str());
        else if (v.s == d.s) std::printf("<- produced this path");
        std::printf("\n");
    }
    std::printf("sum: %.17g\n", sum);
    return 0;
}

}  // namespace

std::function<int()> addMisCommand(CLI::App& app) {
    auto a = std::make_shared<MisArgs>();
    CLI::App* cmd = app.add_subcommand(
        "mis", "print the MIS weight of every strategy (s,t) of a full path given as JSON, their sum, and which strategies "
               "cannot sample it and why (docs/trace-and-mis.md)");
    cmd->add_option("path", a->file, "path JSON ('bdptref-path', e.g. from 'bdptref trace --path S,T'), or a whole trace with --strategy")
        ->required();
    a->misOpt = cmd->add_option("--mis", a->mis, "heuristic: balance, power, uniform (default: the one recorded in the JSON, else balance)");
    a->betaOpt = cmd->add_option("--mis-beta", a->misBeta, "exponent of the power heuristic (default: recorded, else 2)");
    cmd->add_option("--scene", a->scene, "scene file for the scene form (default: the one recorded in the JSON)");
    cmd->add_option("--width", a->width, "image width of the camera (default: recorded, else 256); the camera density depends on it");
    cmd->add_option("--height", a->height, "image height (default: recorded, else 256)");
    cmd->add_option("--form", a->form,
                    "auto (default: scene references with a scene, else densities), scene (misWeightsDefinition), "
                    "densities (explicit per-vertex densities)");
    cmd->add_option("--strategy", a->strategy, "with a whole trace as input: the contributing connection S,T to take the path of");
    cmd->add_flag("--json", a->json, "print JSON instead of a table");
    cmd->footer("Exit codes: 0 done, 1 internal error, 2 bad input (missing file, malformed JSON, < 2 vertices, negative density, ...).");
    return [a] { return run(*a); };
}

}  // namespace bdptref::cli
