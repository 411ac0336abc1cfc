// Image comparison for library users (bdptref.h): images from arrays, two files, a set of renders.
// The statistics are compareImages' (docs/compare.md); this file only adapts inputs and combines.
#include "bdptref/bdptref.h"
#include "bdptref/errors.h"

#include <cstdio>

namespace bdptref {

ExrImage imageFromArrays(int width, int height, const float* rgbMean, const float* rgbVarianceOfMean, const float* count) {
    if (width < 1 || height < 1) throw InputError("image size " + std::to_string(width) + "x" + std::to_string(height) + " is empty");
    if (!rgbMean) throw InputError("image: the pixel mean (R, G, B) is required");
    ExrImage im;
    im.width = width;
    im.height = height;
    const size_t n = size_t(width) * size_t(height);
    static const char* const kRgb[3] = {"R", "G", "B"};
    static const char* const kVar[3] = {"variance.R", "variance.G", "variance.B"};
    for (int c = 0; c < 3; ++c) {
        std::vector<float>& m = im.channels[kRgb[c]];
        m.resize(n);
        for (size_t i = 0; i < n; ++i) m[i] = rgbMean[3 * i + size_t(c)];
        if (rgbVarianceOfMean) {
            std::vector<float>& v = im.channels[kVar[c]];
            v.resize(n);
            for (size_t i = 0; i < n; ++i) v[i] = rgbVarianceOfMean[3 * i + size_t(c)];
        }
    }
    if (count) im.channels["count"].assign(count, count + n);
    return im;
}

CompareResult compareImageFiles(const std::string& testFile, const std::string& referenceFile, const CompareOptions& options) {
    // As the CLI: display-encoded files and a test image without variances are refused.
    const ExrImage test = readCompareInput(testFile, "test");
    requireTestStatistics(test, testFile);
    return compareImages(test, readCompareInput(referenceFile, "reference"), options);
}

RenderSetComparison compareRenderSet(const std::vector<ExrImage>& renders, const ExrImage& reference,
                                     const CompareOptions& options) {
    if (renders.empty()) throw InputError("compare: the set of renders is empty");
    RenderSetComparison out;
    out.hasVerdict = true;
    double pMin = 1.0;
    for (size_t i = 0; i < renders.size(); ++i) {
        out.results.push_back(compareImages(renders[i], reference, options));
        const CompareResult& r = out.results.back();
        if (!r.hasVerdict) out.hasVerdict = false;
        if (out.worst < 0 || r.pGlobal < pMin) {
            pMin = r.pGlobal;
            out.worst = int(i);
        }
    }
    // Sidak over the k global p-values: the renders are independent (different seeds or runs).
    out.pSet = stats::sidak(pMin, double(renders.size()));
    bool hardFailure = false;  // a zero-variance mismatch or a non-finite pixel makes a render inconsistent whatever p says
    for (const CompareResult& r : out.results) hardFailure = hardFailure || (r.hasVerdict && !r.consistent && r.pGlobal >= options.alpha);
    out.consistent = out.hasVerdict && out.pSet >= options.alpha && !hardFailure;
    int noVerdict = -1;
    for (size_t i = 0; i < out.results.size() && noVerdict < 0; ++i)
        if (!out.results[i].hasVerdict) noVerdict = int(i);
    char text[256];
    if (noVerdict >= 0)
        std::snprintf(text, sizeof text, "no verdict: render %d: %s", noVerdict, out.results[size_t(noVerdict)].noVerdictReason.c_str());
    else
        std::snprintf(text, sizeof text, "%s (p = %.3g over %zu renders; smallest p = %.3g in render %d)",
                      out.consistent ? "consistent with the reference" : "INCONSISTENT with the reference", out.pSet,
                      renders.size(), pMin, out.worst);
    out.sentence = text;
    return out;
}

}  // namespace bdptref
