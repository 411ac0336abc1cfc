#include "bdptref/checkpoint.h"
#include "bdptref/errors.h"
#include "bdptref/film_merge.h"
#include "bdptref/exr_io.h"
#include "bdptref/renderer.h"
#include "bdptref/version.h"
#include "bdptref/wavefront.h"
#include "cli/commands.h"
#include "cli/progress.h"
#include "cli/render_record.h"
#include "cli/scene_options.h"
#include "cli/signals.h"
#include "core/output_file.h"

#include <nlohmann/json.hpp>

#include <chrono>
#include <climits>
#include <cmath>
#include <fstream>
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
    // Ground-truth production (docs/ground-truth.md).
    bool sppGiven = false;
    double timeBudget = 0, checkpointEvery = 0;
    std::string resume, sampleRange, statsPath;
    // GPU-style wavefront schedule (docs/wavefront.md).
    std::string mode = "megakernel", gpuReport;
    int wavefrontPool = 0;
};

std::string canonicalVec3(const std::string& text, const std::string& option) {
    if (text.empty()) return "";
    const Vec3 v = parseVec3(text, option);
    char buf[96];
    std::snprintf(buf, sizeof buf, "%.9g,%.9g,%.9g", double(v.x), double(v.y), double(v.z));
    return buf;
}

// This process's command line (Linux /proc), for the bdptref:invocation attribute.
std::string invocationText() {
    std::ifstream f("/proc/self/cmdline", std::ios::binary);
    std::string arg, text;
    while (std::getline(f, arg, '\0')) text += (text.empty() ? "" : " ") + shellQuote(arg);
    return text;
}

ImageSettings imageSettings(const RenderArgs& a, const Scene& scene, const std::string& integratorName) {
    ImageSettings s;
    s.scenePath = a.scene.scenePath;
    s.sceneHash = scene.info.contentHash;
    s.width = scene.camera.width();
    s.height = scene.camera.height();
    if (!a.scene.cameraPos.empty()) {
        s.cameraPos = canonicalVec3(a.scene.cameraPos, "--camera-pos");
        s.cameraTarget = canonicalVec3(a.scene.cameraTarget, "--camera-target");
        s.cameraUp = canonicalVec3(a.scene.cameraUp, "--camera-up");
    }
    s.fovDegrees = a.scene.fovDegrees;
    s.env = canonicalVec3(a.scene.env, "--env");
    s.integrator = integratorName;
    s.mis = a.integrator == "bdpt" ? a.mis : "none";
    s.misBeta = a.misBeta;
    s.maxDepth = a.maxDepth;
    s.seed = uint32_t(a.seed);
    if (!a.crop.empty()) {
        const Camera& c = scene.camera;
        s.crop = std::to_string(c.cropX0()) + "," + std::to_string(c.cropY0()) + "," + std::to_string(c.cropX1()) + "," +
                 std::to_string(c.cropY1());
    }
    s.strategies = a.strategies;
    return s;
}

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
    // The samples to render: --sample-range A:B, else [0, --spp); with only --time, no upper end.
    if (a.sppGiven && !a.sampleRange.empty()) throw InputError("--spp and --sample-range: give one of them, not both");
    SampleRange range{0, uint64_t(a.spp)};
    if (!a.sampleRange.empty()) range = parseSampleRange(a.sampleRange, "--sample-range");
    if (a.timeBudget < 0 || !std::isfinite(a.timeBudget)) throw InputError("--time must be a positive number of seconds");
    if (a.timeBudget > 0 && !a.sppGiven && a.sampleRange.empty()) range.end = UINT64_MAX;
    if (a.checkpointEvery < 0 || !std::isfinite(a.checkpointEvery))
        throw InputError("--checkpoint-every must be a positive number of seconds");
    if (a.maxDepth < 0 || a.maxDepth > 100000) throw InputError("--max-depth must be between 0 and 100000");
    if (a.threads < 0) throw InputError("--threads must be >= 0 (0 = all cores)");
    if (a.seed < 0 || a.seed > 0xFFFFFFFFLL) throw InputError("--seed must be between 0 and 4294967295");
    const std::string preview = a.noPreview ? "" : (a.preview.empty() ? defaultPreviewPath(a.output) : a.preview);
    checkWritable(a.output);
    if (!preview.empty()) checkWritable(preview);
    if (!a.statsPath.empty()) checkWritable(a.statsPath);
    checkOutputs({{"-o", a.output, ".exr"}, {"--preview", preview, ".png"}, {"--stats", a.statsPath, ""}, {"--gpu-report", a.gpuReport, ""}});

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
    const ImageSettings settings = imageSettings(a, scene, integrator->name());
    const std::string settingsKey = settingsText(settings);
    const std::string invocation = invocationText();
    Film film(scene.camera.width(), scene.camera.height());
    if (a.strategies) film.enableStrategies(a.maxDepth);
    double previousSeconds = 0;  // render time already in a resumed checkpoint
    if (!a.resume.empty()) {
        FilmFile ck = readFilmExr(a.resume);
        if (ck.attribute(kAttrSettings) != settingsKey)
            throw InputError("--resume " + a.resume + ": the checkpoint was rendered with other settings: " +
                             describeSettingsDifference(ck.attribute(kAttrSettings), settingsKey) +
                             " (checkpoint vs this command; its bdptref:commandLine attribute has the original command)");
        const SampleRanges& held = ck.film.samples();
        if (!held.contiguous() || held.firstIndex() != range.begin)
            throw InputError("--resume " + a.resume + ": the checkpoint holds samples " + held.text() +
                             ", which is not a start of the samples to render, " + std::to_string(range.begin) + ":" +
                             (range.end == UINT64_MAX ? std::string("") : std::to_string(range.end)));
        if (held.endIndex() > range.end)
            throw InputError("--resume " + a.resume + ": the checkpoint already holds samples " + held.text() +
                             ", more than asked for (--spp/--sample-range)");
        try {
            previousSeconds = std::stod(ck.attribute("bdptref:renderSeconds"));
        } catch (const std::exception&) {
        }
        film = std::move(ck.film);
    }
    RenderOptions ro;
    ro.firstSample = film.samples().empty() ? range.begin : film.samples().endIndex();
    ro.spp = int(std::min<uint64_t>(range.end - ro.firstSample, uint64_t(INT_MAX)));
    ro.seed = uint32_t(a.seed);
    ro.threads = a.threads;
    ro.timeBudgetSeconds = a.timeBudget;
    if (a.mode != "megakernel" && a.mode != "wavefront")
        throw InputError("--mode: expected 'megakernel' or 'wavefront', got '" + a.mode + "'");
    if (a.mode != "wavefront" && (a.wavefrontPool != 0 || !a.gpuReport.empty()))
        throw InputError("--wavefront-pool and --gpu-report need --mode wavefront");
    if (a.wavefrontPool < 0) throw InputError("--wavefront-pool must be >= 0 (0 = automatic)");
    if (!a.gpuReport.empty()) checkWritable(a.gpuReport);
    std::unique_ptr<WavefrontScheduler> wavefront;
    if (a.mode == "wavefront") {
        WavefrontOptions wo;
        wo.poolSize = a.wavefrontPool;
        wavefront = std::make_unique<WavefrontScheduler>(a.integrator, is, wo);
        ro.scheduler = wavefront.get();
    }

    // Checkpoints are the output file itself, written atomically with the exact film state
    // (checkpoint.h), so the last one is always a complete, resumable image.
    const int threadsUsed = a.threads > 0 ? a.threads : int(std::max(1u, std::thread::hardware_concurrency()));
    auto metadata = [&](const std::string& status, double seconds) {
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
                  {"bdptref:status", status},
                  {"bdptref:varianceLayers", "variance.{R,G,B} = variance of the pixel mean (s^2/n); count = samples"}};
    md.ints = {{"bdptref:spp", int(std::min<uint64_t>(film.samples().total(), INT_MAX))},
               {"bdptref:sppRequested", int(std::min<uint64_t>(range.end - range.begin, INT_MAX))},
               {"bdptref:seed", int(uint32_t(a.seed))},
               {"bdptref:maxDepth", a.maxDepth},
               {"bdptref:width", scene.camera.width()},
               {"bdptref:height", scene.camera.height()},
               {"bdptref:threads", threadsUsed},
               {"bdptref:nonFiniteSamples", int(std::min<uint64_t>(film.nonFiniteSamples(), 0x7FFFFFFF))},
               {"bdptref:nonFiniteLayerValues", int(std::min<uint64_t>(film.strategies().nonFiniteValues(), 0x7FFFFFFF))}};
    md.floats = {{"bdptref:renderSeconds", float(previousSeconds + seconds)}, {"bdptref:loadSeconds", float(loadSeconds)},
                 {"bdptref:misBeta", float(a.misBeta)}};
    // The mode does not change a single bit of the image, so it is recorded but not a setting:
    // parts rendered in either mode can be merged or resumed.
    md.strings.push_back({"bdptref:mode", a.mode});
    md.strings.push_back({kAttrSettings, settingsKey});
    md.strings.push_back({"bdptref:commandLine", reproduceCommand(settings, film.samples(), a.output)});
    md.strings.push_back({"bdptref:invocation", invocation});
    md.strings.push_back({"bdptref:timeBudget", a.timeBudget > 0 ? exactNumber(a.timeBudget) : "none"});
    md.strings.push_back({"bdptref:resumedFrom", a.resume.empty() ? "none" : a.resume});
    md.strings.push_back({"bdptref:renderSecondsExact", exactNumber(previousSeconds + seconds)});
    const FilmErrorSummary err = summarizeError(film);
    md.strings.push_back({"bdptref:relativeStandardError",
                          "median " + exactNumber(err.medianRelativeStandardError) + ", p95 " +
                              exactNumber(err.p95RelativeStandardError) + ", image " + exactNumber(err.imageRelativeStandardError)});
    return md;
    };

    installStopHandlers();
    ProgressBar bar(!a.quiet);
    auto lastCheckpoint = std::chrono::steady_clock::now();
    const RayCounts raysBefore = rayCountsSoFar();
    const RenderStats stats = renderImage(scene, *integrator, ro, film, &stopRequested(), [&](const RenderProgress& p) {
        bar.update(p);
        const auto now = std::chrono::steady_clock::now();
        if (a.checkpointEvery > 0 && std::chrono::duration<double>(now - lastCheckpoint).count() >= a.checkpointEvery &&
            p.passesDone < p.passesTotal) {
            writeFilmExr(a.output, film, metadata("checkpoint", p.seconds), integrator->producesSplats());
            if (!preview.empty()) writePreviewPng(preview, film);
            lastCheckpoint = std::chrono::steady_clock::now();
        }
    });
    bar.finish();
    const RayCounts raysAfter = rayCountsSoFar();

    if (film.samples().empty()) {
        std::fprintf(stderr, "bdptref: interrupted before the first sample pass finished; nothing written\n");
        return 128 + (stopSignal() ? stopSignal() : SIGINT);
    }
    writeFilmExr(a.output, film, metadata(stats.cancelled ? "interrupted" : "complete", stats.seconds),
                 integrator->producesSplats());
    if (!preview.empty()) writePreviewPng(preview, film);
    if (wavefront && !a.gpuReport.empty()) {
        writeOutputText(a.gpuReport, gpuReportJson(wavefront->report()));
    }
    if (wavefront && !a.quiet) std::fputs(gpuReportSummary(wavefront->report()).c_str(), stderr);
    if (!a.statsPath.empty()) {
        // The figures the benchmark (bench/README.md) and the reference script read.
        const FilmErrorSummary err = summarizeError(film);
        const RayCounts rays{raysAfter.extension - raysBefore.extension, raysAfter.shadow - raysBefore.shadow};
        const double secs = stats.seconds > 0.0 ? stats.seconds : 1e-9;  // this run only (not a resumed part)
        const double samples = double(stats.passesDone) * double(film.pixelCount());
        nlohmann::ordered_json j;
        j["output"] = a.output;
        j["integrator"] = integrator->name();
        j["mis"] = a.integrator == "bdpt" ? a.mis : "none";
        j["mode"] = a.mode;
        j["width"] = film.width();
        j["height"] = film.height();
        j["samples"] = film.samples().text();
        j["spp"] = film.samples().total();
        j["threads"] = threadsUsed;
        j["triangles"] = scene.mesh.triangleCount();
        j["lights"] = scene.lights.size();
        j["renderSeconds"] = previousSeconds + stats.seconds;
        j["loadSeconds"] = loadSeconds;
        j["runSeconds"] = stats.seconds;
        j["runSamples"] = samples;
        j["samplesPerSecond"] = samples / secs;
        j["extensionRays"] = rays.extension;
        j["shadowRays"] = rays.shadow;
        j["raysPerSecond"] = double(rays.total()) / secs;
        j["extensionRaysPerSecond"] = double(rays.extension) / secs;
        j["shadowRaysPerSecond"] = double(rays.shadow) / secs;
        j["medianRelativeStandardError"] = err.medianRelativeStandardError;
        j["p95RelativeStandardError"] = err.p95RelativeStandardError;
        j["imageRelativeStandardError"] = err.imageRelativeStandardError;
        writeOutputText(a.statsPath, j.dump(2) + "\n");
    }
    const uint64_t nonFinite = film.nonFiniteSamples() + film.strategies().nonFiniteValues();
    if (nonFinite > 0)
        std::fprintf(stderr,
                     "bdptref: %s: %llu samples and %llu strategy-layer values were not finite (counted as zero; "
                     "bdptref:nonFiniteSamples and bdptref:nonFiniteLayerValues in the EXR header)\n",
                     a.strict ? "error" : "warning", static_cast<unsigned long long>(film.nonFiniteSamples()),
                     static_cast<unsigned long long>(film.strategies().nonFiniteValues()));
    if (!a.quiet)
        std::fprintf(stderr, "bdptref: wrote %s (%dx%d, %llu spp: samples %s, %s render)%s%s\n", a.output.c_str(), film.width(),
                     film.height(), static_cast<unsigned long long>(film.samples().total()), film.samples().text().c_str(),
                     formatSeconds(previousSeconds + stats.seconds).c_str(),
                     preview.empty() ? "" : " and ", preview.c_str());
    if (stats.cancelled) {
        std::fprintf(stderr, "bdptref: interrupted after samples %s; the image holds them and can be resumed (--resume)\n",
                     film.samples().text().c_str());
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
    cmd->add_option("--spp", args->spp, "samples per pixel (default 16): pixel samples 0..spp-1")
        ->each([args](const std::string&) { args->sppGiven = true; });
    cmd->add_option("--sample-range", args->sampleRange,
                    "A:B: render only pixel samples A..B-1 (instead of --spp), for 'bdptref merge' (docs/distributed.md)");
    cmd->add_option("--time", args->timeBudget,
                    "time budget in seconds: stop at the first sample pass that ends after it (alone: no spp limit; "
                    "with --spp/--sample-range: whichever comes first); the header records the real spp");
    cmd->add_option("--checkpoint-every", args->checkpointEvery,
                    "write the output EXR (a resumable checkpoint with the exact film state) every SECONDS while rendering");
    cmd->add_option("--stats", args->statsPath,
                    "also write render figures as JSON: samples, spp, seconds, samples/s, extension and shadow rays "
                    "and rays/s, relative standard errors");
    cmd->add_option("--resume", args->resume,
                    "continue the render in this EXR (a checkpoint, an interrupted or a finished render) up to --spp, "
                    "--sample-range's end or --time; give the same scene and settings as the run that wrote it");
    cmd->add_option("--mode", args->mode,
                    "megakernel (default: one function per pixel sample) or wavefront (GPU-style stages over queues; "
                    "the same image bit for bit, docs/wavefront.md)");
    cmd->add_option("--wavefront-pool", args->wavefrontPool,
                    "wavefront: paths in flight per pool pass (default 0 = as many as fit in 512 KiB of path buffers, at least 256)");
    cmd->add_option("--gpu-report", args->gpuReport,
                    "wavefront: write queue, ray, connection, SIMT and memory figures to this JSON file "
                    "(a summary goes to stderr)");
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
        "Every EXR written (final, interrupted, checkpoint) holds the exact film state and can be resumed with\n"
        "--resume or combined with 'bdptref merge' (docs/ground-truth.md).\n"
        "Exit codes: 0 done, 1 internal error, 2 bad input, 3 non-finite samples with --strict, 130/143 interrupted.");
    return [args] { return run(*args); };
}

}  // namespace bdptref::cli
