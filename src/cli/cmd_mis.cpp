// `bdptref mis`: the MIS weight of every strategy of a full path given as JSON
// (docs/trace-and-mis.md). Scene form: misWeightsDefinition on the vertices with the scene, and the
// volume absorption of the path's segments; densities form: misWeightsFromDensities on explicit
// per-vertex densities. The job itself is the library's misWeightsOfPathFile (bdptref.h); this
// file parses options and prints.
#include "bdptref/bdptref.h"
#include "bdptref/errors.h"
#include "cli/commands.h"

#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>

namespace bdptref::cli {

namespace {

// Why the table above the absorption is unchanged by it (docs/materials.md, "Why MIS is unchanged").
constexpr const char* kAbsorptionAndMis =
    "the MIS weights do not depend on it: the transmittance is a factor of the path's contribution f, the same for every "
    "strategy that generates the path, and no sampling density includes it (docs/materials.md, \"Why MIS is unchanged\")";

nlohmann::ordered_json rgbJson(const Rgb& c) { return nlohmann::ordered_json::array({double(c.r), double(c.g), double(c.b)}); }

nlohmann::ordered_json absorptionJson(const std::vector<SegmentAbsorption>& segments) {
    nlohmann::ordered_json a = nlohmann::ordered_json::array();
    for (const SegmentAbsorption& s : segments) {
        nlohmann::ordered_json e{{"from", s.from},
                                 {"to", s.from + 1},
                                 {"material", s.material},
                                 {"materialName", s.materialName},
                                 {"sigma", rgbJson(s.sigma)},
                                 {"length", std::isfinite(s.length) ? nlohmann::ordered_json(s.length) : nlohmann::ordered_json("inf")},
                                 {"transmittance", rgbJson(s.transmittance)}};
        if (s.recorded) e["recorded"] = rgbJson(s.recordedTransmittance);
        a.push_back(e);
    }
    return nlohmann::ordered_json{{"segments", a}, {"misWeights", kAbsorptionAndMis}};
}

void printAbsorption(const std::vector<SegmentAbsorption>& segments) {
    std::printf("volume absorption, transmittance exp(-sigma length) per segment (docs/materials.md, \"Volume absorption\"):\n");
    std::printf("%9s  %-24s %-22s %s\n", "segment", "material", "length", "transmittance (r g b)");
    for (const SegmentAbsorption& s : segments) {
        const std::string segment = "x" + std::to_string(s.from) + "-x" + std::to_string(s.from + 1);
        const std::string material = std::to_string(s.material) + " '" + s.materialName + "'";
        std::printf("%9s  %-24s %-22.17g %.9g %.9g %.9g", segment.c_str(), material.c_str(), s.length, double(s.transmittance.r),
                    double(s.transmittance.g), double(s.transmittance.b));
        if (s.recorded)
            std::printf("  (recorded %.9g %.9g %.9g)", double(s.recordedTransmittance.r), double(s.recordedTransmittance.g),
                        double(s.recordedTransmittance.b));
        std::printf("\n");
    }
    std::printf("%s\n", kAbsorptionAndMis);
}

struct MisArgs {
    std::string file, scene, form = "auto", mis = "balance", strategy, lightSampler;
    double misBeta = 2.0;
    int width = 0, height = 0;
    std::string camera;
    bool json = false;
    CLI::Option* misOpt = nullptr;
    CLI::Option* betaOpt = nullptr;
};

// --strategy S,T: (-1, -1) when absent.
void parseStrategy(const std::string& text, int* s, int* t) {
    *s = -1, *t = -1;
    if (text.empty()) return;
    std::stringstream ss(text);
    char comma = 0;
    std::string rest;
    if (!(ss >> *s >> comma >> *t) || comma != ',' || (ss >> rest) || *s < 0 || *t < 1)
        throw InputError("--strategy: expected S,T with S >= 0 and T >= 1, got '" + text + "'");
}

MisPathOptions pathOptions(const MisArgs& a) {
    MisPathOptions options;
    options.form = a.form;
    options.sceneFile = a.scene;
    options.width = a.width;
    options.height = a.height;
    options.camera = a.camera;
    options.overrideBeta = a.betaOpt->count() > 0;
    options.beta = a.misBeta;
    if (!a.lightSampler.empty()) {
        options.overrideLightSampler = true;
        options.lightSampler = parseLightSamplerKind(a.lightSampler, "--light-sampler");
    }
    if (a.misOpt->count() > 0) {
        options.overrideHeuristic = true;
        options.heuristic = parseMisHeuristic(a.mis);
    }
    return options;
}

void printJson(const MisReport& report, const std::vector<SegmentAbsorption>& absorption) {
    const std::vector<StrategyVerdict>& verdicts = report.strategies;
    const RecursiveMisPath& rec = report.recursive;  // scene form only
    const int n = int(verdicts.size());
    nlohmann::ordered_json o;
    o["form"] = report.form;
    if (!report.sceneFile.empty()) o["scene"] = report.sceneFile;
    o["vertices"] = n;
    o["depth"] = n - 2;
    o["mis"] = misToJson(report.mis);
    o["producedBy"] = report.producedBy >= 0 ? nlohmann::ordered_json{{"s", report.producedBy}, {"t", n - report.producedBy}} : nlohmann::ordered_json();
    nlohmann::ordered_json st = nlohmann::ordered_json::array();
    for (const StrategyVerdict& v : verdicts) {
        nlohmann::ordered_json e{{"s", v.s}, {"t", v.t}, {"weight", v.weight}, {"valid", v.valid}};
        if (!v.valid) e["reason"] = v.reason;
        if (report.form == "densities" && v.valid && std::isfinite(v.logDensity)) e["logDensity"] = v.logDensity;
        if (size_t(v.s) < rec.weights.size()) e["recursiveWeight"] = rec.weights[size_t(v.s)];
        st.push_back(e);
    }
    o["strategies"] = st;
    if (!rec.vertices.empty()) {  // the recursive form's per-vertex quantities (docs/mis.md)
        nlohmann::ordered_json vs = nlohmann::ordered_json::array();
        for (size_t i = 0; i < rec.vertices.size(); ++i) {
            const RecursiveMisVertex& r = rec.vertices[i];
            vs.push_back({{"index", i},
                          {"camera", {{"dVCM", r.cameraDVCM}, {"dVC", r.cameraDVC}}},
                          {"light", {{"dVCM", r.lightDVCM}, {"dVC", r.lightDVC}}}});
        }
        o["recursive"] = vs;
    }
    if (!absorption.empty()) o["absorption"] = absorptionJson(absorption);
    o["sum"] = report.sum;
    std::fputs(formatJson(o).c_str(), stdout);
}

void printText(const MisReport& report, const std::vector<SegmentAbsorption>& absorption) {
    const std::vector<StrategyVerdict>& verdicts = report.strategies;
    const RecursiveMisPath& rec = report.recursive;  // scene form only
    const MisSettings& mis = report.mis;
    const int n = int(verdicts.size());
    const std::string& source = report.sceneFile;
    std::printf("path: %d vertices (depth %d); %s form%s%s; heuristic %s", n, n - 2, report.form.c_str(),
                source.empty() ? "" : ", scene ", source.c_str(), misHeuristicName(mis.heuristic).c_str());
    if (mis.heuristic == MisHeuristic::Power) std::printf(" (beta %g)", mis.beta);
    if (mis.lightSampler != LightSamplerKind::Power) std::printf("; s = 1 light sampler %s", lightSamplerName(mis.lightSampler));
    const bool recursive = !rec.weights.empty();
    std::printf("\n%5s %5s  %-22s%s\n", "s", "t", "weight", recursive ? " recursive" : "");
    for (const StrategyVerdict& v : verdicts) {
        std::printf("%5d %5d  %-22.17g ", v.s, v.t, v.weight);
        if (recursive) std::printf("%-22.17g ", rec.weights[size_t(v.s)]);
        if (!v.valid) std::printf("cannot sample: %s", v.reason.c_str());
        else if (v.s == report.producedBy) std::printf("<- produced this path");
        std::printf("\n");
    }
    std::printf("sum: %.17g\n", report.sum);
    if (recursive) {
        // x_i as the last vertex of the camera subpath x_0..x_i and of the light subpath x_{n-1}..x_i.
        std::printf("recursive MIS quantities (docs/mis.md, \"The recursive form\"):\n%5s  %-22s %-22s %-22s %s\n", "i",
                    "camera dVCM", "camera dVC", "light dVCM", "light dVC");
        for (size_t i = 0; i < rec.vertices.size(); ++i) {
            const RecursiveMisVertex& r = rec.vertices[i];
            std::printf("%5zu  %-22.17g %-22.17g %-22.17g %.17g\n", i, r.cameraDVCM, r.cameraDVC, r.lightDVCM, r.lightDVC);
        }
    }
    if (!absorption.empty()) printAbsorption(absorption);
}

int run(const MisArgs& a) {
    int s, t;
    parseStrategy(a.strategy, &s, &t);
    // The library does the job (form choice, scene loading, checks): one implementation for the
    // command and for library users (bdptref.h).
    std::vector<SegmentAbsorption> absorption;  // scene form: the absorbed segments (bdptref.h)
    const MisReport report = misWeightsOfPathFile(a.file, pathOptions(a), s, t, &absorption);
    for (const std::string& w : report.warnings) std::fprintf(stderr, "bdptref: warning: %s\n", w.c_str());
    if (a.json) printJson(report, absorption);
    else printText(report, absorption);
    return 0;
}

}  // namespace

std::function<int()> addMisCommand(CLI::App& app) {
    auto a = std::make_shared<MisArgs>();
    CLI::App* cmd = app.add_subcommand(
        "mis", "print the MIS weight of every strategy (s,t) of a full path given as JSON, their sum, which strategies "
               "cannot sample it and why, and the volume absorption of its segments (docs/trace-and-mis.md)");
    cmd->add_option("path", a->file, "path JSON ('bdptref-path', e.g. from 'bdptref trace --path S,T'), or a whole trace with --strategy")
        ->required();
    a->misOpt = cmd->add_option("--mis", a->mis, "heuristic: balance, power, uniform (default: the one recorded in the JSON, else balance)");
    a->betaOpt = cmd->add_option("--mis-beta", a->misBeta, "exponent of the power heuristic (default: recorded, else 2)");
    cmd->add_option("--light-sampler", a->lightSampler,
                    "next-event estimation's light choice in the s = 1 densities: power or tree (default: the one\n"
                    "recorded in the JSON's \"mis\", else power; docs/mis.md, 'Light tree in BDPT')");
    cmd->add_option("--scene", a->scene, "scene file for the scene form (default: the one recorded in the JSON)");
    cmd->add_option("--width", a->width, "image width of the camera (default: recorded, else 256); the camera density depends on it");
    cmd->add_option("--height", a->height, "image height (default: recorded, else 256)");
    cmd->add_option("--camera", a->camera, "camera of the file, index or name (default: the one recorded in the JSON, else the first)");
    cmd->add_option("--form", a->form,
                    "auto (default: scene references with a scene, else densities), scene (misWeightsDefinition), "
                    "densities (explicit per-vertex densities)");
    cmd->add_option("--strategy", a->strategy, "with a whole trace as input: the contributing connection S,T to take the path of");
    cmd->add_flag("--json", a->json, "print JSON instead of a table");
    cmd->footer("Exit codes: 0 done, 1 internal error, 2 bad input (missing file, malformed JSON, < 2 vertices, negative density, ...).");
    return [a] { return run(*a); };
}

}  // namespace bdptref::cli
