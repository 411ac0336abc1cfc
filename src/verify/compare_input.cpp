// Inputs of the comparison: which channels of an image hold the mean, the variance of the mean and
// the sample count, options given as text (--region, --mask), and the small formatting helpers the
// other compare_*.cpp files share (src/verify/compare_internal.h).
#include "verify/compare_internal.h"

#include "bdptref/errors.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
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

int rendersOf(const ExrImage& img) {
    const auto it = img.attributes.find(kRendersAttribute);
    if (it == img.attributes.end()) return 0;
    try {
        return std::max(0, std::stoi(it->second));
    } catch (const std::exception&) {
        return 0;
    }
}

}  // namespace compare_detail

using namespace compare_detail;

ExrImage selectImageLayer(const ExrImage& img, const std::string& name, const std::string& role) {
    ExrImage out;
    out.width = img.width;
    out.height = img.height;
    out.window = img.window;
    out.attributes = img.attributes;
    for (const char* c : kChannelNames) {
        const auto it = img.channels.find(name + "." + c);
        if (it == img.channels.end())
            throw InputError(role + " image: no layer '" + name + "' (no channel " + name + "." + c + ")");
        out.channels[c] = it->second;
        const auto v = img.channels.find(name + ".variance." + c);
        if (v != img.channels.end()) out.channels[std::string("variance.") + c] = v->second;
    }
    if (img.has("count")) out.channels["count"] = img.channels.at("count");
    return out;
}

std::array<std::vector<float>, 3> estimatorShape(const ExrImage& render, const std::string& role) {
    if (!hasRgb(render)) throw InputError(role + ": no R, G, B channels (it has: " + channelList(render) + ")");
    if (!render.has("count") || !render.has("variance.R") || !render.has("variance.G") || !render.has("variance.B"))
        throw InputError(role + ": an estimator's shape needs a render with variance layers and a count (what "
                         "`bdptref render` writes; it has: " + channelList(render) + ")");
    const std::vector<float>& count = render.channels.at("count");
    std::array<std::vector<float>, 3> shape;
    std::array<bool, 3> silent{};  // a channel with a mean but no variance (see below)
    for (size_t i = 0; i < count.size(); ++i) {
        float noisiest = std::numeric_limits<float>::quiet_NaN();
        for (int c = 0; c < 3; ++c) {
            const double n = count[i], mean = render.channels.at(kChannelNames[c])[i];
            const double var = std::max(0.0, double(render.channels.at(std::string("variance.") + kChannelNames[c])[i]));
            std::vector<float>& out = shape[size_t(c)];
            if (out.empty()) out.assign(count.size(), std::numeric_limits<float>::quiet_NaN());
            silent[size_t(c)] = false;
            if (!(n >= 2.0) || !std::isfinite(n) || !std::isfinite(mean) || !std::isfinite(var)) continue;
            if (mean == 0.0 && var == 0.0) continue;  // all samples 0: it may have missed every one
            out[i] = float(mean != 0.0 ? std::min((n - 1.0) * var / (mean * mean), n) : n);
            silent[size_t(c)] = var == 0.0;
            if (var > 0.0 && !(out[i] <= noisiest)) noisiest = out[i];
        }
        // The three channels come from the same paths: one with a mean and no variance while another
        // varies is a variance lost in storage (half floats read 0 below 6e-8: a dark pixel of a
        // heavy-tailed estimator read as smooth, docs/compare.md "The test's estimator shape"). It
        // gets the noisiest sibling's C, which can only make the test more conservative.
        for (int c = 0; c < 3; ++c)
            if (silent[size_t(c)] && std::isfinite(noisiest)) shape[size_t(c)][i] = noisiest;
    }
    return shape;
}

namespace {

// Whether v is exactly a 16-bit float (10 mantissa bits; subnormal below 2^-14 in steps of 2^-24).
bool exactInHalf(float v) {
    const double a = std::fabs(double(v));
    if (a == 0.0) return true;
    if (!(a <= 65504.0)) return false;
    if (a < std::ldexp(1.0, -14)) return std::ldexp(a, 24) == std::floor(std::ldexp(a, 24));
    int e = 0;
    const double m = std::ldexp(std::frexp(a, &e), 11);
    return m == std::floor(m);
}

}  // namespace

std::string halfVarianceWarning(const ExrImage& img, const std::string& role) {
    size_t values = 0, lost = 0;
    for (const char* c : kChannelNames) {
        const auto v = img.channels.find(std::string("variance.") + c);
        const auto m = img.channels.find(c);
        if (v == img.channels.end() || m == img.channels.end()) continue;
        for (size_t i = 0; i < v->second.size(); ++i) {
            const float var = v->second[i];
            if (!std::isfinite(var)) continue;
            if (!exactInHalf(var)) return "";  // a 32-bit variance: nothing lost
            values += var > 0.f;
            // A variance in the subnormal range keeps few bits; zero under a non-zero mean none.
            lost += (var > 0.f && var < std::ldexp(1.0f, -14)) || (var == 0.f && m->second[i] != 0.f);
        }
    }
    if (values < 16 || lost == 0) return "";
    return role + ": its variance layers are stored in 16-bit (half) floats: " + std::to_string(lost) +
           " variances are below 6.1e-5, where a half keeps few bits, or read 0 under a non-zero mean, so dark "
           "pixels look less noisy than they are and the test is too confident there; write the variances as "
           "32-bit floats (bdptref render does)";
}

// Every R, G, B value exactly zero.
static bool isBlack(const ExrImage& image) {
    for (int c = 0; c < 3; ++c)
        for (const float v : image.channels.at(kChannelNames[c]))
            if (v != 0.f) return false;
    return true;
}

ExrImage combineRenders(const std::vector<ExrImage>& renders, const std::vector<std::string>& names) {
    auto name = [&](size_t k) {
        return k < names.size() ? "test render " + names[k] : "test render " + std::to_string(k + 1);
    };
    const size_t n = renders.size();
    if (n < 2)
        throw InputError("combining renders: " + std::to_string(n) +
                         " given; the variance of the mean needs N >= 2 independent renders (different seeds)");
    for (size_t k = 0; k < n; ++k) {
        if (!hasRgb(renders[k]))
            throw InputError(name(k) + ": no R, G, B channels (it has: " + channelList(renders[k]) + ")");
        if (renders[k].width != renders[0].width || renders[k].height != renders[0].height ||
            renders[k].window != renders[0].window)
            throw InputError(name(k) + " is " + std::to_string(renders[k].width) + "x" +
                             std::to_string(renders[k].height) + " (data window " + renders[k].window.text() + "), " +
                             name(0) + " " + std::to_string(renders[0].width) + "x" +
                             std::to_string(renders[0].height) + " (data window " + renders[0].window.text() +
                             "): the renders must be the same image");
    }
    // Identical renders (the same seed) would give zero variance: every pixel would look exact.
    // Black renders are identical whatever the seed: a port that renders nothing is compared (and
    // fails wherever the reference has light), not refused as a seeding mistake.
    for (size_t a = 0; a < n; ++a)
        for (size_t b = a + 1; b < n; ++b) {
            bool same = true;
            for (int c = 0; c < 3 && same; ++c)
                same = renders[a].channels.at(kChannelNames[c]) == renders[b].channels.at(kChannelNames[c]);
            if (same && !isBlack(renders[a]))
                throw InputError(name(a) + " and " + name(b) +
                                 " are identical: the renders must be independent (render each with another seed)");
        }
    // Renders that share noise (seeds whose per-thread streams overlap) would look less noisy than
    // their mean is.
    std::vector<std::string> shortNames;
    for (size_t k = 0; k < n; ++k) shortNames.push_back(k < names.size() ? names[k] : std::to_string(k + 1));
    requireIndependentRenders(renders, shortNames);
    ExrImage out;
    out.width = renders[0].width;
    out.height = renders[0].height;
    out.window = renders[0].window;
    const size_t pixels = size_t(out.width) * size_t(out.height);
    const double N = double(n);
    for (int c = 0; c < 3; ++c) {
        std::vector<float>& mean = out.channels[kChannelNames[c]];
        std::vector<float>& var = out.channels[kVarianceNames[c]];
        mean.resize(pixels);
        var.resize(pixels);
        for (size_t i = 0; i < pixels; ++i) {
            // Two passes in double: the mean, then the squared deviations (no cancellation).
            double m = 0;
            for (size_t k = 0; k < n; ++k) m += double(renders[k].channels.at(kChannelNames[c])[i]);
            m /= N;
            double ss = 0;
            for (size_t k = 0; k < n; ++k) {
                const double d = double(renders[k].channels.at(kChannelNames[c])[i]) - m;
                ss += d * d;
            }
            mean[i] = float(m);
            var[i] = float(ss / (N - 1.0) / N);  // s^2 / N: the variance of the mean over the renders
        }
    }
    out.attributes[kRendersAttribute] = std::to_string(n);
    return out;
}

ExrImage readCompareInput(const std::string& path, const std::string& role) {
    if (!std::filesystem::exists(path)) throw InputError(role + " image " + path + ": no such file");
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char ch) { return char(std::tolower(ch)); });
    const std::string howTo =
        ": compare needs linear radiance as floats; write a float EXR (half or 32-bit, linear, no tone mapping or "
        "sRGB curve) or PFM from the renderer, and N >= 2 of them with different seeds when it cannot write "
        "variance layers (docs/compare.md, 'Inputs')";
    for (const char* display : {".png", ".jpg", ".jpeg", ".bmp", ".gif", ".tga", ".ppm", ".pgm", ".webp"})
        if (ext == display)
            throw InputError(role + " image " + path + " is a " + ext.substr(1) +
                             " file, an 8-bit display-encoded (tone-mapped, sRGB) picture" + howTo);
    ExrImage img = readImage(path);
    if (ext == ".exr" || ext == ".pfm" || ext == ".hdr" || !hasRgb(img)) return img;
    // Other formats (TIFF, ...): the reader reports values as float whatever the file's encoding, so
    // an integer encoding is recognised by its values: all on the grid k / 255 (or k / 65535) in
    // [0, 1]. A float render is on such a grid only if it is constant or tiny.
    for (const double levels : {255.0, 65535.0}) {
        bool onGrid = true, varied = false;
        const float first = img.channels.at("R").empty() ? 0.f : img.channels.at("R")[0];
        for (int c = 0; c < 3 && onGrid; ++c)
            for (const float v : img.channels.at(kChannelNames[c])) {
                const double q = double(v) * levels;
                if (!(v >= 0.f && v <= 1.f) || std::abs(q - std::round(q)) > 1e-3) {
                    onGrid = false;
                    break;
                }
                varied = varied || v != first;
            }
        if (onGrid && varied)
            throw InputError(role + " image " + path + " holds " + (levels == 255.0 ? "8" : "16") +
                             "-bit integer values (every value is a multiple of 1/" + std::to_string(int(levels)) +
                             "), a display encoding" + howTo);
    }
    return img;
}

void requireTestStatistics(const ExrImage& test, const std::string& path) {
    if (!hasRgb(test)) throw InputError("test image " + path + ": no R, G, B channels (it has: " + channelList(test) + ")");
    if (hasVariance(test) || rendersOf(test) >= 2) return;
    throw InputError(
        "test image " + path + " has only " + channelList(test) +
        ": one render without variance layers cannot be told apart from its Monte Carlo noise (it would be taken as "
        "exact and fail at any sample count). Either write variance.R, variance.G, variance.B (the variance of the "
        "pixel mean, s^2/n) and count (samples per pixel) as bdptref does, or give N >= 2 independent renders "
        "rendered with different seeds: bdptref compare T1.exr T2.exr ... TN.exr REF.exr (the last file is the "
        "reference; docs/compare.md)");
}

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
