#include "bdptref/checkpoint.h"
#include "bdptref/errors.h"
#include "bdptref/film_merge.h"
#include "bdptref/exr_io.h"
#include "bdptref/renderer.h"
#include "bdptref/version.h"
#include "bdptref/wavefront.h"
#include "cli/commands.h"
#include "cli/progress.h"
#include "film/exr_encode.h"
#include "cli/render_args.h"
#include "cli/render_memory.h"
#include "cli/render_record.h"
#include "cli/render_resume.h"
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

std::string ignoredFeatureList(const SceneInfo& info) {
    std::string s;
    for (const std::string& f : info.ignoredFeatures) s += (s.empty() ? "" : ", ") + f;
    return s;
}

// This process's command line (Linux /proc), for the bdptref:invocation attribute.
std::string invocationText() {
    std::ifstream f("/proc/self/cmdline", std::ios::binary);
    std::string arg, text;
    while (std::getline(f, arg, '\0')) text += (text.empty() ? "" : " ") + shellQuote(arg);
    return text;
}

// Exit code of `render --strict` when a sample or layer value was not finite (the EXR is still
// written, with the counts in its header, so the evidence is kept).
constexpr int kExitNonFinite = 3;

// The PNG preview beside the EXR: OUT.png. None when the output is a device node or FIFO
// (`-o /dev/null`): a preview named after it would be a new file in /dev.
std::string defaultPreviewPath(const std::string& output) {
    std::error_code ec;
    const auto st = std::filesystem::status(output, ec);
    if (!ec && std::filesystem::exists(st) && !std::filesystem::is_regular_file(st)) return "";
    std::filesystem::path p(output);
    p.replace_extension(".png");
    return p.string();
}

// --- validateRenderArgs: every check of an option that needs no file ---------------------------

// Options that do not decide the pixels (checked before the resume file or the scene is read).
void validateRunOptions(const RenderArgs& a) {
    if (a.scene.scenePath.empty() && a.resume.empty())
        throw InputError("no scene given (the first argument; with --resume the checkpoint's header names it)");
    if (a.spp < 1) throw InputError("--spp must be at least 1");
    if (a.sppGiven && !a.sampleRange.empty()) throw InputError("--spp and --sample-range: give one of them, not both");
    if (!a.sampleRange.empty()) parseSampleRange(a.sampleRange, "--sample-range");
    // 0 is refused like a negative value: "--time 0" would otherwise silently mean "no budget".
    if (a.has("--time") && !(a.timeBudget > 0 && std::isfinite(a.timeBudget)))
        throw InputError("--time must be a positive number of seconds (got " + exactNumber(a.timeBudget) + ")");
    if (a.has("--checkpoint-every") && !(a.checkpointEvery > 0 && std::isfinite(a.checkpointEvery)))
        throw InputError("--checkpoint-every must be a positive number of seconds (got " + exactNumber(a.checkpointEvery) + ")");
    if (a.threads < 0) throw InputError("--threads must be >= 0 (0 = all cores)");
    if (a.mode != "megakernel" && a.mode != "wavefront")
        throw InputError("--mode: expected 'megakernel' or 'wavefront', got '" + a.mode + "'");
    if (a.wavefrontPool < 0) throw InputError("--wavefront-pool must be >= 0 (0 = automatic)");
}

// The deepest --max-depth --depth-layers accepts: 257 layers of 6 float and 12 UINT channels each.
constexpr int kMaxDepthLayersDepth = 256;

// Settings that decide the pixels (after --resume filled them from the header). Makes --crop
// canonical ("x0,y0,x1,y1"), as the header records it.
void validateSettings(RenderArgs& a) {
    if (a.maxDepth < 0 || a.maxDepth > 100000) throw InputError("--max-depth must be between 0 and 100000");
    if (a.seed < 0 || a.seed > 0xFFFFFFFFLL) throw InputError("--seed must be between 0 and 4294967295");
    if (a.integrator == "pt") a.integrator = "path";  // the names makeIntegrator also accepts
    if (a.integrator == "light") a.integrator = "lt";
    if (a.integrator != "path" && a.integrator != "lt" && a.integrator != "bdpt")
        throw InputError("--integrator: expected path, lt or bdpt, got '" + a.integrator + "'");
    parseMisHeuristic(a.mis);
    parseLightSamplerKind(a.lightSampler, "--light-sampler");
    if (a.lightSampler == "tree" && a.integrator == "lt")
        throw InputError("--light-sampler tree needs --integrator path or bdpt: light tracing has no shading point to "
                         "choose a light at, its subpaths start on a light chosen by power (docs/lights.md, \"Light tree\")");
    if (!(a.misBeta > 0.0 && a.misBeta <= 16.0)) throw InputError("--mis-beta must be in (0, 16]");
    if (a.exrCompression != "zip" && a.exrCompression != "none")
        throw InputError("--exr-compression: expected zip or none, got '" + a.exrCompression + "'");
    if (a.strategies && a.maxDepth > 32)
        throw InputError("--strategies writes 12 layers per (s,t) strategy: use --max-depth 32 or less with it");
    if (a.depthLayers && a.maxDepth > kMaxDepthLayersDepth)
        throw InputError("--depth-layers writes 6 channels per path depth 0..max-depth: use --max-depth " +
                         std::to_string(kMaxDepthLayersDepth) + " or less with it (got " + std::to_string(a.maxDepth) + ")");
    if (a.mode != "wavefront" && (a.wavefrontPool != 0 || !a.gpuReport.empty()))
        throw InputError("--wavefront-pool and --gpu-report need --mode wavefront");
    if (!a.crop.empty()) {
        // The bounds against a size not given (from the camera's aspect) are checked after loading.
        const int w = a.scene.width > 0 ? a.scene.width : 65536, h = a.scene.height > 0 ? a.scene.height : 65536;
        long long x0, y0, x1, y1;
        char c1, c2, c3;
        std::stringstream ss(a.crop);
        std::string rest;
        if (!(ss >> x0 >> c1 >> y0 >> c2 >> x1 >> c3 >> y1) || c1 != ',' || c2 != ',' || c3 != ',' || (ss >> rest) ||
            x0 < 0 || y0 < 0 || x1 > w || y1 > h || x0 >= x1 || y0 >= y1)
            throw InputError("--crop: expected x0,y0,x1,y1 with 0 <= x0 < x1 <= width and 0 <= y0 < y1 <= height, got '" +
                             a.crop + "'");
        a.crop = std::to_string(x0) + "," + std::to_string(y0) + "," + std::to_string(x1) + "," + std::to_string(y1);
    }
}

// The samples to render: --sample-range A:B, else [0, --spp); with only --time, no upper end; on
// --resume without --spp/--sample-range, the samples the checkpoint's run asked for.
SampleRange samplesToRender(const RenderArgs& a) {
    SampleRange range{0, uint64_t(a.spp)};
    if (!a.sampleRange.empty()) return parseSampleRange(a.sampleRange, "--sample-range");
    if (!a.requestedFromHeader.empty() && !a.sppGiven) {
        const std::string& r = a.requestedFromHeader;
        if (!r.empty() && r.back() == ':') {  // the run had --time alone
            if (!(a.timeBudget > 0))
                throw InputError("--resume " + a.resume + ": the checkpoint's run had no sample limit (--time alone): give "
                                 "--spp N or --time SECONDS");
            range = parseSampleRange(r + "18446744073709551615", std::string("the header's ") + kAttrSamplesRequested);
            range.end = UINT64_MAX;
            return range;
        }
        return parseSampleRange(r, std::string("--resume ") + a.resume + ": the header's " + kAttrSamplesRequested);
    }
    if (a.timeBudget > 0 && !a.sppGiven) range.end = UINT64_MAX;
    return range;
}

std::string rangeText(const SampleRange& r) {
    return std::to_string(r.begin) + ":" + (r.end == UINT64_MAX ? std::string("") : std::to_string(r.end));
}

// --- prepareRender: scene, integrator, film, resumed state -------------------------------------

struct Prepared {
    Scene scene;
    double loadSeconds = 0;
    IntegratorSettings integratorSettings;
    std::unique_ptr<Integrator> integrator;
    ImageSettings settings;
    std::string settingsKey;
    SampleRange range;
    Film film;
    double previousSeconds = 0;  // render time already in a resumed checkpoint
    std::unique_ptr<WavefrontScheduler> wavefront;
};

Prepared prepareRender(const RenderArgs& a, FilmFile* checkpoint) {
    Prepared p;
    p.range = samplesToRender(a);
    const auto loadStart = std::chrono::steady_clock::now();
    p.scene = loadScene(a.scene);
    for (const std::string& w : p.scene.info.warnings) std::fprintf(stderr, "bdptref: warning: %s\n", w.c_str());
    if (a.strictScene && !p.scene.info.ignoredFeatures.empty())
        throw InputError(a.scene.scenePath + ": --strict-scene: the file uses " + ignoredFeatureList(p.scene.info) +
                         ", which this renderer does not implement (without --strict-scene they are left out with a warning "
                         "and listed in the EXR header's bdptref:ignoredFeatures)");
    p.loadSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - loadStart).count();

    IntegratorSettings& is = p.integratorSettings;
    is.maxDepth = a.maxDepth;
    is.mis.heuristic = parseMisHeuristic(a.mis);
    is.mis.beta = a.misBeta;
    is.recordStrategies = a.strategies;
    is.recordDepths = a.depthLayers;
    is.lightSampler = parseLightSamplerKind(a.lightSampler, "--light-sampler");
    FilmWindow window = FilmWindow::full(p.scene.camera.width(), p.scene.camera.height());
    if (!a.crop.empty()) {
        int x0, y0, x1, y1;
        std::sscanf(a.crop.c_str(), "%d,%d,%d,%d", &x0, &y0, &x1, &y1);  // canonical (validateSettings)
        if (x1 > window.fullWidth || y1 > window.fullHeight)
            throw InputError("--crop " + a.crop + ": the image is " + std::to_string(window.fullWidth) + "x" +
                             std::to_string(window.fullHeight) + " (from the camera's aspect ratio)");
        p.scene.camera = p.scene.camera.withCrop(x0, y0, x1, y1);
        window = FilmWindow{window.fullWidth, window.fullHeight, x0, y0, x1 - x0, y1 - y0};
    }
    p.integrator = makeIntegrator(a.integrator, is);
    p.settings = settingsFromArgs(a);
    p.settings.width = p.scene.camera.width();  // as resolved: a side not given follows the camera
    p.settings.height = p.scene.camera.height();
    p.settings.sceneHash = p.scene.info.contentHash;
    p.settingsKey = settingsText(p.settings);

    // The film holds the crop window only; refuse up front what cannot fit in memory.
    const MemoryEstimate need = estimateRenderMemory(double(window.width) * double(window.height),
                                                     a.strategies ? a.maxDepth : -1, a.depthLayers ? a.maxDepth : -1,
                                                     p.integrator->producesSplats(), checkpoint != nullptr);
    checkRenderFits(need, "--width " + std::to_string(window.fullWidth) + " --height " + std::to_string(window.fullHeight) +
                              (a.crop.empty() ? "" : " --crop " + a.crop) + (a.strategies ? " --strategies" : "") +
                              (a.depthLayers ? " --depth-layers" : "") +
                              (a.strategies || a.depthLayers ? " --max-depth " + std::to_string(a.maxDepth) : ""));
    if (checkpoint) {
        FilmFile& ck = *checkpoint;
        if (ck.attribute(kAttrSettings) != p.settingsKey)
            throw InputError("--resume " + a.resume + ": the checkpoint was rendered with other settings: " +
                             describeSettingsDifference(ck.attribute(kAttrSettings), p.settingsKey) +
                             " (checkpoint vs this command; its bdptref:commandLine attribute has the original command)");
        if (ck.film.window() != window)
            throw InputError("--resume " + a.resume + ": the checkpoint holds pixels " + ck.film.window().text() +
                             ", this render " + window.text());
        const SampleRanges& held = ck.film.samples();
        if (!held.contiguous() || held.firstIndex() != p.range.begin)
            throw InputError("--resume " + a.resume + ": the checkpoint holds samples " + held.text() +
                             ", which is not a start of the samples to render, " + rangeText(p.range));
        if (held.endIndex() > p.range.end)
            throw InputError("--resume " + a.resume + ": the checkpoint already holds samples " + held.text() +
                             ", more than asked for (--spp/--sample-range)");
        try {
            p.previousSeconds = std::stod(ck.attribute("bdptref:renderSeconds"));
        } catch (const std::exception&) {
        }
        p.film = std::move(ck.film);
    } else {
        p.film = Film(window);
        if (a.strategies) p.film.enableStrategies(a.maxDepth);
        if (a.depthLayers) p.film.enableDepthLayers(a.maxDepth);
    }
    if (a.mode == "wavefront") {
        WavefrontOptions wo;
        wo.poolSize = a.wavefrontPool;
        p.wavefront = std::make_unique<WavefrontScheduler>(a.integrator, is, wo);
    }
    return p;
}

// --- renderMetadata: the EXR header ------------------------------------------------------------

ExrMetadata renderMetadata(const RenderArgs& a, const Prepared& p, const std::string& invocation, int threadsUsed,
                           const std::string& status, double seconds) {
    const Film& film = p.film;
    const Scene& scene = p.scene;
    ExrMetadata md;
    md.strings = {{"bdptref:integrator", p.integrator->name()},
                  {"bdptref:scene", scene.info.path},
                  {"bdptref:sceneHash", scene.info.contentHash},
                  {"bdptref:camera", scene.info.cameraSource},
                  {"bdptref:ignoredFeatures", scene.info.ignoredFeatures.empty() ? "none" : ignoredFeatureList(scene.info)},
                  {"bdptref:environment", !a.scene.envMap.empty() ? "map " + a.scene.envMap : a.scene.env.empty() ? "none" : a.scene.env},
                  {"bdptref:mis", a.integrator == "bdpt" ? a.mis : "none"},
                  {"bdptref:crop", a.crop.empty() ? "none" : a.crop},
                  {"bdptref:version", BDPTREF_VERSION},
                  {"bdptref:gitRevision", BDPTREF_GIT_REVISION},
                  {"bdptref:status", status},
                  {"bdptref:varianceLayers", "variance.{R,G,B} = variance of the pixel mean (s^2/n); count = samples"}};
    md.ints = {{"bdptref:spp", int(std::min<uint64_t>(film.samples().total(), INT_MAX))},
               {"bdptref:sppRequested", int(std::min<uint64_t>(p.range.end - p.range.begin, INT_MAX))},
               {"bdptref:seed", int(uint32_t(a.seed))},
               {"bdptref:maxDepth", a.maxDepth},
               {"bdptref:width", scene.camera.width()},
               {"bdptref:height", scene.camera.height()},
               {"bdptref:threads", threadsUsed},
               {"bdptref:nonFiniteSamples", int(std::min<uint64_t>(film.nonFiniteSamples(), 0x7FFFFFFF))},
               {"bdptref:nonFiniteLayerValues", int(std::min<uint64_t>(film.nonFiniteLayerValues(), 0x7FFFFFFF))}};
    md.floats = {{"bdptref:renderSeconds", float(p.previousSeconds + seconds)},
                 {"bdptref:loadSeconds", float(p.loadSeconds)},
                 {"bdptref:misBeta", float(a.misBeta)}};
    // The mode does not change a single bit of the image, so it is recorded but not a setting:
    // parts rendered in either mode can be merged or resumed.
    md.strings.push_back({"bdptref:mode", a.mode});
    md.strings.push_back({kAttrSettings, p.settingsKey});
    md.strings.push_back({kAttrSamplesRequested, rangeText(p.range)});
    md.strings.push_back({"bdptref:commandLine", reproduceCommand(p.settings, film.samples(), a.output)});
    md.strings.push_back({"bdptref:invocation", invocation});
    md.strings.push_back({"bdptref:timeBudget", a.timeBudget > 0 ? exactNumber(a.timeBudget) : "none"});
    md.strings.push_back({"bdptref:resumedFrom", a.resume.empty() ? "none" : a.resume});
    md.strings.push_back({"bdptref:renderSecondsExact", exactNumber(p.previousSeconds + seconds)});
    const FilmErrorSummary err = summarizeError(film);
    md.strings.push_back({"bdptref:relativeStandardError",
                          "median " + exactNumber(err.medianRelativeStandardError) + ", p95 " +
                              exactNumber(err.p95RelativeStandardError) + ", image " + exactNumber(err.imageRelativeStandardError)});
    return md;
}

// --- renderWithCheckpoints ---------------------------------------------------------------------

struct RenderRun {
    RenderStats stats;
    RayCounts rays;
    int threadsUsed = 1;
    std::string invocation;
};

// Checkpoints are the output file itself, written atomically with the exact film state
// (checkpoint.h), so the last one is always a complete, resumable image.
RenderRun renderWithCheckpoints(const RenderArgs& a, Prepared& p, const std::string& preview) {
    RenderRun run;
    run.threadsUsed = a.threads > 0 ? a.threads : int(std::max(1u, std::thread::hardware_concurrency()));
    run.invocation = invocationText();
    RenderOptions ro;
    ro.firstSample = p.film.samples().empty() ? p.range.begin : p.film.samples().endIndex();
    ro.spp = int(std::min<uint64_t>(p.range.end - ro.firstSample, uint64_t(INT_MAX)));
    ro.seed = uint32_t(a.seed);
    ro.threads = a.threads;
    ro.timeBudgetSeconds = a.timeBudget;
    ro.scheduler = p.wavefront.get();

    installStopHandlers();
    ProgressBar bar(!a.quiet);
    auto lastCheckpoint = std::chrono::steady_clock::now();
    const RayCounts raysBefore = rayCountsSoFar();
    run.stats = renderImage(p.scene, *p.integrator, ro, p.film, &stopRequested(), [&](const RenderProgress& pr) {
        bar.update(pr);
        const auto now = std::chrono::steady_clock::now();
        if (a.checkpointEvery > 0 && std::chrono::duration<double>(now - lastCheckpoint).count() >= a.checkpointEvery &&
            pr.passesDone < pr.passesTotal) {
            writeFilmExr(a.output, p.film, renderMetadata(a, p, run.invocation, run.threadsUsed, "checkpoint", pr.seconds),
                         p.integrator->producesSplats(), a.exrCompression == "zip");
            if (!preview.empty()) writePreviewPng(preview, p.film);
            lastCheckpoint = std::chrono::steady_clock::now();
        }
    });
    bar.finish();
    const RayCounts raysAfter = rayCountsSoFar();
    run.rays = RayCounts{raysAfter.extension - raysBefore.extension, raysAfter.shadow - raysBefore.shadow};
    return run;
}

// --- writeOutputs: EXR, PNG, GPU report, stats -------------------------------------------------

void writeOutputs(const RenderArgs& a, const Prepared& p, const RenderRun& run, const std::string& preview) {
    const Film& film = p.film;
    const RenderStats& stats = run.stats;
    writeFilmExr(a.output, film,
                 renderMetadata(a, p, run.invocation, run.threadsUsed, stats.cancelled ? "interrupted" : "complete",
                                stats.seconds),
                 p.integrator->producesSplats(), a.exrCompression == "zip");
    if (!preview.empty()) writePreviewPng(preview, film);
    if (p.wavefront && !a.gpuReport.empty()) {
        writeOutputText(a.gpuReport, gpuReportJson(p.wavefront->report()));
    }
    if (p.wavefront && !a.quiet) std::fputs(gpuReportSummary(p.wavefront->report()).c_str(), stderr);
    if (!a.statsPath.empty()) {
        // The figures the benchmark (bench/README.md) and the reference script read.
        const FilmErrorSummary err = summarizeError(film);
        const RayCounts& rays = run.rays;
        const double secs = stats.seconds > 0.0 ? stats.seconds : 1e-9;  // this run only (not a resumed part)
        const double samples = double(stats.passesDone) * double(film.pixelCount());
        nlohmann::ordered_json j;
        j["output"] = a.output;
        j["integrator"] = p.integrator->name();
        j["mis"] = a.integrator == "bdpt" ? a.mis : "none";
        j["mode"] = a.mode;
        j["width"] = film.width();
        j["height"] = film.height();
        j["samples"] = film.samples().text();
        j["spp"] = film.samples().total();
        j["threads"] = run.threadsUsed;
        j["triangles"] = p.scene.mesh.triangleCount();
        j["lights"] = p.scene.lights.size();
        j["renderSeconds"] = p.previousSeconds + stats.seconds;
        j["loadSeconds"] = p.loadSeconds;
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
}

int run(RenderArgs& a) {
    validateRunOptions(a);
    FilmFile checkpoint;
    if (!a.resume.empty()) {
        checkpoint = readFilmExr(a.resume);
        applyResumeHeader(checkpoint, a);
    }
    validateSettings(a);
    const std::string preview = a.noPreview ? "" : (a.preview.empty() ? defaultPreviewPath(a.output) : a.preview);
    checkOutputs({{"-o", a.output, ".exr"}, {"--preview", preview, ".png"}, {"--stats", a.statsPath, ""},
                  {"--gpu-report", a.gpuReport, ""}});

    Prepared p = prepareRender(a, a.resume.empty() ? nullptr : &checkpoint);
    const RenderRun run = renderWithCheckpoints(a, p, preview);
    const Film& film = p.film;
    const RenderStats& stats = run.stats;
    if (film.samples().empty()) {
        std::fprintf(stderr, "bdptref: interrupted before the first sample pass finished; nothing written\n");
        return 128 + (stopSignal() ? stopSignal() : SIGINT);
    }
    writeOutputs(a, p, run, preview);
    const uint64_t nonFinite = film.nonFiniteSamples() + film.nonFiniteLayerValues();
    if (nonFinite > 0)
        std::fprintf(stderr,
                     "bdptref: %s: %llu samples and %llu strategy- or depth-layer values were not finite (counted as zero; "
                     "bdptref:nonFiniteSamples and bdptref:nonFiniteLayerValues in the EXR header)\n",
                     a.strict ? "error" : "warning", static_cast<unsigned long long>(film.nonFiniteSamples()),
                     static_cast<unsigned long long>(film.nonFiniteLayerValues()));
    if (!a.quiet)
        std::fprintf(stderr, "bdptref: wrote %s (%dx%d, %llu spp: samples %s, %s render)%s%s\n", a.output.c_str(), film.width(),
                     film.height(), static_cast<unsigned long long>(film.samples().total()), film.samples().text().c_str(),
                     formatSeconds(p.previousSeconds + stats.seconds).c_str(), preview.empty() ? "" : " and ",
                     preview.c_str());
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
                    "continue the render in this EXR (a checkpoint, an interrupted or a finished render) with the scene and "
                    "settings of its header, up to the samples that run asked for, or --spp / --sample-range's end / "
                    "--time; other options may repeat the header's values but not change them (docs/ground-truth.md)");
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
    cmd->add_option("--light-sampler", args->lightSampler,
                    "how next-event estimation picks a light: power (default; in proportion to power) or tree (a light\n"
                    "BVH weighing each light by its importance at the shading point: less noise per sample with many\n"
                    "lights, more time per sample; --integrator path, and bdpt (its s = 1 strategy, with exact MIS\n"
                    "densities); lt refuses it; docs/lights.md, 'Light tree', docs/mis.md, 'Light tree in BDPT',\n"
                    "bench/README.md, 'Many lights')");
    cmd->add_option("--mis", args->mis, "BDPT MIS heuristic: balance (default), power, uniform");
    cmd->add_option("--mis-beta", args->misBeta, "exponent of the power heuristic (default 2)");
    cmd->add_flag("--strategies", args->strategies,
                  "write per-(s,t) layers s<S>t<T>.{weighted,unweighted}[.variance].{R,G,B}: every strategy of bdpt, t = 1 "
                  "of lt, and of path s = 0 (emission found by BSDF sampling) and s = 1 (next-event estimation)");
    cmd->add_option("--exr-compression", args->exrCompression,
                    "zip (default) or none: an uncompressed EXR is larger and written faster, for files a program reads\n"
                    "once (validate's renders with --strategies, whose ZIP took half the time of a 5-spp 64x64 render)");
    cmd->add_flag("--depth-layers", args->depthLayers,
                  "write per-depth layers depth<D>.{R,G,B} and depth<D>.variance.{R,G,B} for D = 0..max-depth (every\n"
                  "integrator and mode): what paths of D scattering bounces add (an emitter seen directly: 0; BDPT\n"
                  "strategy (s,t): s+t-2); they sum to R,G,B. Compare one with 'compare --layer depth<D>'\n"
                  "(docs/compare.md, 'Localising a bug by path depth'); --max-depth 256 or less");
    cmd->add_option("--crop", args->crop,
                    "render only pixels x0,y0,x1,y1 (x1, y1 exclusive) of the full image; same expected values there");
    cmd->add_flag("--strict-scene", args->strictScene,
                  "refuse (exit 2) a scene that uses a picture-changing feature this renderer does not implement; "
                  "without it such features are left out with a warning and listed in bdptref:ignoredFeatures");
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
    // --resume takes every setting not given from the checkpoint's header, so the scene is optional.
    cmd->get_option("scene")->required(false);
    return [args, cmd] {
        for (const CLI::Option* o : cmd->get_options())
            if (o->count() > 0) args->given.insert(o->get_name());
        return run(*args);
    };
}

}  // namespace bdptref::cli
