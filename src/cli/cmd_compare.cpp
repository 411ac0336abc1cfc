// `bdptref compare TEST REF` or `bdptref compare T1 T2 ... TN REF` (N >= 2 independent renders of
// a renderer that writes only R, G, B): is the test consistent with REF up to Monte Carlo noise? Metrics, a
// per-pixel statistical test with a global p-value, flagged pixels, a heatmap and JSON output
// (include/bdptref/image_compare.h, docs/compare.md). Exit codes: 0 consistent, 1 inconsistent,
// 2 unusable input (including "no verdict possible": no variance layers, nothing testable).
#include "bdptref/errors.h"
#include "bdptref/exr_io.h"
#include "bdptref/image_compare.h"
#include "cli/commands.h"
#include "core/output_file.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>

namespace bdptref::cli {

namespace {

struct CompareArgs {
    std::vector<std::string> files;  // TEST REF, or T1 ... TN REF
    std::string region, mask, heatmap, layer, testShape;
    double alpha = 0.01, epsilon = 1e-2, minEffective = 10.0, precision = 1e-5;
    double samplesPerRender = 0.0;  // N renders: the spp of each (0: not given)
    int tile = 16;
    bool json = false;
    bool metricsOnly = false;
};

// --metrics-only: the error metrics of the beauty, no statistical test (variance layers dropped).
ExrImage withoutVariances(ExrImage img) {
    for (const char* c : {"variance.R", "variance.G", "variance.B"}) img.channels.erase(c);
    return img;
}

// The statistics an image claims must be usable: a negative or non-finite variance, or a variance
// claimed for a pixel with no samples, means a broken or hand-made file, and a verdict against it
// would be meaningless. The reference's means must be finite too; a non-finite mean in the test
// image is a finding (the test renderer produced NaN/Inf: flagged, exit 1), not bad input.
void checkStatistics(const ExrImage& img, const std::string& path, const char* role, bool meansMustBeFinite) {
    auto where = [&](size_t i, const std::string& channel) {
        const FilmWindow& w = img.window;
        return std::string(role) + " image " + path + ": pixel (" + std::to_string(int(i % size_t(img.width)) + w.x0) +
               ", " + std::to_string(int(i / size_t(img.width)) + w.y0) + ") channel " + channel;
    };
    const std::vector<float>* count = img.has("count") ? &img.channels.at("count") : nullptr;
    const size_t n = size_t(img.width) * size_t(img.height);
    for (size_t i = 0; i < n; ++i) {
        if (count && !(std::isfinite((*count)[i]) && (*count)[i] >= 0.f))
            throw InputError(where(i, "count") + " is " + std::to_string((*count)[i]) + ": a sample count must be >= 0");
        for (const char* c : {"R", "G", "B"}) {
            const auto m = img.channels.find(c);
            if (meansMustBeFinite && m != img.channels.end() && !std::isfinite(m->second[i]))
                throw InputError(where(i, c) + " is not finite (" + std::to_string(m->second[i]) + ")");
            const std::string vn = std::string("variance.") + c;
            const auto v = img.channels.find(vn);
            if (v == img.channels.end()) continue;
            const float var = v->second[i];
            if (!std::isfinite(var) || var < 0.f)
                throw InputError(where(i, vn) + " is " + std::to_string(var) +
                                 ": a variance must be finite and >= 0 (a broken or hand-edited file?)");
            if (count && (*count)[i] == 0.f && var > 0.f)
                throw InputError(where(i, vn) + " is " + std::to_string(var) + " with count 0: no samples, no variance");
        }
    }
}

int run(const CompareArgs& a) {
    if (!(a.alpha > 0.0 && a.alpha < 1.0)) throw InputError("--alpha must be in (0, 1)");
    if (!(a.epsilon > 0.0)) throw InputError("--epsilon must be > 0");
    if (!(a.minEffective >= 0.0)) throw InputError("--min-effective must be >= 0");
    if (!(a.precision >= 0.0 && a.precision < 1.0)) throw InputError("--precision must be in [0, 1)");
    if (a.tile < 1) throw InputError("--tile must be >= 1");
    if (!(a.samplesPerRender >= 0.0) || !std::isfinite(a.samplesPerRender))
        throw InputError("--samples-per-render must be a number of samples >= 1 (or 0: not known)");
    if (a.samplesPerRender > 0.0 && a.files.size() < 3)
        throw InputError("--samples-per-render applies to N >= 2 renders (bdptref compare T1.exr ... TN.exr REF.exr); "
                         "a single test image says its samples in its count layer");
    if (a.files.size() < 2)
        throw InputError("compare needs a test image and a reference: bdptref compare TEST.exr REF.exr, or N >= 2 "
                         "renders and a reference: bdptref compare T1.exr ... TN.exr REF.exr");
    const std::string refPath = a.files.back();
    const std::vector<std::string> testPaths(a.files.begin(), a.files.end() - 1);
    ExrImage ref = readCompareInput(refPath, "reference");
    if (!a.layer.empty()) ref = selectImageLayer(ref, a.layer, "reference");
    checkStatistics(ref, refPath, "reference", true);
    ExrImage test;
    std::string testName = testPaths[0];
    if (testPaths.size() == 1) {
        test = readCompareInput(testPaths[0], "test");
        if (!a.layer.empty()) test = selectImageLayer(test, a.layer, "test");
        checkStatistics(test, testPaths[0], "test", false);
        if (!a.metricsOnly) requireTestStatistics(test, testPaths[0]);
    } else {
        // N renders: their mean and the variance of that mean over the renders (N - 1 dof).
        std::vector<ExrImage> renders;
        for (const std::string& p : testPaths) {
            renders.push_back(readCompareInput(p, "test"));
            if (!a.layer.empty()) renders.back() = selectImageLayer(renders.back(), a.layer, "test");
        }
        test = combineRenders(renders, testPaths);
        testName = "mean of " + std::to_string(testPaths.size()) + " renders " + testPaths[0] + " ... " + testPaths.back();
    }
    // Crop renders store only their window (EXR data window); pixels are compared by position.
    if (test.window != ref.window && test.width == ref.width && test.height == ref.height)
        throw InputError("the images hold different pixels of the image: test " + testPaths[0] + " has data window " +
                         test.window.text() + ", reference " + refPath + " " + ref.window.text() +
                         " (crop renders of different windows; render the same --crop)");

    CompareOptions o;
    o.alpha = a.alpha;
    o.epsilon = a.epsilon;
    o.minEffectiveSamples = a.minEffective;
    o.samplesPerRender = a.samplesPerRender;
    o.precision = a.precision;
    o.tileSize = a.tile;
    if (!a.region.empty()) {
        o.useRegion = true;
        o.region = parseRegion(a.region);
    }
    if (!a.mask.empty()) {
        if (!std::filesystem::exists(a.mask)) throw InputError("--mask " + a.mask + ": no such file");
        o.mask = loadMask(a.mask, test.width, test.height);
    }
    std::string shapeWarning;  // a --test-shape whose variances lost their bits in half floats
    if (!a.testShape.empty()) {
        if (!a.layer.empty())
            throw InputError("--test-shape is the shape of the beauty; it does not apply with --layer " + a.layer);
        const ExrImage shape = readCompareInput(a.testShape, "--test-shape");
        if (shape.width != test.width || shape.height != test.height || shape.window != test.window)
            throw InputError("--test-shape " + a.testShape + " is " + std::to_string(shape.width) + "x" +
                             std::to_string(shape.height) + " (data window " + shape.window.text() + "), the test " +
                             std::to_string(test.width) + "x" + std::to_string(test.height) + " (" + test.window.text() +
                             "): render it at the same size and crop");
        checkStatistics(shape, a.testShape, "--test-shape", true);
        o.testShape = estimatorShape(shape, "--test-shape " + a.testShape);
        shapeWarning = halfVarianceWarning(shape, "--test-shape " + a.testShape);
    }
    checkOutputs({{"--heatmap", a.heatmap, ".png"}});  // core/output_file.h

    if (a.metricsOnly) {
        test = withoutVariances(std::move(test));
        ref = withoutVariances(std::move(ref));
    }
    CompareResult r = compareImages(test, ref, o);
    if (!shapeWarning.empty()) r.warnings.push_back(shapeWarning);
    if (!a.heatmap.empty()) writeHeatmapPng(a.heatmap, r);
    if (a.json && a.metricsOnly) {
        // The same JSON, saying that no verdict was asked for (and the exit status it has).
        nlohmann::ordered_json j = nlohmann::ordered_json::parse(compareResultJson(r, testName, refPath));
        j["verdict"] = "metrics only";
        j["exitCode"] = 0;
        j["sentence"] = "metrics only (--metrics-only): no statistical test";
        std::printf("%s\n", j.dump(2).c_str());
    } else if (a.json) {
        std::printf("%s\n", compareResultJson(r, testName, refPath).c_str());
    } else {
        std::printf("%s", formatCompareReport(r, testName, refPath).c_str());
    }
    std::fflush(stdout);
    if (a.metricsOnly) return 0;  // asked for the metrics only: no verdict is not an error
    if (!r.hasVerdict) throw InputError("no statistical verdict: " + r.noVerdictReason);
    return r.consistent ? 0 : 1;
}

}  // namespace

std::function<int()> addCompareCommand(CLI::App& app) {
    auto a = std::make_shared<CompareArgs>();
    CLI::App* cmd = app.add_subcommand(
        "compare",
        "is a rendered image consistent with a reference up to Monte Carlo noise? Metrics, per-pixel statistical "
        "test, global p-value (docs/compare.md)");
    cmd->add_option("files", a->files,
                    "TEST REF: a test image with variance layers (variance.R/G/B, count) and the reference; or "
                    "T1 ... TN REF: N >= 2 independent plain RGB renders (different seeds) and the reference. "
                    "Linear float images (EXR, PFM); the reference ideally a bdptref EXR with variances")
        ->required()
        ->expected(1, -1);  // fewer than 2: refused in run() with a message naming the reference
    cmd->add_option("--region", a->region, "compare only pixels x,y,w,h (x, y: top-left corner)");
    cmd->add_option("--mask", a->mask, "compare only where this image (EXR/PNG, same size; first channel) is > 0.5");
    cmd->add_option("--alpha", a->alpha,
                    "significance level of the global test and false discovery rate of the flagged pixels "
                    "(default 0.01)");
    cmd->add_option("--epsilon", a->epsilon, "relMSE = mean((t - r)^2 / (r^2 + epsilon)) (default 0.01)");
    cmd->add_option("--min-effective", a->minEffective,
                    "test a channel only if each image is expected to hold this many effective samples "
                    "(sum x)^2 / sum x^2 (default 10; 0 = test everything)");
    cmd->add_option("--samples-per-render", a->samplesPerRender,
                    "with N renders: the samples per pixel of each; a pixel is then tested only where the reference's own "
                    "noise says N times that many hold --min-effective effective samples (renders that all missed a rare "
                    "contribution look smooth; docs/compare.md)");
    cmd->add_option("--test-shape", a->testShape,
                    "a long render (EXR with variance layers and a count) of an estimator like the test's: where its "
                    "samples are heavy-tailed (per-sample relative variance C), the test's few samples are given the "
                    "variance C mu^2 / n and tested only with --min-effective n / (1 + C) effective samples (needs the "
                    "test's samples: a count layer, or N renders with --samples-per-render; docs/compare.md)");
    cmd->add_option("--precision", a->precision,
                    "relative precision of the values: zero-variance pixels must agree to it, and smaller "
                    "differences are never significant (default 1e-5, float rounding)");
    cmd->add_option("--tile", a->tile, "tile size for locating the worst region (default 16)");
    cmd->add_option("--layer", a->layer,
                    "compare layer NAME instead of the beauty: NAME.R/G/B with NAME.variance.R/G/B (e.g. "
                    "s1t2.weighted from render --strategies)");
    cmd->add_option("--heatmap", a->heatmap,
                    "write a PNG of the signed per-pixel z-scores (relative error without variances) with a legend");
    cmd->add_flag("--json", a->json, "print everything as JSON on stdout instead of the text report");
    cmd->add_flag("--metrics-only", a->metricsOnly,
                  "only the error metrics (MSE, RMSE, relMSE, MAE, bias): no statistical test, so a single plain RGB "
                  "test image is accepted; exit 0 when the metrics were computed (for benchmarks)");
    cmd->footer(
        "Layers read: R, G, B (required); variance.R, variance.G, variance.B = variance of the pixel MEAN (s^2/n) and "
        "count = samples per pixel. A test image without variance layers is refused: give N >= 2 renders with "
        "different seeds instead (their per-pixel mean and variance are used, N - 1 degrees of freedom). 8-bit or "
        "display-encoded images (PNG, JPEG, 8-bit TIFF, sRGB) are refused: write linear float EXR or PFM.\n"
        "Exit codes: 0 consistent with the reference, 1 inconsistent, 2 unusable input (missing or unreadable file, "
        "size mismatch, no R/G/B, no variances, display-encoded input, bad option, or no verdict possible: "
        "'insufficient samples' when fewer than a quarter of the pixels with noise could be tested).");
    return [a] { return run(*a); };
}

}  // namespace bdptref::cli
