// `bdptref validate --renderer 'CMD {scene} {out} {spp} {seed} ...' --estimator path`: the
// conformance runner (docs/validate.md). Exit codes: 0 every scene consistent, 1 a scene
// inconsistent, 2 no verdict (a renderer failure, too few samples, bad input), 130/143 interrupted.
#include "bdptref/errors.h"
#include "cli/commands.h"
#include "cli/signals.h"
#include "core/output_file.h"
#include "verify/validate.h"

#include <cstdio>
#include <filesystem>
#include <memory>
#include <sstream>
#include <unistd.h>

namespace bdptref::cli {

namespace {

struct ValidateArgs {
    std::string renderer, self, estimator, suite, scenes, out = "validate-report";
    double budget = 60, alpha = 0.01, timeout = 3600;
    int renders = 8, spp = 0;
    uint32_t seedBase = 1;
    bool json = false, quiet = false, dropRenders = false, strategyLayers = false;
    CLI::Option* rendersOption = nullptr;  // given: exactly that many renders per scene
};

std::string selfExecutable() {
    std::error_code ec;
    const auto p = std::filesystem::read_symlink("/proc/self/exe", ec);
    return ec ? std::string("bdptref") : p.string();
}

// bdptref itself as "the port": render with INTEGRATOR (path, lt, bdpt, bdpt-power, wavefront).
std::string selfCommand(const std::string& integrator, PortEstimator* estimator) {
    std::string flags;
    if (integrator == "path") flags = "--integrator path", *estimator = PortEstimator::Path;
    else if (integrator == "lt") flags = "--integrator lt", *estimator = PortEstimator::Light;
    else if (integrator == "bdpt") flags = "--integrator bdpt --mis balance", *estimator = PortEstimator::Bidirectional;
    else if (integrator == "bdpt-power") flags = "--integrator bdpt --mis power", *estimator = PortEstimator::Bidirectional;
    else if (integrator == "wavefront")
        flags = "--integrator bdpt --mode wavefront", *estimator = PortEstimator::Bidirectional;
    else
        throw InputError("--self " + integrator + ": use path, lt, bdpt, bdpt-power or wavefront");
    std::string exe = selfExecutable(), q = "'";
    for (char c : exe) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "' render {scene} -o {out} --spp {spp} --seed {seed} --width {width} --height {height} {options} " +
           flags + " --depth-layers --threads 1 --no-preview -q";
}

std::vector<std::string> splitComma(const std::string& s) {
    std::vector<std::string> out;
    std::stringstream ss(s);
    for (std::string item; std::getline(ss, item, ',');)
        if (!item.empty()) out.push_back(item);
    return out;
}

int run(const ValidateArgs& a) {
    ValidateOptions o;
    if (a.renderer.empty() == a.self.empty())
        throw InputError("give the renderer to validate: --renderer 'COMMAND {scene} {out} {spp} {seed} ...' (see "
                         "--help), or --self INTEGRATOR to validate bdptref itself");
    if (!a.self.empty()) {
        o.command = selfCommand(a.self, &o.estimator);
        if (a.strategyLayers) {
            if (o.estimator == PortEstimator::Light)
                throw InputError("--strategy-layers: a light tracer has one strategy, its beauty (use --self path, bdpt, "
                                 "bdpt-power or wavefront)");
            o.command += " --strategies --exr-compression none";  // ZIP would take half a short render's time
        }
        if (!a.estimator.empty() && parsePortEstimator(a.estimator) != o.estimator)
            throw InputError("--estimator " + a.estimator + " contradicts --self " + a.self);
    } else if (a.strategyLayers) {
        throw InputError("--strategy-layers is for --self; a port of your own writes its s<S>t<T>.unweighted layers through its "
                         "own command (docs/validate.md, 'Strategy classes')");
    } else {
        if (a.estimator.empty())
            throw InputError("--estimator is required with --renderer: say what your renderer samples (path: a path "
                             "tracer with next-event estimation; light: light tracing; bidirectional: BDPT/VCM), so that "
                             "scenes it cannot render without missing paths are skipped, not failed");
        o.command = a.renderer;
        o.estimator = parsePortEstimator(a.estimator);
    }
    checkCommandTemplate(o.command);
    o.budgetSeconds = a.budget;
    o.renders = a.renders;
    o.adaptRenders = !(a.rendersOption && a.rendersOption->count() > 0);
    o.spp = a.spp;
    o.alpha = a.alpha;
    o.seedBase = a.seedBase;
    o.timeoutSeconds = a.timeout;
    o.only = splitComma(a.scenes);
    o.outDir = a.out;
    o.keepRenders = !a.dropRenders;
    if (a.spp < 0) throw InputError("--spp must be >= 1 (or 0: sized to --budget)");
    const Suite suite = loadSuite(a.suite.empty() ? defaultSuitePath(selfExecutable()) : a.suite);

    installStopHandlers();
    const ValidateReport r = runValidation(
        suite, o,
        [&](const std::string& line) {
            if (!a.quiet) std::fprintf(stderr, "validate %s\n", line.c_str());
        },
        [] { return stopRequested().load(); });
    const std::string dir = a.out;
    writeOutputText(dir + "/report.json", validateReportJson(r));
    writeOutputText(dir + "/report.html", validateReportHtml(r));
    if (a.json) std::printf("%s", validateReportJson(r).c_str());
    else std::printf("%s", validateSummaryText(r).c_str());
    if (!a.quiet) std::fprintf(stderr, "validate: report in %s/report.html (and report.json)\n", dir.c_str());
    std::fflush(stdout);
    if (r.interrupted) return 128 + (stopSignal() ? stopSignal() : 2);
    return r.exitCode;
}

}  // namespace

std::function<int()> addValidateCommand(CLI::App& app) {
    auto a = std::make_shared<ValidateArgs>();
    CLI::App* cmd = app.add_subcommand(
        "validate",
        "run a renderer on the conformance suite and compare every result with the suite's reference: is the port "
        "right, and if not, in which scene and at which path depth? (docs/validate.md)");
    cmd->add_option("--renderer", a->renderer,
                    "the renderer's command, run by /bin/sh once per render, with placeholders {scene} (glTF), {out} "
                    "(EXR or PFM to write, linear float R,G,B; depth<d>.R/G/B layers optional), {spp}, {seed}, {width}, "
                    "{height}, {max_depth} (scattering events), {env_map}/{env_scale} (equirectangular HDR and its "
                    "scale, both empty if none), {env} (constant 'r,g,b', empty if none) and {options} (bdptref's "
                    "render options for the scene); {scene} {out} {spp} {seed} are required. {name:text} is text with "
                    "% replaced by the value, or nothing when the value is empty: {env_map:--envmap %}. With {seeds} "
                    "instead of {seed} one process per scene gets every seed (comma-separated) and writes {out} with "
                    "{seed} replaced by each (docs/validate.md)");
    cmd->add_option("--self", a->self,
                    "validate bdptref itself: path, lt, bdpt, bdpt-power or wavefront (instead of --renderer)");
    cmd->add_flag("--strategy-layers", a->strategyLayers,
                  "with --self path or bdpt: also write the unweighted strategy layers (a path tracer's emitter hits and "
                  "next events, every class of BDPT), which validate compares per class of strategy with the reference's "
                  "depth layers (more time per sample; docs/validate.md, 'Strategy classes')");
    cmd->add_option("--estimator", a->estimator,
                    "what the renderer samples: path, light or bidirectional (required with --renderer); scenes it "
                    "cannot render without missing paths are skipped");
    cmd->add_option("--budget", a->budget,
                    "seconds of the renderer's wall time for the whole suite (default 60): pilot renders measure what "
                    "each scene costs, and each scene's share follows what its verdict needs (its reference's noise), "
                    "split over --renders renders");
    cmd->add_option("--spp", a->spp, "samples per pixel of every render instead of a budget");
    a->rendersOption = cmd->add_option(
        "--renders", a->renders,
        "independent renders per scene, seeds seed-base.. (default 8, or down to 4 where the renderer's fixed cost per "
        "process would take more than half of an equal share of the budget; given: exactly N, at least 2; fewer give a less "
        "reliable spread: docs/validate.md)");
    cmd->add_option("--seed-base", a->seedBase, "seed of the first render of each scene; render k uses it + 1000 k (default 1)");
    cmd->add_option("--scenes", a->scenes, "only these scenes, comma-separated (default: all)");
    cmd->add_option("--alpha", a->alpha, "false-alarm rate of the whole suite (default 0.01; Sidak over the scenes)");
    cmd->add_option("--suite", a->suite, "suite file (default: the shipped scenes/conformance/suite.json)");
    cmd->add_option("-o,--out", a->out, "folder for renders, logs, heatmaps, report.html and report.json (default validate-report)");
    cmd->add_option("--timeout", a->timeout, "seconds one render may take with --spp (default 3600)");
    cmd->add_flag("--drop-renders", a->dropRenders, "delete each scene's renders once compared, and its pilot renders once timed");
    cmd->add_flag("--json", a->json, "print the report as JSON on stdout instead of the summary");
    cmd->add_flag("-q,--quiet", a->quiet, "no progress on stderr");
    return [a] { return run(*a); };
}

}  // namespace bdptref::cli
