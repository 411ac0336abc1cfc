// The comparison in words: warnings, the verdict sentence, the text report and the JSON
// (include/bdptref/image_compare.h).
#include "verify/compare_internal.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <sstream>

namespace bdptref {

namespace compare_detail {

const char* statusName(PixelStatus s) {
    switch (s) {
    case PixelStatus::Outside: return "outside";
    case PixelStatus::NonFinite: return "non-finite";
    case PixelStatus::FewSamples: return "few samples";
    case PixelStatus::LowEffective: return "low effective samples";
    case PixelStatus::Equal: return "equal";
    case PixelStatus::Unequal: return "zero-variance mismatch";
    case PixelStatus::Tested: return "tested";
    case PixelStatus::NoVariance: return "no variance";
    }
    return "?";
}

std::string methodDescription(const CompareResult& r) {
    switch (r.kind) {
    case TestKind::Welch:
        if (r.testRenders >= 2)
            return "Welch t-test per pixel and channel: the test image is the mean of " + std::to_string(r.testRenders) +
                   " renders, its variance the spread over them (" + std::to_string(r.testRenders - 1) +
                   " degrees of freedom), and at least the reference's times the image's test/reference ratio";
        return std::string("Welch t-test per pixel and channel (both images have variances") +
               (r.testHasCount && r.refHasCount ? " and counts)" : "; a missing count is taken as large)");
    case TestKind::RefVariance:
        return "one-sample t-test of the test image against the reference mean and variance (only the reference has "
               "variances; the test image is taken as exact)";
    case TestKind::TestVariance:
        return "one-sample t-test of the reference against the test image's mean and variance (only the test image "
               "has variances; the reference is taken as exact)";
    case TestKind::None: return "none (no variance layers): metrics only";
    }
    return "?";
}

int exitCodeOf(const CompareResult& r) { return !r.hasVerdict ? 2 : r.consistent ? 0 : 1; }

void addWarnings(const ExrImage& test, const ExrImage& ref, CompareResult& r) {
    const double thr = r.options.minEffectiveSamples;
    {
        auto attr = [](const ExrImage& img, const std::string& k) {
            const auto it = img.attributes.find(k);
            return it == img.attributes.end() ? std::string() : it->second;
        };
        const std::string st = attr(test, "bdptref:seed"), sr = attr(ref, "bdptref:seed");
        if (!st.empty() && st == sr)
            r.warnings.push_back("both images were rendered with seed " + st +
                                 ": their noise is correlated (identical for identical settings) and the test assumes "
                                 "independent images; render one of them with another seed");
        for (const auto* img : {&test, &ref}) {
            const std::string nf = attr(*img, "bdptref:nonFiniteSamples");
            if (!nf.empty() && nf != "0")
                r.warnings.push_back(std::string(img == &test ? "test" : "reference") + " image: " + nf +
                                     " non-finite samples were counted as zero while rendering");
        }
        for (const auto* img : {&test, &ref}) {
            const std::string w = halfVarianceWarning(*img, img == &test ? "test image" : "reference");
            if (!w.empty()) r.warnings.push_back(w);
        }
        if (r.kind == TestKind::RefVariance)
            r.warnings.push_back("the test image has no variance layers: it is treated as exact (noise-free), which is "
                                 "valid only if it is far more converged than the reference; otherwise write "
                                 "variance.R/G/B and count into it");
        if (r.kind == TestKind::TestVariance)
            r.warnings.push_back("the reference has no variance layers: it is treated as exact (noise-free)");
        if (r.kind != TestKind::None && r.compared > 0 && r.lowEffective * 10 > r.compared)
            r.warnings.push_back(std::to_string(r.lowEffective) + " of " + std::to_string(r.compared) +
                                 " pixels have fewer than " + fmtG(thr) +
                                 " effective samples and were not tested: render more samples");
        if (r.nonFinite > 0)
            r.warnings.push_back(std::to_string(r.nonFinite) + " pixels are NaN or infinite in one of the images");
    }
}

void writeSentence(CompareResult& r) {
    {
        std::ostringstream s;
        if (!r.hasVerdict) {
            s << "no statistical verdict: " << r.noVerdictReason << "; overall mean bias "
              << fmtPercent(r.overall.relativeBias) << ", relMSE " << fmtG(r.overall.relMse, 3);
        } else if (r.consistent) {
            s << "consistent with the reference (" << pIs(r.pGlobal) << ", " << r.tested << " pixels tested";
            if (r.equal > 0) s << ", " << r.equal << " equal with zero variance";
            s << ")";
        } else {
            s << "INCONSISTENT with the reference (" << (r.unequal + r.nonFinite > 0 ? "p = 0" : pIs(r.pGlobal)) << "): ";
            std::vector<std::string> parts;
            if (r.unequal > 0)
                parts.push_back(std::to_string(r.unequal) + " zero-variance pixels differ");
            if (r.nonFinite > 0) parts.push_back(std::to_string(r.nonFinite) + " pixels are NaN or infinite");
            for (size_t k = 0; k < parts.size(); ++k) s << (k ? ", " : "") << parts[k];
            if (!parts.empty()) s << "; ";
            if (r.flagged > 0) {
                s << r.flagged << " pixels flagged, worst region x " << r.worstX0 << ".." << r.worstX1 << ", y "
                  << r.worstY0 << ".." << r.worstY1 << " (";
                if (!r.worstIsBoundingBox) s << r.worstFlagged << " flagged, ";
                s << "median bias " << fmtPercent(r.worstRelativeBias) << ")";
            } else {
                s << "no single pixel flagged";
            }
            if (r.biasTiles > 0) {
                // The three channels' tile-weighted relative biases, averaged (their sigmas too:
                // the channels are correlated, adding them is the safe side).
                double b = 0, sb = 0;
                for (int c = 0; c < 3; ++c) {
                    b += r.weightedRelativeBias[size_t(c)] / 3.0;
                    sb += r.weightedRelativeBiasSigma[size_t(c)] / 3.0;
                }
                s << "; over the image the test is off by " << fmtPercent(b) << " +- " << fmtPercent(sb).substr(1)
                  << " (bias test " << pIs(r.pBias) << ")";
            } else {
                s << "; whole-image mean bias " << fmtPercent(r.overall.relativeBias);
            }
        }
        r.sentence = s.str();
    }
}

}  // namespace compare_detail

using namespace compare_detail;

std::string formatCompareReport(const CompareResult& r, const std::string& testName, const std::string& refName) {
    std::ostringstream o;
    char line[512];
    o << "test:      " << testName << "\nreference: " << refName << "\n";
    o << "image " << r.width << "x" << r.height << ", compared region x " << r.region.x << ".."
      << r.region.x + r.region.width - 1 << ", y " << r.region.y << ".." << r.region.y + r.region.height - 1
      << (r.options.mask.empty() ? "" : " (masked)") << ": " << r.compared << " pixels\n";
    o << "method: " << methodDescription(r) << "\n\n";
    std::snprintf(line, sizeof line, "%-22s %12s %12s %12s %12s\n", "", "R", "G", "B", "all");
    o << line;
    auto row = [&](const char* name, auto get) {
        std::snprintf(line, sizeof line, "%-22s %12.5g %12.5g %12.5g %12.5g\n", name, get(r.channel[0]),
                      get(r.channel[1]), get(r.channel[2]), get(r.overall));
        o << line;
    };
    row("mean test", [](const ChannelMetrics& m) { return m.meanTest; });
    row("mean reference", [](const ChannelMetrics& m) { return m.meanRef; });
    row("MSE", [](const ChannelMetrics& m) { return m.mse; });
    row("RMSE", [](const ChannelMetrics& m) { return m.rmse; });
    std::string relName = "relMSE (eps " + fmtG(r.options.epsilon, 3) + ")";
    row(relName.c_str(), [](const ChannelMetrics& m) { return m.relMse; });
    row("mean |t - r|", [](const ChannelMetrics& m) { return m.mae; });
    row("max |t - r|", [](const ChannelMetrics& m) { return m.maxAbs; });
    row("mean bias (t - r)", [](const ChannelMetrics& m) { return m.bias; });
    row("  95% CI low", [](const ChannelMetrics& m) { return m.biasLow; });
    row("  95% CI high", [](const ChannelMetrics& m) { return m.biasHigh; });
    std::snprintf(line, sizeof line, "%-22s %12s %12s %12s %12s\n", "  relative", fmtPercent(r.channel[0].relativeBias).c_str(),
                  fmtPercent(r.channel[1].relativeBias).c_str(), fmtPercent(r.channel[2].relativeBias).c_str(),
                  fmtPercent(r.overall.relativeBias).c_str());
    o << line;
    if (r.overall.maxChannel >= 0)
        o << "max |t - r| at (" << r.overall.maxX << ", " << r.overall.maxY << ") channel "
          << kChannelNames[r.overall.maxChannel] << "\n";
    o << "bias CI from " << (r.biasFromVariances ? "the per-pixel variances (pixels independent)" : "the spread of t - r over the pixels")
      << "\n\n";

    o << "pixels: " << r.compared << " compared, " << r.tested << " tested, " << r.equal
      << " equal with zero variance, " << r.unequal << " zero-variance mismatches, " << r.fewSamples
      << " with count < 2, " << r.lowEffective << " with fewer than " << fmtG(r.options.minEffectiveSamples)
      << " effective samples, " << r.nonFinite << " non-finite\n";
    if (r.kind != TestKind::None && r.tested > 0) {
        o << "local test: smallest pixel " << pIs(r.pMin) << " at (" << r.pMinX << ", " << r.pMinY
          << "); Sidak over " << r.tested << " pixels: " << pIs(r.pLocal) << " (one pixel alone needs |z| > "
          << fmtG(r.zThreshold, 3) << ")\n";
        o << "bias test: z = " << fmtG(r.biasZ[0], 3) << " (R), " << fmtG(r.biasZ[1], 3) << " (G), "
          << fmtG(r.biasZ[2], 3) << " (B) over " << r.biasTiles << " tiles of " << r.biasTile << "x" << r.biasTile
          << "; " << pIs(r.pBias) << "\n  tile-weighted relative bias";
        for (int c = 0; c < 3; ++c)
            o << (c ? ", " : " ") << fmtPercent(r.weightedRelativeBias[size_t(c)]) << " +- "
              << fmtPercent(r.weightedRelativeBiasSigma[size_t(c)]).substr(1);
        o << "\n";
        if (r.kind == TestKind::Welch && r.testRenders >= 2 && !r.testHasCount)
            o << "test/reference ratio of the variances of the means: " << fmtG(r.varianceRatio[0], 3) << " (R), "
              << fmtG(r.varianceRatio[1], 3) << " (G), " << fmtG(r.varianceRatio[2], 3)
              << " (B); that bound exceeded the renders' own variance in " << r.pooledChannels << " of "
              << r.testedChannels << " tested channels\n";
        if (r.kind == TestKind::Welch && r.testHasCount && r.refHasCount)
            o << "per-sample variance ratio test/reference: " << fmtG(r.varianceRatio[0], 3) << " (R), "
              << fmtG(r.varianceRatio[1], 3) << " (G), " << fmtG(r.varianceRatio[2], 3)
              << " (B); the neighbourhood bound raised the variance in " << r.pooledChannels << " of "
              << r.testedChannels << " tested channels\n";
        o << "global (Sidak over the two tests): "
          << (r.unequal + r.nonFinite > 0 ? std::string("p = 0 (hard failures)") : pIs(r.pGlobal))
          << ", alpha " << fmtG(r.options.alpha) << "\n";
        o << "flagged (Benjamini-Hochberg, FDR " << fmtG(r.options.alpha) << "): " << r.flagged << " pixels";
        if (r.flagged > 0)
            o << ", bounding box x " << r.boxX0 << ".." << r.boxX1 << ", y " << r.boxY0 << ".." << r.boxY1
              << "; worst region ("
              << (r.worstIsBoundingBox ? std::string("that box")
                                       : "the " + std::to_string(r.options.tileSize) + "x" +
                                             std::to_string(r.options.tileSize) + " tile with the most")
              << ") x "
              << r.worstX0 << ".." << r.worstX1 << ", y " << r.worstY0 << ".." << r.worstY1 << ": " << r.worstFlagged
              << " flagged, median pixel bias " << fmtPercent(r.worstRelativeBias);
        o << "\n";
    } else if (r.flagged > 0) {
        o << "flagged: " << r.flagged << " pixels (hard failures)\n";
    }
    if (r.kind != TestKind::None && r.hasVerdict && !r.worst.empty() && (!r.consistent || r.flagged > 0)) {
        o << "most significant pixels:\n";
        for (const FlaggedPixel& f : r.worst) {
            if (f.status == PixelStatus::Tested && !r.isFlagged[size_t(f.y) * size_t(r.width) + size_t(f.x)] &&
                &f - r.worst.data() >= 5)
                break;
            std::snprintf(line, sizeof line, "  (%d, %d) %s %s z = %+.3g: test (%.5g, %.5g, %.5g)", f.x, f.y,
                          statusName(f.status), pIs(f.p).c_str(), f.z, f.test[0], f.test[1], f.test[2]);
            o << line;
            if (r.kind == TestKind::Welch || r.kind == TestKind::TestVariance) {
                std::snprintf(line, sizeof line, " +- (%.2g, %.2g, %.2g)", f.testSigma[0], f.testSigma[1], f.testSigma[2]);
                o << line;
            }
            std::snprintf(line, sizeof line, ", ref (%.5g, %.5g, %.5g)", f.ref[0], f.ref[1], f.ref[2]);
            o << line;
            if (r.kind == TestKind::Welch || r.kind == TestKind::RefVariance) {
                std::snprintf(line, sizeof line, " +- (%.2g, %.2g, %.2g)", f.refSigma[0], f.refSigma[1], f.refSigma[2]);
                o << line;
            }
            o << "\n";
        }
    }
    for (const std::string& w : r.warnings) o << "warning: " << w << "\n";
    o << "\n" << r.sentence << "\n";
    return o.str();
}

std::string compareResultJson(const CompareResult& r, const std::string& testName, const std::string& refName) {
    using Json = nlohmann::ordered_json;
    auto num = [](double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); };
    auto metrics = [&](const ChannelMetrics& m) {
        Json j;
        j["mse"] = num(m.mse);
        j["rmse"] = num(m.rmse);
        j["relMse"] = num(m.relMse);
        j["mae"] = num(m.mae);
        j["maxAbs"] = num(m.maxAbs);
        j["maxAt"] = Json::array({m.maxX, m.maxY});
        j["meanTest"] = num(m.meanTest);
        j["meanRef"] = num(m.meanRef);
        j["bias"] = num(m.bias);
        j["biasCI95"] = Json::array({num(m.biasLow), num(m.biasHigh)});
        j["relativeBias"] = num(m.relativeBias);
        return j;
    };
    Json j;
    j["test"] = testName;
    j["reference"] = refName;
    j["width"] = r.width;
    j["height"] = r.height;
    j["region"] = {{"x", r.region.x}, {"y", r.region.y}, {"width", r.region.width}, {"height", r.region.height}};
    j["masked"] = !r.options.mask.empty();
    j["method"] = testKindName(r.kind);
    j["methodDescription"] = methodDescription(r);
    j["alpha"] = r.options.alpha;
    j["epsilon"] = r.options.epsilon;
    j["minEffectiveSamples"] = r.options.minEffectiveSamples;
    j["precision"] = r.options.precision;
    Json m;
    for (int c = 0; c < 3; ++c) m[kChannelNames[c]] = metrics(r.channel[size_t(c)]);
    m["overall"] = metrics(r.overall);
    m["overall"]["maxChannel"] = r.overall.maxChannel >= 0 ? Json(kChannelNames[r.overall.maxChannel]) : Json(nullptr);
    j["metrics"] = m;
    j["biasCISource"] = r.biasFromVariances ? "per-pixel variances" : "spread of t-r over pixels";
    j["pixels"] = {{"compared", r.compared},   {"tested", r.tested},         {"equal", r.equal},
                   {"unequal", r.unequal},     {"fewSamples", r.fewSamples}, {"lowEffective", r.lowEffective},
                   {"nonFinite", r.nonFinite}, {"flagged", r.flagged},       {"lowEffectiveChannels", r.lowEffectiveChannels}};
    Json t;
    t["pMin"] = num(r.pMin);
    t["pMinAt"] = Json::array({r.pMinX, r.pMinY});
    t["pLocal"] = num(r.pLocal);
    t["biasZ"] = Json::array({num(r.biasZ[0]), num(r.biasZ[1]), num(r.biasZ[2])});
    t["weightedRelativeBias"] = Json::array({num(r.weightedRelativeBias[0]), num(r.weightedRelativeBias[1]),
                                             num(r.weightedRelativeBias[2])});
    t["weightedRelativeBiasSigma"] = Json::array({num(r.weightedRelativeBiasSigma[0]),
                                                  num(r.weightedRelativeBiasSigma[1]),
                                                  num(r.weightedRelativeBiasSigma[2])});
    t["biasTile"] = r.biasTile;
    t["biasTiles"] = r.biasTiles;
    t["varianceRatio"] = Json::array({num(r.varianceRatio[0]), num(r.varianceRatio[1]), num(r.varianceRatio[2])});
    t["pooledChannels"] = r.pooledChannels;
    t["testedChannels"] = r.testedChannels;
    t["pBias"] = num(r.pBias);
    t["pGlobal"] = num(r.pGlobal);
    t["zThreshold"] = num(r.zThreshold);
    t["bhThreshold"] = num(r.bhThreshold);
    t["testRenders"] = r.testRenders;
    j["tests"] = t;
    j["verdict"] = !r.hasVerdict ? "no verdict" : r.consistent ? "consistent" : "inconsistent";
    j["consistent"] = r.hasVerdict && r.consistent;
    j["exitCode"] = exitCodeOf(r);
    if (!r.hasVerdict) j["noVerdictReason"] = r.noVerdictReason;
    j["insufficientSamples"] = r.insufficientSamples;
    j["samplesFactorNeeded"] = num(r.samplesFactorNeeded);
    j["sentence"] = r.sentence;
    if (r.flagged > 0) {
        j["flaggedBox"] = {{"x0", r.boxX0}, {"y0", r.boxY0}, {"x1", r.boxX1}, {"y1", r.boxY1}};
        j["worstRegion"] = {{"x0", r.worstX0},
                            {"y0", r.worstY0},
                            {"x1", r.worstX1},
                            {"y1", r.worstY1},
                            {"flagged", r.worstFlagged},
                            {"relativeBias", num(r.worstRelativeBias)},
                            {"kind", r.worstIsBoundingBox ? "bounding box" : "tile"}};
    } else {
        j["flaggedBox"] = nullptr;
        j["worstRegion"] = nullptr;
    }
    Json fl = Json::array();
    const size_t kMaxListed = 1000;
    for (size_t i = 0; i < r.isFlagged.size() && fl.size() < kMaxListed; ++i)
        if (r.isFlagged[i]) fl.push_back(Json::array({int(i % size_t(r.width)), int(i / size_t(r.width))}));
    j["flaggedPixels"] = fl;
    j["flaggedPixelsTruncated"] = r.flagged > kMaxListed;
    Json w = Json::array();
    for (const FlaggedPixel& f : r.worst) {
        Json e;
        e["x"] = f.x;
        e["y"] = f.y;
        e["status"] = statusName(f.status);
        e["p"] = num(f.p);
        e["z"] = num(f.z);
        e["flagged"] = bool(r.isFlagged[size_t(f.y) * size_t(r.width) + size_t(f.x)]);
        e["test"] = Json::array({num(f.test[0]), num(f.test[1]), num(f.test[2])});
        e["ref"] = Json::array({num(f.ref[0]), num(f.ref[1]), num(f.ref[2])});
        e["testSigma"] = Json::array({num(f.testSigma[0]), num(f.testSigma[1]), num(f.testSigma[2])});
        e["refSigma"] = Json::array({num(f.refSigma[0]), num(f.refSigma[1]), num(f.refSigma[2])});
        w.push_back(e);
    }
    j["worstPixels"] = w;
    j["warnings"] = r.warnings;
    return j.dump(2);
}

}  // namespace bdptref
