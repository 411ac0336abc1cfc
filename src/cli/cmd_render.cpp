#include "bdptref/errors.h"
#include "bdptref/exr_io.h"
#include "bdptref/renderer.h"
#include "bdptref/version.h"
#include "cli/commands.h"
#include "cli/progress.h"
#include "cli/scene_options.h"
#include "cli/signals.h"

#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <sstream>
#include <thread>

namespace bdptref::cli {

namespace {

struct RenderArgs {
    SceneOptions scene;
    std::string output, preview;
    bool noPreview = false, quiet = false;
    int spp = 16, maxDepth = 64, threads = 0;
    long long seed = 0;
    std::string integrator = "path";
    std::string mis = "balance";
    double misBeta = 2.0;
    bool strategies = false;
    bool strict = false;  // non-finite samples make the run fail (exit kExitNonFinite)
    std::string crop;
};

// Exit code of `render --strict` when a sample or layer value was not finite (the EXR is still
// written, with the counts in its header, so the evidence is kept).
constexpr int kExitNonFinite = 3;

std::string defaultPreviewPath(const std::string& output) {
    std::filesystem::path p(output);
    p.replace_extension(".png");
    return p.string();
}

int run(const RenderArgs& a) {
    if (a.spp < 1) throw InputError("--spp must be at least 1");
    if (a.maxDepth < 0 || a.maxDepth > 100000) throw InputError("--max-depth must be between 0 and 100000");
    if (a.threads < 0) throw InputError("--threads must be >= 0 (0 = all cores)");
    if (a.seed < 0 || a.seed > 0xFFFFFFFFLL) throw InputError("--seed must be between 0 and 4294967295");
    const std::string preview = a.noPreview ? "" : (a.preview.empty() ? defaultPreviewPath(a.output) : a.preview);
    checkWritable(a.output);
    if (!preview.empty()) checkWritable(preview);

    const auto loadStart = std::chrono::steady_clock::now();
    Scene scene = loadScene(a.scene);
    for (const std::string& w : scene.info.warnings) std::fprintf(stderr, "bdptref: warning: %s\n", w.c_str());
    if (scene.lights.empty()) std::fprintf(stderr, "bdptref: warning: the scene has no lights; the image will be black\n");
    const double loadSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - loadStart).count();

    IntegratorSettings is;
    is.maxDepth = a.maxDepth;
    is.mis.heuristic = parseMisHeuristic(a.mis);
    if (!(a.misBeta > 0.0 && a.misBeta <= 16.0)) throw InputError("--mis-beta must be in (0, 16]");
    is.mis.beta = a.misBeta;
    is.recordStrategies = a.strategies;
    if (a.strategies && a.integrator == "path")
        throw InputError("--strategies needs --integrator bdpt or lt (the path tracer has no (s,t) strategies)");
    if (a.strategies && a.maxDepth > 32)
        throw InputError("--strategies writes 12 layers per (s,t) strategy: use --max-depth 32 or less with it");
    if (!a.crop.empty()) {
        int x0, y0, x1, y1;
        char c1, c2, c3;
        std::stringstream ss(a.crop);
        std::string rest;
        if (!(ss >> x0 >> c1 >> y0 >> c2 >> x1 >> c3 >> y1) || c1 != ',' || c2 != ',' || c3 != ',' || (ss >> rest) ||
            x0 < 0 || y0 < 0 || x1 > scene.camera.width() || y1 > scene.camera.height() || x0 >= x1 || y0 >= y1)
            throw InputError("--crop: expected x0,y0,x1,y1 with 0 <= x0 < x1 <= width and 0 <= y0 < y1 <= height, got '" + a.crop + "'");
        scene.camera = scene.camera.withCrop(x0, y0, x1, y1);
    }
    const auto integrator = makeIntegrator(a.integrator, is);
    RenderOptions ro;
    ro.spp = a.spp;
    ro.seed = uint32_t(a.seed);
    ro.threads = a.threads;
    Film film(scene.camera.width(), scene.camera.height());
    if (a.strategies) film.enableStrategies(a.maxDepth);

    installStopHandlers();
    ProgressBar bar(!a.quiet);
    const RenderStats stats = renderImage(scene, *integrator, ro, film, &stopRequested(),
                                          [&](const RenderProgress& p) { bar.update(p); });
    bar.finish();

    const int threadsUsed = a.threads > 0 ? a.threads : int(std::max(1u, std::thread::hardware_concurrency()));
    ExrMetadata md;
    md.strings = {{"bdptref:integrator", integrator->name()},
                  {"bdptref:scene", scene.info.path},
                  {"bdptref:sceneHash", scene.info.contentHash},
                  {"bdptref:camera", scene.info.cameraSource},
                  {"bdptref:environment", a.scene.env.empty() ? "none" : a.scene.env},
                  {"bdptref:mis", a.integrator == "bdpt" ? a.mis : "none"},
                  {"bdptref:crop", a.crop.empty() ? "none" : a.crop},
                  {"bdptref:version", BDPTREF_VERSION},
                  {"bdptref:gitRevision", BDPTREF_GIT_REVISION},
                  {"bdptref:status", stats.cancelled ? "interrupted" : "complete"},
                  {"bdptref:varianceLayers", "variance.{R,G,B} = variance of the pixel mean (s^2/n); count = samples"}};
    md.ints = {{"bdptref:spp", stats.passesDone},
               {"bdptref:sppRequested", a.spp},
               {"bdptref:seed", int(uint32_t(a.seed))},
               {"bdptref:maxDepth", a.maxDepth},
               {"bdptref:width", scene.camera.width()},
               {"bdptref:height", scene.camera.height()},
               {"bdptref:threads", threadsUsed},
               {"bdptref:nonFiniteSamples", int(std::min<uint64_t>(film.nonFiniteSamples(), 0x7FFFFFFF))},
               {"bdptref:nonFiniteLayerValues", int(std::min<uint64_t>(film.strategies().nonFiniteValues(), 0x7FFFFFFF))}};
    md.floats = {{"bdptref:renderSeconds", float(stats.seconds)}, {"bdptref:loadSeconds", float(loadSeconds)},
                 {"bdptref:misBeta", float(a.misBeta)}};
    if (stats.passesDone == 0) {
        std::fprintf(stderr, "bdptref: interrupted before the first sample pass finished; nothing written\n");
        return 128 + (stopSignal() ? stopSignal() : SIGINT);
    }
    writeFilmExr(a.output, film, md, integrator->producesSplats());
    if (!preview.empty()) writePreviewPng(preview, film);
    const uint64_t nonFinite = film.nonFiniteSamples() + film.strategies().nonFiniteValues();
    if (nonFinite > 0)
        std::fprintf(stderr,
                     "bdptref: %s: %llu samples and %llu strategy-layer values were not finite (counted as zero; "
                     "bdptref:nonFiniteSamples and bdptref:nonFiniteLayerValues in the EXR header)\n",
                     a.strict ? "error" : "warning", static_cast<unsigned long long>(film.nonFiniteSamples()),
                     static_cast<unsigned long long>(film.strategies().nonFiniteValues()));
    if (!a.quiet)
        std::fprintf(stderr, "bdptref: wrote %s (%dx%d, %d spp, %s render)%s%s\n", a.output.c_str(), film.width(),
                     film.height(), stats.passesDone, formatSeconds(stats.seconds).c_str(),
                     preview.empty() ? "" : " and ", preview.c_str());
    if (stats.cancelled) {
        std::fprintf(stderr, "bdptref: interrupted after %d of %d spp; the image holds the completed samples\n",
                     stats.passesDone, a.spp);
        return 128 + (stopSignal() ? stopSignal() : SIGINT);
    }
    if (a.strict && nonFinite > 0) return kExitNonFinite;
    return 0;
}

}  // namespace

std::function<int()> addRenderCommand(CLI::App& app) {
    auto args = std::make_shared<RenderArgs>();
    CLI::App* cmd = app.add_subcommand("render", "render a scene to an EXR (plus a PNG preview)");
    addSceneOptions(*cmd, args->scene);
    cmd->add_option("-o,--output", args->output, "output EXR file (written atomically)")->required();
    cmd->add_option("--spp", args->spp, "samples per pixel (default 16)");
    cmd->add_option("--max-depth", args->maxDepth,
                    "maximum path depth = path edges - 1 (0: emitters seen directly, 1: direct lighting; default 64)");
    cmd->add_option("--seed", args->seed, "random seed, 0..4294967295 (default 0)");
    cmd->add_option("--threads", args->threads, "worker threads (default 0 = all cores); the image does not depend on it");
    cmd->add_option("--integrator", args->integrator,
                    "estimator: path (unidirectional, NEE + MIS; default), lt (light tracing), bdpt (bidirectional)");
    cmd->add_option("--mis", args->mis, "BDPT MIS heuristic: balance (default), power, uniform");
    cmd->add_option("--mis-beta", args->misBeta, "exponent of the power heuristic (default 2)");
    cmd->add_flag("--strategies", args->strategies,
                  "write per-(s,t) layers s<S>t<T>.{weighted,unweighted}[.variance].{R,G,B} (bdpt, lt)");
    cmd->add_option("--crop", args->crop,
                    "render only pixels x0,y0,x1,y1 (x1, y1 exclusive) of the full image; same expected values there");
    cmd->add_flag("--strict", args->strict,
                  "fail (exit 3, after writing the EXR) when any sample or layer value was not finite (NaN/Inf);\n"
                  "without it they are counted as zero, reported on stderr and in the EXR header");
    cmd->add_option("--preview", args->preview, "PNG preview path (default: the output with .png)");
    cmd->add_flag("--no-preview", args->noPreview, "do not write the PNG preview");
    cmd->add_flag("-q,--quiet", args->quiet, "no progress or summary on stderr");
    cmd->footer(
        "Ctrl-C (SIGINT) or SIGTERM stops the render, writes the completed sample passes with their true\n"
        "sample count in the header (bdptref:spp, bdptref:status=interrupted) and exits with 128+signal.\n"
        "Exit codes: 0 done, 1 internal error, 2 bad input, 3 non-finite samples with --strict, 130/143 interrupted.");
    return [args] { return run(*args); };
}

}  // namespace bdptref::cli
