// `bdptref trace`: replays one BDPT / light-tracing pixel sample (megakernel or wavefront
// scheduler) and prints it as JSON (docs/trace-and-mis.md).
#include "bdptref/errors.h"
#include "bdptref/path_io.h"
#include "bdptref/trace.h"
#include "cli/commands.h"
#include "core/output_file.h"
#include "cli/scene_options.h"
#include "verify/trace_path.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <sstream>

namespace bdptref::cli {

namespace {

struct TraceArgs {
    SceneOptions scene;
    std::string pixel, path, output, crop;
    std::string integrator = "bdpt", mode = "megakernel", mis = "balance", lightSampler = "power";
    long long sample = 0, seed = 0;
    int maxDepth = 64;
    double misBeta = 2.0;
    bool noPaths = false, compact = false;
};

void parsePair(const std::string& text, const std::string& option, long long* a, long long* b) {
    std::stringstream ss(text);
    char comma = 0;
    std::string rest;
    if (!(ss >> *a >> comma >> *b) || comma != ',' || (ss >> rest))
        throw InputError(option + ": expected two integers 'A,B', got '" + text + "'");
}

void writeOutput(const std::string& file, const std::string& text) {
    if (file.empty() || file == "-") {
        std::fwrite(text.data(), 1, text.size(), stdout);
        std::fflush(stdout);
        return;
    }
    writeOutputText(file, text);  // durable: temp file, fsync, rename (core/output_file.h)
}

nlohmann::ordered_json number(double v) {
    if (std::isfinite(v)) return v;
    return std::isnan(v) ? "nan" : v > 0 ? "inf" : "-inf";  // as path_io.h writes them
}
nlohmann::ordered_json rgb(const Rgb& c) { return nlohmann::ordered_json::array({number(c.x), number(c.y), number(c.z)}); }

// The wavefront stages' view of the sample: every connection-queue entry, stage by stage.
nlohmann::ordered_json connectionQueueToJson(const TracedSample& traced) {
    nlohmann::ordered_json queue = nlohmann::ordered_json::array();
    for (const WavefrontQueueRecord& r : traced.connectionQueue) {
        nlohmann::ordered_json e{{"slot", r.slot}, {"s", r.s}, {"t", r.t}, {"connect", r.connected ? "contribution" : "none"}};
        if (r.connected) {
            e["unoccluded"] = rgb(r.unoccluded);
            e["shadowRay"] = r.shadowRay;
            e["shadow"] = !r.shadowRay ? "not-needed" : r.visible ? "unoccluded" : "occluded";
        }
        if (r.visible) {
            e["weight"] = number(r.weight);
            e["weighted"] = rgb(r.weighted);
        }
        queue.push_back(e);
    }
    return nlohmann::ordered_json{
        {"connectionQueue", queue},
        {"accumulate", nlohmann::ordered_json{{"L", rgb(traced.L)}, {"splats", traced.splats.size()}}},
        {"note", "subpaths: the PathVertex records of the pool buffers after the densities stage; connectionQueue: "
                 "the entries the expand stage wrote (slot order = path, t, s), with the connect stage's unoccluded "
                 "contribution, the shadow stage's result, the finish stage's MIS weight and the accumulate stage's "
                 "weighted value; total.L and total.splats: the accumulate stage's outputs"}};
}

// Every option checked before the scene is loaded (a bad command line costs nothing).
void checkArgs(const TraceArgs& a, bool pathTracing) {
    if (a.integrator != "bdpt" && a.integrator != "lt" && !pathTracing)
        throw InputError("--integrator: trace replays samples of 'path', 'lt' or 'bdpt', got '" + a.integrator + "'");
    if (pathTracing && a.mode != "megakernel")
        throw InputError("--mode " + a.mode + ": path-tracing samples are traced in the megakernel only (the wavefront path "
                         "tracer runs the same ptShade per bounce, so its numbers are the same)");
    if (pathTracing && !a.path.empty())
        throw InputError("--path: a path-tracing sample has no (s,t) strategies; its JSON lists every bounce instead");
    if (a.mode != "megakernel" && a.mode != "wavefront")
        throw InputError("--mode: expected 'megakernel' or 'wavefront', got '" + a.mode + "'");
    if (a.maxDepth < 0 || a.maxDepth > 100000) throw InputError("--max-depth must be between 0 and 100000");
    if (a.seed < 0 || a.seed > 0xFFFFFFFFLL) throw InputError("--seed must be between 0 and 4294967295");
    if (a.sample < 0) throw InputError("--sample must be >= 0");
    if (!(a.misBeta > 0.0 && a.misBeta <= 16.0)) throw InputError("--mis-beta must be in (0, 16]");
    parseLightSamplerKind(a.lightSampler, "--light-sampler");
    if (a.lightSampler == "tree" && (a.integrator == "lt" || a.integrator == "light"))
        throw InputError("--light-sampler tree needs --integrator path or bdpt: light tracing has no shading point to "
                         "choose a light at (docs/lights.md, \"Light tree\")");
    if (a.noPaths && !a.path.empty()) throw InputError("--path needs the full paths: do not combine it with --no-paths");
}

// What the JSON records of the scene, so that `mis` can load it again as it was rendered.
SceneReference sceneReference(const TraceArgs& a, const Scene& scene) {
    SceneReference ref;
    ref.file = std::filesystem::absolute(a.scene.scenePath).lexically_normal().string();
    ref.width = scene.camera.width();  // as resolved (a side not given follows the camera's aspect)
    ref.height = scene.camera.height();
    ref.camera = a.scene.camera;
    ref.env = a.scene.env;
    ref.envMap = a.scene.envMap.empty() ? "" : std::filesystem::absolute(a.scene.envMap).lexically_normal().string();
    ref.envScale = a.scene.envScale;
    ref.envRotate = a.scene.envRotate;
    ref.cameraPos = a.scene.cameraPos;
    ref.cameraTarget = a.scene.cameraTarget;
    ref.cameraUp = a.scene.cameraUp;
    ref.fov = a.scene.fovDegrees;
    ref.crop = a.crop;
    ref.contentHash = scene.info.contentHash;
    return ref;
}

// --path S,T: the JSON of that one strategy's full path, with its densities.
nlohmann::ordered_json strategyPathJson(const TraceArgs& a, const TracedSample& traced, long long ps, long long pt,
                                        const Scene& scene, const SceneReference& ref, const TraceSettings& ts) {
    const TracedConnection* found = nullptr;
    for (const TracedConnection& c : traced.connections)
        if (c.s == int(ps) && c.t == int(pt)) found = &c;
    if (!found)
        throw InputError("--path " + a.path + ": this sample has no strategy (" + std::to_string(ps) + "," + std::to_string(pt) +
                         ") (camera subpath " + std::to_string(traced.cameraPath.size()) + " vertices, light subpath " +
                         std::to_string(traced.lightPath.size()) + ")");
    if (found->status != ConnectionStatus::Contributed)
        throw InputError("--path " + a.path + ": strategy (" + std::to_string(ps) + "," + std::to_string(pt) +
                         ") contributed nothing in this sample: " + found->reason);
    return pathToJson(found->path, &found->densities, &scene, &ref, &ts.bdpt.mis, found->s);
}

int run(const TraceArgs& a) {
    const bool pathTracing = a.integrator == "path" || a.integrator == "pt";
    checkArgs(a, pathTracing);
    const LightSamplerKind lightSampler = parseLightSamplerKind(a.lightSampler, "--light-sampler");
    long long px = 0, py = 0, ps = -1, pt = -1;
    parsePair(a.pixel, "--pixel", &px, &py);
    if (!a.path.empty()) {
        parsePair(a.path, "--path", &ps, &pt);
        if (ps < 0 || pt < 1) throw InputError("--path: expected S,T with S >= 0 and T >= 1");
    }
    if (!a.output.empty() && a.output != "-") checkOutputs({{"-o", a.output, ""}});

    Scene scene = loadScene(a.scene);
    for (const std::string& w : scene.info.warnings) std::fprintf(stderr, "bdptref: warning: %s\n", w.c_str());
    applyCropWindow(scene, a.crop);
    if (px < 0 || py < 0 || px >= scene.camera.width() || py >= scene.camera.height())
        throw InputError("--pixel: (" + std::to_string(px) + ", " + std::to_string(py) + ") is outside the " +
                         std::to_string(scene.camera.width()) + "x" + std::to_string(scene.camera.height()) + " image");
    const SceneReference ref = sceneReference(a, scene);

    if (pathTracing) {
        IntegratorSettings is;
        is.maxDepth = a.maxDepth;
        is.lightSampler = lightSampler;
        const TracedPathSample traced = tracePathSample(scene, uint32_t(a.seed), is, int(px), int(py), uint64_t(a.sample));
        const nlohmann::ordered_json out = pathTraceToJson(traced, scene, &ref);
        writeOutput(a.output, a.compact ? out.dump() + "\n" : formatJson(out));
        return 0;
    }

    TraceSettings ts;
    ts.integrator = a.integrator;
    ts.seed = uint32_t(a.seed);
    ts.bdpt.maxDepth = a.maxDepth;
    ts.bdpt.mis.heuristic = parseMisHeuristic(a.mis);
    ts.bdpt.mis.beta = a.misBeta;
    ts.bdpt.mis.lightSampler = lightSampler;
    ts.fullPaths = !a.noPaths;
    const TracedSample traced = a.mode == "wavefront" ? traceSampleWavefront(scene, ts, int(px), int(py), uint64_t(a.sample))
                                                      : traceSample(scene, ts, int(px), int(py), uint64_t(a.sample));
    nlohmann::ordered_json out;
    if (!a.path.empty()) {
        out = strategyPathJson(a, traced, ps, pt, scene, ref, ts);
    } else {
        out = traceToJson(traced, scene, &ref);
        if (traced.mode == "wavefront") out["wavefront"] = connectionQueueToJson(traced);
    }
    writeOutput(a.output, a.compact ? out.dump() + "\n" : formatJson(out));
    return 0;
}

}  // namespace

std::function<int()> addTraceCommand(CLI::App& app) {
    auto a = std::make_shared<TraceArgs>();
    CLI::App* cmd = app.add_subcommand(
        "trace", "replay one BDPT (or lt, or path) pixel sample exactly as the renderer computes it and print every vertex and (s,t) "
                 "connection as JSON (docs/trace-and-mis.md)");
    addSceneOptions(*cmd, a->scene);
    cmd->add_option("--pixel", a->pixel, "pixel X,Y in full-image coordinates (x right, y down)")->required();
    cmd->add_option("--sample", a->sample, "sample index (the render's pass number, 0-based; default 0)");
    cmd->add_option("--seed", a->seed, "random seed of the render, 0..4294967295 (default 0)");
    cmd->add_option("--max-depth", a->maxDepth, "maximum path depth, as render (default 64)");
    cmd->add_option("--mis", a->mis, "MIS heuristic: balance (default), power, uniform");
    cmd->add_option("--mis-beta", a->misBeta, "exponent of the power heuristic (default 2)");
    cmd->add_option("--light-sampler", a->lightSampler,
                    "next-event estimation's light choice, as render: power (default) or tree (path, bdpt; the path JSON\n"
                    "records it, so that 'bdptref mis' uses the same s = 1 densities)");
    cmd->add_option("--integrator", a->integrator,
                    "bdpt (default), lt (light tracing: t = 1 only, weight 1) or path (path tracing: every bounce's hit, "
                    "emission with its MIS weight, next-event sample, BSDF sample, roulette and random numbers)");
    cmd->add_option("--mode", a->mode,
                    "megakernel (default: the integrator's function) or wavefront (the wavefront scheduler's stages, "
                    "restricted to this pixel; adds a 'wavefront' object with every connection-queue entry)");
    cmd->add_option("--crop", a->crop, "the render's crop window x0,y0,x1,y1, if it had one (it changes the t = 1 densities)");
    cmd->add_option("--path", a->path, "print only the full path of contributing strategy S,T, in the input format of 'bdptref mis'");
    cmd->add_flag("--no-paths", a->noPaths, "omit the full path, densities and definition weights of each contribution");
    cmd->add_flag("--compact", a->compact, "one-line JSON instead of indented");
    cmd->add_option("-o,--output", a->output, "write the JSON to this file instead of stdout");
    cmd->footer("Exit codes: 0 done, 1 internal error, 2 bad input.");
    return [a] { return run(*a); };
}

}  // namespace bdptref::cli
