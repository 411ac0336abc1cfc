// Inputs of the comparison: which channels of an image hold the mean, the variance of the mean and
// the sample count, options given as text (--region, --mask), and the small formatting helpers the
// other compare_*.cpp files share (src/verify/compare_internal.h).
#include "verify/compare_internal.h"

#include "bdptref/errors.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

namespace bdptref {

namespace compare_detail {

const char* const kChannelNames[3] = {"R", "G", "B"};
const char* const kVarianceNames[3] = {"variance.R", "variance.G", "variance.B"};

bool hasRgb(const ExrImage& img) { return img.has("R") && img.has("G") && img.has("B"); }
bool hasVariance(const ExrImage& img) {
    return img.has(kVarianceNames[0]) && img.has(kVarianceNames[1]) && img.has(kVarianceNames[2]);
}

std::string channelList(const ExrImage& img) {
    std::string s;
    for (const auto& kv : img.channels) s += (s.empty() ? "" : ", ") + kv.first;
    return s.empty() ? std::string("none") : s;
}

std::string fmtP(double p) {
    if (std::isnan(p)) return "n/a";
    if (p <= 0.0) return "0";
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.2g", p);
    return buf;
}

// "p = 0.43", or "p < 1e-300" when the p-value underflowed.
std::string pIs(double p) { return p <= 0.0 ? std::string("p < 1e-300") : "p = " + fmtP(p); }

std::string fmtG(double v, int digits) {
    char buf[48];
    std::snprintf(buf, sizeof buf, "%.*g", digits, v);
    return buf;
}

std::string fmtPercent(double v) {
    char buf[48];
    std::snprintf(buf, sizeof buf, "%+.*f%%", std::abs(v) < 0.1 ? 3 : (std::abs(v) < 10 ? 2 : 1), v * 100.0);
    return buf;
}

// Effective number of samples (sum x)^2 / sum x^2 from n, the mean and the variance of the mean
// (s^2 / n); without a count (n = infinity) mean^2 / variance, its large-n value.
double effectiveSamples(double n, double mean, double varOfMean) {
    if (std::isinf(n)) return varOfMean > 0 ? mean * mean / varOfMean : std::numeric_limits<double>::infinity();
    const double denom = (n - 1.0) * varOfMean + mean * mean;
    return denom > 0 ? n * mean * mean / denom : 0.0;
}

}  // namespace compare_detail

using namespace compare_detail;

const char* testKindName(TestKind k) {
    switch (k) {
    case TestKind::Welch: return "welch";
    case TestKind::RefVariance: return "z-ref";
    case TestKind::TestVariance: return "z-test";
    case TestKind::None: return "none";
    }
    return "?";
}

PixelRegion parseRegion(const std::string& text) {
    std::stringstream ss(text);
    long long v[4];
    char c[3] = {0, 0, 0};
    const bool parsed = bool(ss >> v[0] >> c[0] >> v[1] >> c[1] >> v[2] >> c[2] >> v[3]);
    ss >> std::ws;
    if (!parsed || !ss.eof() || c[0] != ',' || c[1] != ',' || c[2] != ',' || v[0] < 0 || v[1] < 0 || v[2] < 1 ||
        v[3] < 1 || v[0] > INT32_MAX || v[1] > INT32_MAX || v[2] > INT32_MAX || v[3] > INT32_MAX)
        throw InputError("--region: expected x,y,w,h with x, y >= 0 and w, h >= 1, got '" + text + "'");
    return PixelRegion{int(v[0]), int(v[1]), int(v[2]), int(v[3])};
}

std::vector<uint8_t> loadMask(const std::string& path, int width, int height) {
    const ExrImage m = readImage(path);
    if (m.width != width || m.height != height)
        throw InputError(path + ": the mask is " + std::to_string(m.width) + "x" + std::to_string(m.height) +
                         ", the images are " + std::to_string(width) + "x" + std::to_string(height));
    const std::vector<float>* ch = nullptr;
    for (const char* name : {"R", "Y", "A"})
        if (m.has(name)) {
            ch = &m.channels.at(name);
            break;
        }
    if (!ch) {
        if (m.channels.empty()) throw InputError(path + ": the mask has no channels");
        ch = &m.channels.begin()->second;
    }
    std::vector<uint8_t> mask(ch->size());
    for (size_t i = 0; i < ch->size(); ++i) mask[i] = (*ch)[i] > 0.5f ? 1 : 0;
    return mask;
}

}  // namespace bdptref
