// Running the suite: with a budget, first the pilot renders of every scene (what a sample and a
// process cost, and from the reference how many samples a verdict needs), then the budget's shares
// (validate_budget.cpp), then per scene N independent renders (N processes, or one with {seeds})
// and the beauty and every depth layer
// both sides have compared with the reference (docs/validate.md, "Budget and samples", "What a
// verdict means").
#include "verify/validate.h"

#include "bdptref/errors.h"
#include "core/output_file.h"
#include "film/png_write.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace fs = std::filesystem;

namespace bdptref {

const char* sceneVerdictName(SceneVerdict v) {
    switch (v) {
        case SceneVerdict::Consistent: return "consistent";
        case SceneVerdict::Inconsistent: return "INCONSISTENT";
        case SceneVerdict::NoVerdict: return "no verdict";
        case SceneVerdict::Failed: return "renderer failed";
        case SceneVerdict::Skipped: return "skipped";
    }
    return "?";
}

namespace {

// The depth layers ("depth<d>.R") an image holds, in increasing d.
std::vector<int> depthLayers(const ExrImage& img) {
    std::vector<int> d;
    for (const auto& kv : img.channels) {
        const std::string& n = kv.first;
        if (n.rfind("depth", 0) != 0 || n.size() < 8 || n.compare(n.size() - 2, 2, ".R") != 0) continue;
        const std::string digits = n.substr(5, n.size() - 7);
        if (digits.empty() || digits.find_first_not_of("0123456789") != std::string::npos || digits.size() > 4) continue;
        d.push_back(std::stoi(digits));
    }
    std::sort(d.begin(), d.end());
    return d;
}

}  // namespace

double sidakLevel(double alpha, int k) { return k <= 1 ? alpha : -std::expm1(std::log1p(-alpha) / double(k)); }

LayerOutcome layerOutcome(const CompareResult& r, const std::string& layer, int depth) {
    LayerOutcome o;
    o.layer = layer;
    o.depth = depth;
    o.p = r.pGlobal;
    o.hasVerdict = r.hasVerdict;
    o.consistent = !r.hasVerdict || r.consistent;
    // The bias the tile test judges (docs/compare.md, "Global test"), with its 95% interval: the
    // plain image mean of t - r rests on the few heavy-tailed pixels whose renders missed rare
    // samples (bdpt on caustic-glass, 24 spp x 8: -2.8% [-4.1%, -1.6%] where the bias test gave
    // p = 0.97). The channels' values and sigmas are averaged (correlated: the safe side).
    if (r.biasTiles > 0) {
        double b = 0, sb = 0;
        for (int c = 0; c < 3; ++c) {
            b += r.weightedRelativeBias[size_t(c)] / 3.0;
            sb += r.weightedRelativeBiasSigma[size_t(c)] / 3.0;
        }
        const double z95 = stats::normalQuantile(0.975);
        o.relativeBias = b;
        o.relativeBiasLow = b - z95 * sb;
        o.relativeBiasHigh = b + z95 * sb;
    } else if (const double m = r.overall.meanRef; m != 0) {
        o.relativeBias = r.overall.bias / m;
        o.relativeBiasLow = r.overall.biasLow / m;
        o.relativeBiasHigh = r.overall.biasHigh / m;
    }
    if (const double m = r.overall.meanRef; m != 0) {
        o.hasMeanBias = true;
        o.meanRelativeBias = r.overall.bias / m;
        o.meanRelativeBiasLow = r.overall.biasLow / m;
        o.meanRelativeBiasHigh = r.overall.biasHigh / m;
    }
    o.tested = r.tested;
    o.compared = r.compared;
    o.equal = r.equal;
    o.sentence = r.sentence;
    return o;
}

namespace {

std::string tailOfFile(const std::string& path, size_t maxBytes) {
    std::ifstream in(path, std::ios::binary);
    std::string s((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (s.size() > maxBytes) s = "..." + s.substr(s.size() - maxBytes);
    while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
    return s;
}

// An sRGB PNG of R, G, B (clamped to [0, 1]), for the report.
void writePreview(const std::string& path, const ExrImage& img) {
    std::vector<uint8_t> px(size_t(img.width) * size_t(img.height) * 3);
    const char* names[3] = {"R", "G", "B"};
    for (int c = 0; c < 3; ++c) {
        const std::vector<float>& ch = img.channels.at(names[c]);
        for (size_t i = 0; i < ch.size(); ++i) px[i * 3 + size_t(c)] = linearToSrgbByte(ch[i]);
    }
    const std::vector<unsigned char> png = encodePng8(img.width, img.height, 3, px.data());
    writeOutputBytes(path, png.data(), png.size());
}

}  // namespace

std::array<std::vector<float>, 3> suiteEstimatorShape(const SuiteScene& sc, PortEstimator estimator, int width,
                                                      int height, std::string* path) {
    if (path) path->clear();
    const auto it = sc.shapes.find(estimator);
    if (it == sc.shapes.end()) return {};
    const std::string role = "the suite's estimator shape " + it->second;
    const ExrImage render = readCompareInput(it->second, role);
    if (render.width != width || render.height != height)
        throw InputError(role + " is " + std::to_string(render.width) + "x" + std::to_string(render.height) +
                         ", the reference " + std::to_string(width) + "x" + std::to_string(height));
    if (path) *path = it->second;
    // A suite of one's own may ship half-float shapes (the shipped ones did): said, not refused.
    const std::string halfWarning = halfVarianceWarning(render, role);
    if (!halfWarning.empty()) std::fprintf(stderr, "validate: warning: %s\n", halfWarning.c_str());
    return estimatorShape(render, role);
}

void compareSceneRenders(const std::vector<ExrImage>& renders, const ExrImage& reference, double alpha,
                         SceneOutcome& outcome, CompareResult* beautyOut, int samplesPerRender,
                         const std::array<std::vector<float>, 3>& testShape, PortEstimator estimator) {
    // The depth layers both sides hold, each compared at the Sidak level of alpha over the L layers.
    std::vector<int> depths;
    const std::vector<int> refDepths = depthLayers(reference);
    for (int d : depthLayers(renders.front()))
        if (std::binary_search(refDepths.begin(), refDepths.end(), d)) depths.push_back(d);
    CompareOptions o;
    o.alpha = alpha;  // the beauty decides the verdict
    o.samplesPerRender = double(std::max(0, samplesPerRender));
    outcome.layers.clear();
    o.testShape = testShape;  // a shape of the beauty: not of the depth layers
    const CompareResult beauty = compareImages(combineRenders(renders), reference, o);
    o.testShape = {};
    o.alpha = sidakLevel(alpha, std::max(1, int(depths.size())));
    outcome.layers.push_back(layerOutcome(beauty, "beauty", -1));
    for (int d : depths) {
        const std::string name = "depth" + std::to_string(d);
        std::vector<ExrImage> layer;
        for (const ExrImage& r : renders) layer.push_back(selectImageLayer(r, name, "test"));
        try {
            const CompareResult r = compareImages(combineRenders(layer), selectImageLayer(reference, name, "reference"), o);
            outcome.layers.push_back(layerOutcome(r, name, d));
        } catch (const InputError& e) {  // e.g. a layer that is zero in every render: nothing to test
            LayerOutcome none;
            none.layer = name;
            none.depth = d;
            none.sentence = std::string("not compared: ") + e.what();
            outcome.layers.push_back(none);
        }
    }

    compareStrategyClasses(renders, reference, refDepths, alpha, outcome, estimator);

    // The verdict is the beauty's alone: depth layers are sparse and skewed (most pixels of a deep
    // layer are zero in most renders), and compare's N-renders statistics are not yet calibrated
    // for them (docs/validate.md, "What a verdict means"). They locate the error once the beauty
    // has failed: the first failing depth is the smallest depth whose layer is inconsistent.
    const LayerOutcome& b = outcome.layers.front();
    outcome.firstFailingDepth = -1;
    outcome.p = b.p;
    if (!b.hasVerdict) {
        outcome.verdict = SceneVerdict::NoVerdict;
        outcome.message = beauty.noVerdictReason;
    } else if (b.consistent) {
        outcome.verdict = SceneVerdict::Consistent;
        outcome.message.clear();
    } else {
        outcome.verdict = SceneVerdict::Inconsistent;
        outcome.message.clear();
        for (const LayerOutcome& l : outcome.layers)
            if (l.depth >= 0 && l.hasVerdict && !l.consistent) {
                outcome.firstFailingDepth = l.depth;
                break;
            }
    }
    if (beautyOut) *beautyOut = beauty;
}

namespace {

// One scene of the run: its folder, its progress lines and the renderer's processes.
struct SceneRun {
    const ValidateOptions& opt;
    ValidateReport& rep;
    SceneOutcome& o;
    const std::function<bool()>& stop;
    std::function<void(const std::string&)> say;
    fs::path dir;
    RenderRequest req;
    bool seedList = false;  // the command takes {seeds}: one process renders all of a scene's seeds

    // The files a process with `seeds` writes: `file` itself, or with {seeds} `file` as a pattern
    // whose {seed} each seed replaces.
    std::vector<std::string> outputs(const std::string& file, const std::vector<uint32_t>& seeds) const {
        if (!seedList) return {(dir / file).string()};
        std::vector<std::string> out;
        for (uint32_t s : seeds) out.push_back(outputForSeed((dir / file).string(), s));
        return out;
    }

    // Runs one process of the renderer into the scene's folder (`file`: the output, with {seeds} a
    // pattern holding {seed}; its log `logName`); on failure sets the outcome and returns false.
    bool render(const std::string& file, const std::string& logName, int spp, const std::vector<uint32_t>& seeds,
                double timeout, ProcessResult* pr) {
        std::error_code ec;
        req.output = (dir / file).string();
        req.spp = spp;
        req.seed = seeds.front();
        req.seeds = seeds;
        const std::vector<std::string> files = outputs(file, seeds);
        for (const std::string& f : files) fs::remove(f, ec);
        const std::string log = (dir / logName).string();
        *pr = runShellCommand(expandCommand(opt.command, req), log, timeout, stop);
        if (pr->interrupted) {
            rep.interrupted = true;
            o.verdict = SceneVerdict::Skipped;
            o.message = "interrupted";
            return false;
        }
        const auto missing = std::find_if(files.begin(), files.end(), [](const std::string& f) { return !fs::is_regular_file(f); });
        if (pr->timedOut || pr->exitCode != 0 || missing != files.end()) {
            o.verdict = SceneVerdict::Failed;
            o.message = pr->timedOut ? "the render did not finish in " + std::to_string(int(timeout)) + " s"
                        : pr->exitCode != 0 ? "the renderer exited with status " + std::to_string(pr->exitCode)
                                            : "the renderer wrote no " + *missing;
            o.message += " (command: " + expandCommand(opt.command, req) + "; log " + log + ": " + tailOfFile(log, 600) + ")";
            return false;
        }
        return true;
    }
};

// The pilot renders (nextPilotSpp: 1 spp, then 16, 64, ... until the samples clearly add time; one
// process each, one seed) give the cost line fixed + spp * perSample, and the reference's shape
// the samples a verdict needs: what the scene's verdict costs. False when the scene failed or was
// stopped.
bool pilotScene(SceneRun& sr, double equalShare, SceneCost* cost) {
    ProcessResult pr;
    std::vector<PilotTiming> pilots;
    for (int spp = nextPilotSpp(pilots); spp > 0; spp = nextPilotSpp(pilots)) {
        sr.say("pilot render at " + std::to_string(spp) + " spp");
        const std::string name = "pilot-" + std::to_string(spp);
        const uint32_t seed = sr.opt.seedBase + 10000000u + uint32_t(pilots.size());
        const std::string file = sr.seedList ? name + "-seed{seed}.exr" : name + ".exr";
        if (!sr.render(file, name + ".log", spp, {seed}, 600, &pr)) return false;
        pilots.push_back({spp, pr.wallSeconds});
        // Timed, never compared: --drop-renders deletes it at once (a port writing strategy layers
        // writes tens of MB per render; 21 scenes of 3 pilots each filled a disk).
        std::error_code ec;
        if (!sr.opt.keepRenders)
            for (const std::string& f : sr.outputs(file, {seed})) fs::remove(f, ec);
    }
    const PilotFit fit = fitPilotCost(pilots);
    cost->secondsPerSample = fit.secondsPerSample;
    cost->fixedSeconds = fit.fixedSeconds;
    cost->oneProcess = sr.seedList;
    // A renderer with a large fixed cost per process (a GPU port's start-up, a BVH build) gets
    // fewer renders rather than samples too few to test; with {seeds} it pays that cost once. N is
    // decided on the equal share, before the shares (which depend on N through the needs) are known.
    cost->renders = sr.opt.adaptRenders && !sr.seedList ? rendersForBudget(equalShare, cost->fixedSeconds, sr.opt.renders)
                                                        : sr.opt.renders;
    try {
        const ExrImage reference = readCompareInput(sr.o.scene->reference, "reference");
        sr.o.referenceShape = referenceShapeMedian(
            reference, suiteEstimatorShape(*sr.o.scene, sr.opt.estimator, reference.width, reference.height, nullptr));
    } catch (const InputError& e) {
        sr.o.verdict = SceneVerdict::Failed;
        sr.o.message = std::string("the reference or the suite's estimator shape cannot be read: ") + e.what();
        return false;
    }
    cost->samplesNeeded = samplesNeededPerRender(sr.o.referenceShape, cost->renders, CompareOptions().minEffectiveSamples);
    cost->samplesFloor = samplesNeededPerRender(sr.o.referenceShape, cost->renders, CompareOptions().minEffectiveSamples, 1.0);
    sr.o.fixedSeconds = cost->fixedSeconds;
    sr.o.secondsPerSample = cost->secondsPerSample;
    sr.o.samplesNeeded = cost->samplesNeeded;
    sr.o.pilots = pilots;
    char line[240];
    std::snprintf(line, sizeof line,
                  "%.3g s per process, %.3g s per spp (pilots 1 and %d spp); reference C = %.3g: a verdict needs %d "
                  "spp x %d (%.1f s)",
                  cost->fixedSeconds, cost->secondsPerSample, pilots.back().spp, sr.o.referenceShape,
                  cost->samplesNeeded, cost->renders, cost->neededSeconds());
    sr.say(line);
    return true;
}

// Shares the budget among the scenes whose pilots succeeded and sets their spp and renders.
void planBudget(const std::vector<SceneRun*>& scenes, const std::vector<SceneCost>& costs, double budget,
                ValidateReport& rep, const ProgressFn& progress) {
    const BudgetShares shares = allocateSceneBudgets(costs, budget);
    rep.budgetNeededSeconds = shares.neededSeconds;
    rep.budgetSufficient = shares.needsFit;
    for (size_t i = 0; i < scenes.size(); ++i) {
        SceneOutcome& o = scenes[i]->o;
        o.budgetShareSeconds = shares.seconds[i];
        o.renders = costs[i].renders;
        o.spp = sppForShare(shares.seconds[i], costs[i]);
    }
    if (!progress || scenes.empty()) return;
    char line[300];
    if (shares.needsFit)
        std::snprintf(line, sizeof line, "budget: %.0f s shared by what each scene's verdict costs (%.0f s together)", budget,
                      shares.neededSeconds);
    else
        std::snprintf(line, sizeof line,
                      "budget: %.0f s is too small for a verdict on every scene: their needs add up to about %.0f s "
                      "(--budget %.0f would do); each scene gets the same fraction of its need",
                      budget, shares.neededSeconds, std::ceil(shares.neededSeconds));
    progress(line);
}

// The seeds of a scene's renders: seedBase + kRenderSeedSpacing k. Spaced, because a renderer that
// seeds thread i with seed + i (SmallVCM) makes consecutive seeds share streams, and compare then
// refuses the renders (docs/compare.md, "Renders that share noise").
std::vector<uint32_t> renderSeeds(const ValidateOptions& opt, int renders) {
    std::vector<uint32_t> seeds;
    for (int k = 0; k < renders; ++k) seeds.push_back(opt.seedBase + kRenderSeedSpacing * uint32_t(k));
    return seeds;
}

// The scene's N renders: one process each, or with {seeds} one process for all of them (the file
// of seed s: render-seed<s>.exr). False when the scene failed or was stopped.
bool renderScene(SceneRun& sr, double timeout, std::vector<std::string>* files) {
    SceneOutcome& o = sr.o;
    const std::vector<uint32_t> seeds = renderSeeds(sr.opt, o.renders);
    ProcessResult pr;
    if (sr.seedList) {
        sr.say(std::to_string(o.renders) + " renders at " + std::to_string(o.spp) + " spp in one process");
        if (!sr.render("render-seed{seed}.exr", "renders.log", o.spp, seeds, timeout * o.renders, &pr)) return false;
        o.renderSeconds += pr.wallSeconds;
        *files = sr.outputs("render-seed{seed}.exr", seeds);
        return true;
    }
    for (int k = 0; k < o.renders; ++k) {
        sr.say("render " + std::to_string(k + 1) + "/" + std::to_string(o.renders) + " at " + std::to_string(o.spp) + " spp");
        const std::string file = "render-" + std::to_string(k + 1) + ".exr";
        if (!sr.render(file, file + ".log", o.spp, {seeds[size_t(k)]}, timeout, &pr)) return false;
        o.renderSeconds += pr.wallSeconds;
        files->push_back(sr.req.output);
    }
    return true;
}

// The scene's renders and their comparison with the reference. `timeout`: per render.
void renderAndCompare(SceneRun& sr, double timeout) {
    SceneOutcome& o = sr.o;
    const SuiteScene& sc = *o.scene;
    std::vector<std::string> files;
    if (!renderScene(sr, timeout, &files)) return;
    std::vector<ExrImage> images;
    for (const std::string& f : files) {
        try {
            images.push_back(readCompareInput(f, "test"));
        } catch (const InputError& e) {
            o.verdict = SceneVerdict::Failed;
            o.message = std::string("the render cannot be compared: ") + e.what();
            return;
        }
    }
    const std::string outDir = sr.opt.outDir;
    try {
        const ExrImage reference = readCompareInput(sc.reference, "reference");
        // The port's estimator may be shaped unlike the reference's: the suite's long render of a
        // like estimator says where its samples are heavy-tailed (docs/validate.md).
        const std::array<std::vector<float>, 3> shape =
            suiteEstimatorShape(sc, sr.opt.estimator, reference.width, reference.height, &o.testShape);
        CompareResult beauty;
        compareSceneRenders(images, reference, sr.rep.alphaPerScene, o, &beauty, o.spp, shape, sr.opt.estimator);
        o.heatmap = sc.name + "/heatmap.png";
        writeHeatmapPng((fs::path(outDir) / o.heatmap).string(), beauty);
        o.testPreview = sc.name + "/mean.png";
        writePreview((fs::path(outDir) / o.testPreview).string(), combineRenders(images));
        o.referencePreview = sc.name + "/reference.png";
        writePreview((fs::path(outDir) / o.referencePreview).string(), reference);
    } catch (const InputError& e) {
        o.verdict = SceneVerdict::Failed;
        o.message = std::string("the renders cannot be compared with the reference: ") + e.what();
    }
    sr.say(std::string(sceneVerdictName(o.verdict)) + (o.layers.empty() ? "" : " (" + o.layers.front().sentence + ")"));
    std::error_code ec;
    if (!sr.opt.keepRenders)
        for (const std::string& f : files) fs::remove(f, ec);
}

// The scenes the options choose and the estimator can render; the others get their reason.
std::vector<SceneOutcome*> chooseScenes(const Suite& suite, const ValidateOptions& opt, ValidateReport& rep) {
    for (const std::string& n : opt.only)
        if (std::none_of(suite.scenes.begin(), suite.scenes.end(), [&](const SuiteScene& s) { return s.name == n; })) {
            std::string names;
            for (const SuiteScene& s : suite.scenes) names += (names.empty() ? "" : ", ") + s.name;
            throw InputError("--scenes: no scene '" + n + "' in the suite (it has: " + names + ")");
        }
    for (const SuiteScene& s : suite.scenes) {
        SceneOutcome o;
        o.scene = &s;
        const bool chosen = opt.only.empty() || std::find(opt.only.begin(), opt.only.end(), s.name) != opt.only.end();
        const bool canRender = std::find(s.estimators.begin(), s.estimators.end(), opt.estimator) != s.estimators.end();
        if (!chosen) {
            o.message = "not chosen (--scenes)";
        } else if (!canRender) {
            o.message = std::string("a ") + portEstimatorName(opt.estimator) +
                        " estimator cannot sample every path of this scene (rendered by: ";
            for (size_t i = 0; i < s.estimators.size(); ++i)
                o.message += (i ? ", " : "") + std::string(portEstimatorName(s.estimators[i]));
            o.message += ")";
        }
        rep.scenes.push_back(o);
    }
    std::vector<SceneOutcome*> run;
    for (SceneOutcome& o : rep.scenes)
        if (o.message.empty()) run.push_back(&o);
    return run;
}

}  // namespace

ValidateReport runValidation(const Suite& suite, const ValidateOptions& opt, const ProgressFn& progress,
                             const std::function<bool()>& stop) {
    const auto start = std::chrono::steady_clock::now();
    checkCommandTemplate(opt.command);
    if (opt.renders < 2) throw InputError("--renders must be >= 2: the spread of N independent renders is their noise");
    if (!(opt.alpha > 0 && opt.alpha < 1)) throw InputError("--alpha must be in (0, 1)");
    if (opt.spp <= 0 && !(opt.budgetSeconds > 0)) throw InputError("--budget must be > 0 seconds");

    ValidateReport rep;
    rep.suitePath = suite.path;
    rep.signatures = suite.signatures;
    rep.command = opt.command;
    rep.options = opt;
    const std::vector<SceneOutcome*> chosen = chooseScenes(suite, opt, rep);
    std::error_code ec;
    fs::create_directories(opt.outDir, ec);
    if (!fs::is_directory(opt.outDir)) throw InputError("--out " + opt.outDir + ": cannot create the folder");
    checkOutputWritable((fs::path(opt.outDir) / "report.json").string());
    if (chosen.empty()) throw InputError("no scene of the suite to run (see --scenes and --estimator)");
    rep.alphaPerScene = sidakLevel(opt.alpha, int(chosen.size()));

    std::vector<SceneRun> runs;
    runs.reserve(chosen.size());  // `ready` below points into it
    for (size_t i = 0; i < chosen.size(); ++i) {
        SceneOutcome& o = *chosen[i];
        const std::string prefix =
            "[" + std::to_string(i + 1) + "/" + std::to_string(chosen.size()) + "] " + o.scene->name + ": ";
        auto say = [&progress, prefix](const std::string& what) {
            if (progress) progress(prefix + what);
        };
        SceneRun sr{opt, rep, o, stop, say,
                    fs::path(opt.outDir) / o.scene->name, RenderRequest{}};
        sr.req.scene = o.scene;
        sr.seedList = commandTakesSeedList(opt.command);
        sr.req.width = suite.width;
        sr.req.height = suite.height;
        runs.push_back(std::move(sr));
    }
    // A scene that is stopped before it starts says so.
    auto stopped = [&](SceneOutcome& o) {
        if (!(stop && stop())) return false;
        rep.interrupted = true;
        o.message = "not run (interrupted)";
        return true;
    };

    // With a budget, the pilots of every scene first: the shares depend on what all of them cost.
    std::vector<SceneRun*> ready;
    if (opt.spp > 0) {
        for (SceneRun& sr : runs) {
            sr.o.spp = opt.spp;
            sr.o.renders = opt.renders;
            ready.push_back(&sr);
        }
    } else {
        std::vector<SceneCost> costs;
        const double equalShare = opt.budgetSeconds / double(runs.size());
        for (SceneRun& sr : runs) {
            if (stopped(sr.o)) continue;
            fs::create_directories(sr.dir, ec);
            SceneCost cost;
            if (!pilotScene(sr, equalShare, &cost)) continue;
            ready.push_back(&sr);
            costs.push_back(cost);
        }
        if (!rep.interrupted) planBudget(ready, costs, opt.budgetSeconds, rep, progress);
    }

    for (SceneRun* sr : ready) {
        if (stopped(sr->o)) continue;
        fs::create_directories(sr->dir, ec);
        const double timeout =
            opt.spp > 0 ? opt.timeoutSeconds : std::max(120.0, 10.0 * sr->o.budgetShareSeconds / sr->o.renders);
        renderAndCompare(*sr, timeout);
    }

    bool anyInconsistent = false, allConsistent = true;
    for (const SceneOutcome* o : chosen) {
        anyInconsistent |= o->verdict == SceneVerdict::Inconsistent;
        allConsistent &= o->verdict == SceneVerdict::Consistent;
    }
    rep.exitCode = anyInconsistent ? 1 : allConsistent && !rep.interrupted ? 0 : 2;
    rep.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return rep;
}

}  // namespace bdptref
