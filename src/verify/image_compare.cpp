// Statistical image comparison (include/bdptref/image_compare.h; the statistics are derived and
// discussed in docs/compare.md).
#include "bdptref/image_compare.h"
#include "bdptref/exr_io.h"

#include "bdptref/errors.h"

#include <OpenImageIO/imageio.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <numeric>
#include <sstream>
#include <unistd.h>

namespace bdptref {

// ============================================================================================
// distributions
// ============================================================================================

namespace stats {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kPiD = 3.14159265358979323846;

// log B(a, b) = lgamma(a) + lgamma(b) - lgamma(a + b). std::lgamma may write the global signgam;
// the comparison calls it from one thread only.
double logBeta(double a, double b) { return std::lgamma(a) + std::lgamma(b) - std::lgamma(a + b); }

// Continued fraction of I_x(a, b) (modified Lentz; Numerical Recipes 3rd ed., section 6.4); it
// converges quickly for x < (a + 1) / (a + b + 2).
double betaContinuedFraction(double a, double b, double x) {
    const double tiny = 1e-300;
    const double qab = a + b, qap = a + 1.0, qam = a - 1.0;
    double c = 1.0, d = 1.0 - qab * x / qap;
    if (std::abs(d) < tiny) d = tiny;
    d = 1.0 / d;
    double h = d;
    for (int m = 1; m < 200000; ++m) {
        const double m2 = 2.0 * m;
        double aa = m * (b - m) * x / ((qam + m2) * (a + m2));
        d = 1.0 + aa * d;
        if (std::abs(d) < tiny) d = tiny;
        c = 1.0 + aa / c;
        if (std::abs(c) < tiny) c = tiny;
        d = 1.0 / d;
        h *= d * c;
        aa = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2));
        d = 1.0 + aa * d;
        if (std::abs(d) < tiny) d = tiny;
        c = 1.0 + aa / c;
        if (std::abs(c) < tiny) c = tiny;
        d = 1.0 / d;
        const double del = d * c;
        h *= del;
        if (std::abs(del - 1.0) < 1e-15) break;
    }
    return h;
}

// I_x(a, b) with y = 1 - x passed separately (exact when x is close to 1).
double betaI(double a, double b, double x, double y) {
    if (!(a > 0.0) || !(b > 0.0) || std::isnan(x) || std::isnan(y)) return std::numeric_limits<double>::quiet_NaN();
    if (x <= 0.0) return 0.0;
    if (y <= 0.0) return 1.0;
    const double logFront = a * std::log(x) + b * std::log(y) - logBeta(a, b);
    if (x < (a + 1.0) / (a + b + 2.0)) return std::exp(logFront) * betaContinuedFraction(a, b, x) / a;
    return 1.0 - std::exp(logFront) * betaContinuedFraction(b, a, y) / b;
}

}  // namespace

double regularizedIncompleteBeta(double a, double b, double x) {
    x = std::clamp(x, 0.0, 1.0);
    return std::clamp(betaI(a, b, x, 1.0 - x), 0.0, 1.0);
}

double normalTwoSidedP(double z) {
    if (std::isnan(z)) return std::numeric_limits<double>::quiet_NaN();
    return std::erfc(std::abs(z) / std::sqrt(2.0));
}

double studentTTwoSidedP(double t, double dof) {
    if (std::isnan(t) || !(dof > 0.0)) return std::numeric_limits<double>::quiet_NaN();
    if (std::isinf(t)) return 0.0;
    // Beyond 1e5 degrees of freedom Student's t and the normal differ by < 1e-3 relative in the
    // two-sided tail up to |t| = 6, and the continued fraction would need ~sqrt(dof) terms.
    if (dof > 1e5) return normalTwoSidedP(t);
    const double t2 = t * t;
    // P(|T| >= |t|) = I_{nu / (nu + t^2)}(nu / 2, 1 / 2), both arguments without cancellation.
    return std::clamp(betaI(0.5 * dof, 0.5, dof / (dof + t2), t2 / (dof + t2)), 0.0, 1.0);
}

double normalQuantile(double p) {
    if (std::isnan(p) || p < 0.0 || p > 1.0) return std::numeric_limits<double>::quiet_NaN();
    if (p == 0.0) return -kInf;
    if (p == 1.0) return kInf;
    // Acklam's rational approximation (relative error < 1.2e-9) and one Halley step on erfc.
    static const double a[6] = {-3.969683028665376e+01, 2.209460984245205e+02, -2.759285104469687e+02,
                                1.383577518672690e+02,  -3.066479806614716e+01, 2.506628277459239e+00};
    static const double b[5] = {-5.447609879822406e+01, 1.615858368580409e+02, -1.556989798598866e+02,
                                6.680131188771972e+01,  -1.328068155288572e+01};
    static const double c[6] = {-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e+00,
                                -2.549732539343734e+00, 4.374664141464968e+00,  2.938163982698783e+00};
    static const double d[4] = {7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e+00,
                                3.754408661907416e+00};
    const double pLow = 0.02425;
    double x;
    if (p < pLow) {
        const double q = std::sqrt(-2.0 * std::log(p));
        x = (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
            ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1.0);
    } else if (p <= 1.0 - pLow) {
        const double q = p - 0.5, r = q * q;
        x = (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
            (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1.0);
    } else {
        const double q = std::sqrt(-2.0 * std::log1p(-p));
        x = -(((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
            ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1.0);
    }
    // Halley refinement: e = Phi(x) - p, computed on the side where it does not cancel.
    const double e = x < 0 ? 0.5 * std::erfc(-x / std::sqrt(2.0)) - p : (1.0 - p) - 0.5 * std::erfc(x / std::sqrt(2.0));
    const double u = e * std::sqrt(2.0 * kPiD) * std::exp(0.5 * x * x);
    const double refined = x - u / (1.0 + 0.5 * x * u);
    return std::isfinite(refined) ? refined : x;
}

double zFromTwoSidedP(double p) {
    if (std::isnan(p)) return std::numeric_limits<double>::quiet_NaN();
    if (p <= 0.0) return 40.0;  // beyond any double-precision p-value (p(40) ~ 1e-350)
    if (p >= 1.0) return 0.0;
    return -normalQuantile(0.5 * p);
}

double sidak(double p, double m) {
    if (std::isnan(p)) return p;
    if (p <= 0.0) return 0.0;
    if (p >= 1.0 || m <= 0.0) return std::min(1.0, std::max(0.0, p));
    return std::min(1.0, -std::expm1(m * std::log1p(-p)));
}

double cauchyCombination(const double* p, int k) {
    if (k <= 0) return 1.0;
    if (k == 1) return p[0];
    for (int i = 0; i < k; ++i)
        if (p[i] <= 0.0) return 0.0;  // a p-value of exactly 0 (underflow) decides
    // T = sum w_i tan((1/2 - p_i) pi), w_i = 1/k; p = 1/2 - atan(T) / pi. For small p_i,
    // tan((1/2 - p) pi) = 1 / tan(p pi); for large T, 1/2 - atan(T)/pi = atan(1/T)/pi.
    double T = 0.0;
    for (int i = 0; i < k; ++i) {
        const double pi = std::clamp(p[i], 1e-300, 1.0 - 1e-16);
        T += (pi < 1e-15 ? 1.0 / (pi * kPiD) : 1.0 / std::tan(pi * kPiD)) / double(k);
    }
    if (T > 1e15) return std::min(1.0, 1.0 / (T * kPiD));
    if (T > 0) return std::atan(1.0 / T) / kPiD;
    return std::clamp(0.5 - std::atan(T) / kPiD, 0.0, 1.0);
}

}  // namespace stats

// ============================================================================================
// helpers
// ============================================================================================

namespace {

namespace fs = std::filesystem;

const char* kChannelNames[3] = {"R", "G", "B"};
const char* kVarianceNames[3] = {"variance.R", "variance.G", "variance.B"};

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

std::string fmtG(double v, int digits = 4) {
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

// Channel test of one pixel.
struct ChannelTest {
    enum Kind : uint8_t { None, Tested, Equal, Unequal, LowEffective } kind = None;
    double p = 1.0, stat = 0.0, var = 0.0, floorSd = 0.0;  // p-value, t statistic, variance of t - r
                                                          // (without the floor), precision floor
};

}  // namespace

int biasTileSize(int regionWidth, int regionHeight) {
    const double m = double(regionWidth) * double(regionHeight);
    return std::max(4, int(std::ceil(std::sqrt(m / 64.0))));
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

// ============================================================================================
// the comparison
// ============================================================================================

CompareResult compareImages(const ExrImage& test, const ExrImage& ref, const CompareOptions& options) {
    if (!hasRgb(test)) throw InputError("test image: no R, G, B channels (it has: " + channelList(test) + ")");
    if (!hasRgb(ref)) throw InputError("reference image: no R, G, B channels (it has: " + channelList(ref) + ")");
    if (test.width != ref.width || test.height != ref.height)
        throw InputError("the images differ in size: test " + std::to_string(test.width) + "x" +
                         std::to_string(test.height) + ", reference " + std::to_string(ref.width) + "x" +
                         std::to_string(ref.height));
    if (test.width < 1 || test.height < 1) throw InputError("the images are empty");
    if (!(options.alpha > 0.0 && options.alpha < 1.0)) throw InputError("--alpha must be in (0, 1)");
    if (!(options.epsilon > 0.0) || !std::isfinite(options.epsilon)) throw InputError("--epsilon must be > 0");
    if (!(options.minEffectiveSamples >= 0.0)) throw InputError("the minimum effective sample count must be >= 0");
    if (!(options.precision >= 0.0 && options.precision < 1.0)) throw InputError("the precision must be in [0, 1)");
    if (options.tileSize < 1) throw InputError("the tile size must be >= 1");

    const int W = test.width, H = test.height;
    const size_t N = size_t(W) * size_t(H);
    CompareResult r;
    r.width = W;
    r.height = H;
    r.options = options;
    r.region = PixelRegion{0, 0, W, H};
    if (options.useRegion) {
        const PixelRegion& g = options.region;
        if (g.x < 0 || g.y < 0 || g.width < 1 || g.height < 1 || int64_t(g.x) + g.width > W ||
            int64_t(g.y) + g.height > H)
            throw InputError("--region " + std::to_string(g.x) + "," + std::to_string(g.y) + "," +
                             std::to_string(g.width) + "," + std::to_string(g.height) + " is not inside the " +
                             std::to_string(W) + "x" + std::to_string(H) + " image");
        r.region = g;
    }
    if (!options.mask.empty() && options.mask.size() != N)
        throw InputError("the mask has " + std::to_string(options.mask.size()) + " pixels, the images " +
                         std::to_string(N));

    const bool tVar = hasVariance(test), rVar = hasVariance(ref);
    r.testHasCount = test.has("count");
    r.refHasCount = ref.has("count");
    r.kind = tVar && rVar ? TestKind::Welch : rVar ? TestKind::RefVariance : tVar ? TestKind::TestVariance : TestKind::None;
    r.biasFromVariances = r.kind != TestKind::None;

    const std::vector<float>* tm[3];
    const std::vector<float>* rm[3];
    const std::vector<float>* tv[3] = {nullptr, nullptr, nullptr};
    const std::vector<float>* rv[3] = {nullptr, nullptr, nullptr};
    for (int c = 0; c < 3; ++c) {
        tm[c] = &test.channels.at(kChannelNames[c]);
        rm[c] = &ref.channels.at(kChannelNames[c]);
        if (tVar) tv[c] = &test.channels.at(kVarianceNames[c]);
        if (rVar) rv[c] = &ref.channels.at(kVarianceNames[c]);
    }
    const std::vector<float>* tn = r.testHasCount ? &test.channels.at("count") : nullptr;
    const std::vector<float>* rn = r.refHasCount ? &ref.channels.at("count") : nullptr;
    const bool useTestVar = r.kind == TestKind::Welch || r.kind == TestKind::TestVariance;
    const bool useRefVar = r.kind == TestKind::Welch || r.kind == TestKind::RefVariance;

    r.status.assign(N, PixelStatus::Outside);
    r.pixelP.assign(N, std::numeric_limits<float>::quiet_NaN());
    r.pixelZ.assign(N, std::numeric_limits<float>::quiet_NaN());
    r.relError.assign(N, std::numeric_limits<float>::quiet_NaN());
    r.isFlagged.assign(N, 0);
    std::vector<double> pixelPd(N, 1.0);  // double-precision pixel p-values (tested pixels)

    // Bias test and metric accumulators (double, in pixel order: deterministic).
    // Per channel: t - r and the variance of t - r of every t-tested pixel (NaN elsewhere).
    // The variance excludes the precision floor, kept apart as a standard deviation: rounding may
    // be systematic, so the bias test adds the floors of many pixels linearly, not in quadrature.
    std::array<std::vector<double>, 3> diff, diffVar, diffFloor;
    for (int c = 0; c < 3; ++c) {
        diff[size_t(c)].assign(N, std::numeric_limits<double>::quiet_NaN());
        diffVar[size_t(c)].assign(N, std::numeric_limits<double>::quiet_NaN());
        diffFloor[size_t(c)].assign(N, 0.0);
    }
    struct Acc {
        double se = 0, rel = 0, ae = 0, sumT = 0, sumR = 0, sumD = 0, sumD2 = 0, sumV = 0, maxAbs = -1;
        int maxX = -1, maxY = -1;
    };
    std::array<Acc, 3> acc;
    double sumMeanD = 0, sumMeanD2 = 0;  // channel-averaged differences (spread CI of the overall bias)
    const double eps = options.epsilon, thr = options.minEffectiveSamples;

    // The test/reference ratio of per-sample variances, per channel: the median over the pixels
    // where both images have a variance (1 when none). With equal estimators it is near 1.
    const bool pooled = r.kind == TestKind::Welch && tn && rn;
    r.varianceRatio = {1.0, 1.0, 1.0};
    if (pooled) {
        std::vector<double> ratios;
        for (int c = 0; c < 3; ++c) {
            ratios.clear();
            for (int y = r.region.y; y < r.region.y + r.region.height; ++y)
                for (int x = r.region.x; x < r.region.x + r.region.width; ++x) {
                    const size_t i = size_t(y) * size_t(W) + size_t(x);
                    if (!options.mask.empty() && !options.mask[i]) continue;
                    const double nT = (*tn)[i], nR = (*rn)[i], va = (*tv[c])[i], vb = (*rv[c])[i];
                    if (nT >= 2 && nR >= 2 && va > 0 && vb > 0 && std::isfinite(va) && std::isfinite(vb))
                        ratios.push_back((nT * va) / (nR * vb));
                }
            if (!ratios.empty()) {
                std::nth_element(ratios.begin(), ratios.begin() + long(ratios.size() / 2), ratios.end());
                const double med = ratios[ratios.size() / 2];
                if (med > 0 && std::isfinite(med)) r.varianceRatio[size_t(c)] = med;
            }
        }
    }

    for (int y = r.region.y; y < r.region.y + r.region.height; ++y)
        for (int x = r.region.x; x < r.region.x + r.region.width; ++x) {
            const size_t i = size_t(y) * size_t(W) + size_t(x);
            if (!options.mask.empty() && !options.mask[i]) continue;
            ++r.compared;
            double tvals[3], rvals[3], vt[3] = {0, 0, 0}, vr[3] = {0, 0, 0};
            bool finite = true;
            for (int c = 0; c < 3; ++c) {
                tvals[c] = (*tm[c])[i];
                rvals[c] = (*rm[c])[i];
                if (useTestVar) vt[c] = (*tv[c])[i];
                if (useRefVar) vr[c] = (*rv[c])[i];
                finite = finite && std::isfinite(tvals[c]) && std::isfinite(rvals[c]) && std::isfinite(vt[c]) &&
                         std::isfinite(vr[c]);
                vt[c] = std::max(0.0, vt[c]);  // a negative variance (rounding in a writer) is 0
                vr[c] = std::max(0.0, vr[c]);
            }
            if (!finite) {
                r.status[i] = PixelStatus::NonFinite;
                ++r.nonFinite;
                continue;
            }
            // metrics
            ++r.metricPixels;
            double meanD = 0, rel = 0;
            for (int c = 0; c < 3; ++c) {
                const double d = tvals[c] - rvals[c];
                Acc& a = acc[size_t(c)];
                a.se += d * d;
                a.rel += d * d / (rvals[c] * rvals[c] + eps);
                a.ae += std::abs(d);
                a.sumT += tvals[c];
                a.sumR += rvals[c];
                a.sumD += d;
                a.sumD2 += d * d;
                a.sumV += vt[c] + vr[c];
                if (std::abs(d) > a.maxAbs) {
                    a.maxAbs = std::abs(d);
                    a.maxX = x;
                    a.maxY = y;
                }
                meanD += d / 3.0;
                rel += d / std::sqrt(rvals[c] * rvals[c] + eps) / 3.0;
            }
            sumMeanD += meanD;
            sumMeanD2 += meanD * meanD;
            r.relError[i] = float(rel);

            if (r.kind == TestKind::None) {
                r.status[i] = PixelStatus::NoVariance;
                continue;
            }
            // sample counts (infinity when the image has no count layer)
            const double nT = tn ? double((*tn)[i]) : std::numeric_limits<double>::infinity();
            const double nR = rn ? double((*rn)[i]) : std::numeric_limits<double>::infinity();
            const bool fewT = useTestVar && tn && !(nT >= 2.0);
            const bool fewR = useRefVar && rn && !(nR >= 2.0);
            if (fewT || fewR) {
                r.status[i] = PixelStatus::FewSamples;
                ++r.fewSamples;
                continue;
            }
            ChannelTest ct[3];
            for (int c = 0; c < 3; ++c) {
                ChannelTest& o = ct[c];
                const double a = tvals[c], b = rvals[c], va = vt[c], vb = vr[c];
                const double scale = std::max(std::abs(a), std::abs(b));
                if (va == 0.0 && vb == 0.0) {
                    const double tol = options.precision * scale;
                    o.kind = std::abs(a - b) <= tol ? ChannelTest::Equal : ChannelTest::Unequal;
                    continue;
                }
                if (thr > 0.0) {
                    double effA = std::numeric_limits<double>::infinity(), effB = effA;
                    if (r.kind == TestKind::Welch && tn && rn) {
                        // Expected effective samples of each image under H0, from the pooled
                        // first and second moments of the two sample sets.
                        const double s1 = nT * a + nR * b;
                        const double s2 = nT * ((nT - 1.0) * va + a * a) + nR * ((nR - 1.0) * vb + b * b);
                        const double mu = s1 / (nT + nR), q = s2 / (nT + nR);
                        effA = q > 0 ? nT * mu * mu / q : 0.0;
                        effB = q > 0 ? nR * mu * mu / q : 0.0;
                    } else if (r.kind == TestKind::Welch) {
                        const double mu = 0.5 * (a + b);
                        effA = effectiveSamples(nT, mu, va);
                        effB = effectiveSamples(nR, mu, vb);
                    } else if (r.kind == TestKind::RefVariance) {
                        effB = effectiveSamples(nR, b, vb);
                    } else {
                        effA = effectiveSamples(nT, a, va);
                    }
                    if (std::min(effA, effB) < thr) {
                        o.kind = ChannelTest::LowEffective;
                        continue;
                    }
                }
                // Welch: V = va + vb with the Welch-Satterthwaite degrees of freedom; an image without
                // counts or without variance contributes no term (its n is taken as infinite / it is
                // exact).
                double v = va + vb;
                double den = 0.0;
                if (va > 0 && std::isfinite(nT)) den += va * va / (nT - 1.0);
                if (vb > 0 && std::isfinite(nR)) den += vb * vb / (nR - 1.0);
                double dof = den > 0 ? v * v / den : std::numeric_limits<double>::infinity();
                // Guard against a variance estimate that is low because the mean is low (a skewed
                // pixel estimator that missed its rare large samples; docs/compare.md): the variance
                // of t - r under H0 is at least what the per-sample variances pooled from both
                // images give, with the test/reference ratio rho of the whole image.
                if (pooled) {
                    const double rho = r.varianceRatio[size_t(c)];
                    const double sp2 = ((nR - 1.0) * nR * vb + (nT - 1.0) * nT * va / rho) / (nT + nR - 2.0);
                    const double vPooled = sp2 * (rho / nT + 1.0 / nR);
                    if (vPooled > v) {
                        v = vPooled;
                        dof = nT + nR - 2.0;
                        ++r.pooledChannels;
                    }
                }
                // The precision floor: differences below precision * |value| are float rounding
                // (32-bit storage, float accumulation in the renderer), not Monte Carlo noise.
                o.floorSd = options.precision * scale;
                o.var = v;
                o.stat = (a - b) / std::sqrt(v + o.floorSd * o.floorSd);
                o.p = stats::studentTTwoSidedP(o.stat, dof);
                o.kind = ChannelTest::Tested;
                ++r.testedChannels;
            }
            int nTested = 0, nLow = 0, nUnequal = 0;
            double ps[3];
            double bestP = 2.0, bestStat = 0.0;
            for (int c = 0; c < 3; ++c) {
                if (ct[c].kind == ChannelTest::Tested) {
                    ps[nTested++] = ct[c].p;
                    if (ct[c].p < bestP) {
                        bestP = ct[c].p;
                        bestStat = ct[c].stat;
                    }
                }
                nLow += ct[c].kind == ChannelTest::LowEffective;
                nUnequal += ct[c].kind == ChannelTest::Unequal;
            }
            r.lowEffectiveChannels += uint64_t(nLow);
            if (nUnequal > 0) {
                r.status[i] = PixelStatus::Unequal;
                ++r.unequal;
                r.pixelP[i] = 0.f;
                double dsum = 0;
                for (int c = 0; c < 3; ++c) dsum += tvals[c] - rvals[c];
                r.pixelZ[i] = float(dsum >= 0 ? 40.0 : -40.0);
                continue;
            }
            if (nTested == 0) {
                r.status[i] = nLow > 0 ? PixelStatus::LowEffective : PixelStatus::Equal;
                if (nLow > 0) ++r.lowEffective;
                else {
                    ++r.equal;
                    r.pixelZ[i] = 0.f;
                }
                continue;
            }
            r.status[i] = PixelStatus::Tested;
            ++r.tested;
            const double p = stats::cauchyCombination(ps, nTested);
            pixelPd[i] = p;
            r.pixelP[i] = float(p);
            const double z = stats::zFromTwoSidedP(p);
            r.pixelZ[i] = float(bestStat >= 0 ? z : -z);
            for (int c = 0; c < 3; ++c)
                if (ct[c].kind == ChannelTest::Tested) {
                    diff[size_t(c)][i] = tvals[c] - rvals[c];
                    diffVar[size_t(c)][i] = ct[c].var;
                    diffFloor[size_t(c)][i] = ct[c].floorSd;
                }
            if (p < r.pMin || r.pMinX < 0) {
                r.pMin = p;
                r.pMinX = x;
                r.pMinY = y;
            }
        }

    if (r.compared == 0) throw InputError("the region and the mask leave no pixel to compare");

    // ---- metrics ----
    const double np = double(r.metricPixels);
    const double z95 = 1.959963984540054;
    if (r.metricPixels > 0) {
        double overallSe = 0;
        for (int c = 0; c < 3; ++c) {
            const Acc& a = acc[size_t(c)];
            ChannelMetrics& m = r.channel[size_t(c)];
            m.mse = a.se / np;
            m.rmse = std::sqrt(m.mse);
            m.relMse = a.rel / np;
            m.mae = a.ae / np;
            m.maxAbs = std::max(0.0, a.maxAbs);
            m.maxX = a.maxX;
            m.maxY = a.maxY;
            m.meanTest = a.sumT / np;
            m.meanRef = a.sumR / np;
            m.bias = a.sumD / np;
            double se;
            if (r.biasFromVariances) se = std::sqrt(a.sumV) / np;
            else se = np > 1 ? std::sqrt(std::max(0.0, (a.sumD2 - a.sumD * a.sumD / np) / (np - 1.0)) / np) : 0.0;
            overallSe += se / 3.0;
            m.biasLow = m.bias - z95 * se;
            m.biasHigh = m.bias + z95 * se;
            m.relativeBias = m.meanRef != 0 ? m.bias / m.meanRef : 0.0;
            r.overall.mse += m.mse / 3.0;
            r.overall.relMse += m.relMse / 3.0;
            r.overall.mae += m.mae / 3.0;
            r.overall.meanTest += m.meanTest / 3.0;
            r.overall.meanRef += m.meanRef / 3.0;
            r.overall.bias += m.bias / 3.0;
            if (m.maxAbs > r.overall.maxAbs || r.overall.maxChannel < 0) {
                r.overall.maxAbs = m.maxAbs;
                r.overall.maxX = m.maxX;
                r.overall.maxY = m.maxY;
                r.overall.maxChannel = c;
            }
        }
        r.overall.rmse = std::sqrt(r.overall.mse);
        // Overall bias CI: with variances, the channels' standard errors are added (the channels
        // are correlated by an unknown amount; adding is the perfectly-correlated upper bound);
        // without, the spread of the channel-averaged differences, which includes the correlation.
        double se = overallSe;
        if (!r.biasFromVariances)
            se = np > 1 ? std::sqrt(std::max(0.0, (sumMeanD2 - sumMeanD * sumMeanD / np) / (np - 1.0)) / np) : 0.0;
        r.overall.biasLow = r.overall.bias - z95 * se;
        r.overall.biasHigh = r.overall.bias + z95 * se;
        r.overall.relativeBias = r.overall.meanRef != 0 ? r.overall.bias / r.overall.meanRef : 0.0;
    }

    // ---- tests ----
    const double alpha = options.alpha;
    if (r.kind == TestKind::None) {
        r.hasVerdict = false;
        r.noVerdictReason = "neither image has variance layers (variance.R, variance.G, variance.B)";
    } else if (r.tested + r.equal + r.unequal + r.nonFinite == 0) {
        r.hasVerdict = false;
        r.noVerdictReason = "no pixel could be tested (" + std::to_string(r.fewSamples) + " with count < 2, " +
                            std::to_string(r.lowEffective) + " with fewer than " + fmtG(thr) +
                            " effective samples): render more samples";
    } else {
        r.hasVerdict = true;
    }
    if (r.tested > 0) {
        r.pLocal = stats::sidak(r.pMin, double(r.tested));
        // Bias test, per channel: the region is cut into about 64 square tiles (side >= 4); tile T
        // has D_T = sum(t - r), V_T = sum V (the variance of t - r) and F_T = sum of the precision
        // floors over its t-tested pixels, and
        //     Z = sum_T w_T D_T / sqrt(sum_T w_T^2 V_T + (sum_T w_T F_T)^2),  w_T = 1 / sqrt(V_T + F_T^2):
        // Stouffer's combination of the tiles' z-scores D_T / sqrt(V_T) when the floors are
        // negligible, while a systematic difference at the precision floor stays below |Z| = 1.
        // Within a tile the sum runs over many pixels x samples, so D_T is close to normal and its
        // studentisation bias (for skewed pixel estimators) is small; across tiles, every tile has
        // about the same weight, so a few very noisy pixels (fireflies, light edges) only silence
        // their own tile instead of the whole test. docs/compare.md discusses the choice.
        r.biasTile = biasTileSize(r.region.width, r.region.height);
        const int bt = r.biasTile;
        double pc[3];
        int k = 0;
        for (int c = 0; c < 3; ++c) {
            const std::vector<double>& d = diff[size_t(c)];
            const std::vector<double>& V = diffVar[size_t(c)];
            const std::vector<double>& F = diffFloor[size_t(c)];
            double num = 0, noise = 0, floorSum = 0, sumWr = 0;
            int tiles = 0;
            for (int ty = r.region.y; ty < r.region.y + r.region.height; ty += bt)
                for (int tx = r.region.x; tx < r.region.x + r.region.width; tx += bt) {
                    double D = 0, VT = 0, FT = 0, R = 0;
                    for (int y = ty; y < std::min(ty + bt, r.region.y + r.region.height); ++y)
                        for (int x = tx; x < std::min(tx + bt, r.region.x + r.region.width); ++x) {
                            const size_t i = size_t(y) * size_t(W) + size_t(x);
                            if (std::isnan(d[i])) continue;
                            D += d[i];
                            VT += V[i];
                            FT += F[i];
                            R += double((*rm[c])[i]);
                        }
                    const double total = VT + FT * FT;
                    if (!(total > 0)) continue;
                    const double w = 1.0 / std::sqrt(total);
                    num += w * D;
                    noise += w * w * VT;
                    floorSum += w * FT;
                    sumWr += w * R;
                    ++tiles;
                }
            const double den = std::sqrt(noise + floorSum * floorSum);
            if (tiles > 0 && den > 0) {
                r.biasZ[size_t(c)] = num / den;
                r.weightedRelativeBias[size_t(c)] = sumWr != 0 ? num / sumWr : 0.0;
                r.weightedRelativeBiasSigma[size_t(c)] = sumWr != 0 ? den / std::abs(sumWr) : 0.0;
                r.biasTiles = std::max(r.biasTiles, tiles);
                pc[k++] = stats::normalTwoSidedP(r.biasZ[size_t(c)]);
            }
        }
        r.pBias = stats::cauchyCombination(pc, k);
        r.pGlobal = stats::sidak(std::min(r.pLocal, r.pBias), 2.0);
        // The |z| at which one pixel alone makes the global test reject.
        const double twoTestLevel = -std::expm1(0.5 * std::log1p(-alpha));  // 1 - (1 - alpha)^(1/2)
        const double pixelLevel = -std::expm1(std::log1p(-twoTestLevel) / double(r.tested));
        r.zThreshold = stats::zFromTwoSidedP(pixelLevel);
    }
    if (r.unequal > 0 || r.nonFinite > 0) r.pGlobal = 0.0;
    r.consistent = !r.hasVerdict || (r.pGlobal >= alpha && r.unequal == 0 && r.nonFinite == 0);

    // ---- flagged pixels: Benjamini-Hochberg at FDR alpha over the tested pixels ----
    {
        std::vector<std::pair<double, size_t>> tp;
        tp.reserve(size_t(r.tested));
        for (size_t i = 0; i < N; ++i)
            if (r.status[i] == PixelStatus::Tested) tp.emplace_back(pixelPd[i], i);
        std::sort(tp.begin(), tp.end());
        const double m = double(tp.size());
        size_t k = 0;
        for (size_t j = tp.size(); j > 0; --j)
            if (tp[j - 1].first <= double(j) * alpha / m) {
                k = j;
                break;
            }
        for (size_t j = 0; j < k; ++j) r.isFlagged[tp[j].second] = 1;
        r.bhThreshold = k > 0 ? tp[k - 1].first : 0.0;
        for (size_t i = 0; i < N; ++i)
            if (r.status[i] == PixelStatus::Unequal || r.status[i] == PixelStatus::NonFinite) r.isFlagged[i] = 1;

        // the most significant pixels: hard failures first, then the smallest p-values
        std::vector<size_t> order;
        for (size_t i = 0; i < N && order.size() < 10; ++i)
            if (r.status[i] == PixelStatus::Unequal || r.status[i] == PixelStatus::NonFinite) order.push_back(i);
        for (size_t j = 0; j < tp.size() && order.size() < 10; ++j) order.push_back(tp[j].second);
        for (size_t i : order) {
            FlaggedPixel f;
            f.x = int(i % size_t(W));
            f.y = int(i / size_t(W));
            f.status = r.status[i];
            f.p = r.status[i] == PixelStatus::Tested ? pixelPd[i] : 0.0;
            f.z = double(r.pixelZ[i]);
            for (int c = 0; c < 3; ++c) {
                f.test[size_t(c)] = (*tm[c])[i];
                f.ref[size_t(c)] = (*rm[c])[i];
                f.testSigma[size_t(c)] = useTestVar ? std::sqrt(std::max(0.f, (*tv[c])[i])) : 0.0;
                f.refSigma[size_t(c)] = useRefVar ? std::sqrt(std::max(0.f, (*rv[c])[i])) : 0.0;
            }
            r.worst.push_back(f);
        }
    }

    // ---- where: bounding box of the flagged pixels and the worst region ----
    {
        const int ts = options.tileSize;
        const int tilesX = (r.region.width + ts - 1) / ts, tilesY = (r.region.height + ts - 1) / ts;
        std::vector<uint64_t> tileCount(size_t(tilesX) * size_t(tilesY), 0);
        r.boxX0 = W;
        r.boxY0 = H;
        for (int y = r.region.y; y < r.region.y + r.region.height; ++y)
            for (int x = r.region.x; x < r.region.x + r.region.width; ++x) {
                const size_t i = size_t(y) * size_t(W) + size_t(x);
                if (!r.isFlagged[i]) continue;
                ++r.flagged;
                r.boxX0 = std::min(r.boxX0, x);
                r.boxY0 = std::min(r.boxY0, y);
                r.boxX1 = std::max(r.boxX1, x);
                r.boxY1 = std::max(r.boxY1, y);
                ++tileCount[size_t((y - r.region.y) / ts) * size_t(tilesX) + size_t((x - r.region.x) / ts)];
            }
        if (r.flagged == 0) {
            r.boxX0 = r.boxY0 = 0;
        } else {
            // The worst region: the bounding box of all flagged pixels when it is compact (at most
            // two tiles across each way and a quarter of the region), else the tile holding the
            // most flagged pixels.
            const double boxArea = double(r.boxX1 - r.boxX0 + 1) * double(r.boxY1 - r.boxY0 + 1);
            if (r.boxX1 - r.boxX0 < 2 * ts && r.boxY1 - r.boxY0 < 2 * ts &&
                boxArea <= 0.25 * double(r.region.width) * double(r.region.height)) {
                r.worstX0 = r.boxX0;
                r.worstY0 = r.boxY0;
                r.worstX1 = r.boxX1;
                r.worstY1 = r.boxY1;
                r.worstFlagged = r.flagged;
                r.worstIsBoundingBox = true;
            } else {
                size_t best = 0;
                for (size_t t = 1; t < tileCount.size(); ++t)
                    if (tileCount[t] > tileCount[best]) best = t;
                r.worstFlagged = tileCount[best];
                r.worstX0 = r.region.x + int(best % size_t(tilesX)) * ts;
                r.worstY0 = r.region.y + int(best / size_t(tilesX)) * ts;
                r.worstX1 = std::min(r.worstX0 + ts, r.region.x + r.region.width) - 1;
                r.worstY1 = std::min(r.worstY0 + ts, r.region.y + r.region.height) - 1;
            }
            // Its relative bias: the median over its compared pixels of sum_c(t - r) / sum_c r, the
            // relative error of a typical pixel (a sum over the region would be ruled by its
            // brightest or noisiest pixels).
            std::vector<double> rel;
            for (int y = r.worstY0; y <= r.worstY1; ++y)
                for (int x = r.worstX0; x <= r.worstX1; ++x) {
                    const size_t i = size_t(y) * size_t(W) + size_t(x);
                    if (r.status[i] == PixelStatus::Outside || r.status[i] == PixelStatus::NonFinite) continue;
                    double sd = 0, sr = 0;
                    for (int c = 0; c < 3; ++c) {
                        sd += double((*tm[c])[i]) - double((*rm[c])[i]);
                        sr += double((*rm[c])[i]);
                    }
                    if (sr > 0) rel.push_back(sd / sr);
                }
            if (!rel.empty()) {
                std::nth_element(rel.begin(), rel.begin() + long(rel.size() / 2), rel.end());
                r.worstRelativeBias = rel[rel.size() / 2];
            }
        }
    }

    // ---- warnings ----
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

    // ---- the sentence ----
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
    return r;
}

// ============================================================================================
// reports
// ============================================================================================

namespace {

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

}  // namespace

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
        if (r.kind == TestKind::Welch && r.testHasCount && r.refHasCount)
            o << "per-sample variance ratio test/reference: " << fmtG(r.varianceRatio[0], 3) << " (R), "
              << fmtG(r.varianceRatio[1], 3) << " (G), " << fmtG(r.varianceRatio[2], 3)
              << " (B); the pooled variance exceeded Welch's in " << r.pooledChannels << " of " << r.testedChannels
              << " tested channels\n";
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
    if (r.kind != TestKind::None && !r.worst.empty() && (!r.consistent || r.flagged > 0)) {
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
    j["tests"] = t;
    j["verdict"] = !r.hasVerdict ? "no verdict" : r.consistent ? "consistent" : "inconsistent";
    j["consistent"] = r.hasVerdict && r.consistent;
    j["exitCode"] = exitCodeOf(r);
    if (!r.hasVerdict) j["noVerdictReason"] = r.noVerdictReason;
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

// ============================================================================================
// heatmap
// ============================================================================================

namespace {

// A 3x5 bitmap font: each glyph is 5 rows of 3 bits (bit 2 = left column).
struct Glyph {
    char c;
    uint8_t rows[5];
};
const Glyph kFont[] = {
    {'0', {7, 5, 5, 5, 7}}, {'1', {2, 6, 2, 2, 7}}, {'2', {7, 1, 7, 4, 7}}, {'3', {7, 1, 7, 1, 7}},
    {'4', {5, 5, 7, 1, 1}}, {'5', {7, 4, 7, 1, 7}}, {'6', {7, 4, 7, 5, 7}}, {'7', {7, 1, 1, 1, 1}},
    {'8', {7, 5, 7, 5, 7}}, {'9', {7, 5, 7, 1, 7}}, {'+', {0, 2, 7, 2, 0}}, {'-', {0, 0, 7, 0, 0}},
    {'.', {0, 0, 0, 0, 2}}, {'%', {5, 1, 2, 4, 5}}, {'e', {0, 7, 7, 4, 7}}, {'z', {0, 7, 2, 4, 7}},
    {'|', {2, 2, 2, 2, 2}},
};
constexpr int kFontScale = 2;
constexpr int kGlyphW = 3 * kFontScale, kGlyphH = 5 * kFontScale, kGlyphGap = kFontScale;

struct Canvas {
    int w, h;
    std::vector<uint8_t> px;  // RGB
    Canvas(int width, int height) : w(width), h(height), px(size_t(width) * size_t(height) * 3, 0) {}
    void set(int x, int y, const std::array<uint8_t, 3>& c) {
        if (x < 0 || y < 0 || x >= w || y >= h) return;
        uint8_t* p = &px[(size_t(y) * size_t(w) + size_t(x)) * 3];
        p[0] = c[0];
        p[1] = c[1];
        p[2] = c[2];
    }
    void fill(int x0, int y0, int x1, int y1, const std::array<uint8_t, 3>& c) {
        for (int y = y0; y < y1; ++y)
            for (int x = x0; x < x1; ++x) set(x, y, c);
    }
};

int textWidth(const std::string& s) { return s.empty() ? 0 : int(s.size()) * (kGlyphW + kGlyphGap) - kGlyphGap; }

void drawText(Canvas& cv, int x, int y, const std::string& s, const std::array<uint8_t, 3>& col) {
    for (char ch : s) {
        for (const Glyph& g : kFont)
            if (g.c == ch) {
                for (int ry = 0; ry < 5; ++ry)
                    for (int rx = 0; rx < 3; ++rx)
                        if (g.rows[ry] & (4 >> rx)) cv.fill(x + rx * kFontScale, y + ry * kFontScale,
                                                            x + (rx + 1) * kFontScale, y + (ry + 1) * kFontScale, col);
                break;
            }
        x += kGlyphW + kGlyphGap;
    }
}

// Diverging blue - grey - red ("cool to warm") for u in [-1, 1].
std::array<uint8_t, 3> diverging(double u) {
    u = std::clamp(u, -1.0, 1.0);
    const double lo[3] = {59, 76, 192}, mid[3] = {221, 221, 221}, hi[3] = {180, 4, 38};
    std::array<uint8_t, 3> c{};
    for (int k = 0; k < 3; ++k) {
        const double v = u < 0 ? mid[k] + (lo[k] - mid[k]) * (-u) : mid[k] + (hi[k] - mid[k]) * u;
        c[size_t(k)] = uint8_t(std::lround(v));
    }
    return c;
}

std::string shortNumber(double v, bool percent) {
    char buf[32];
    if (percent) {
        const double pv = v * 100.0;
        std::snprintf(buf, sizeof buf, std::abs(pv) >= 10 || pv == std::round(pv) ? "%+.0f%%" : "%+.1f%%", pv);
        if (std::abs(pv) < 0.1 && pv != 0) std::snprintf(buf, sizeof buf, "%+.2f%%", pv);
    } else {
        std::snprintf(buf, sizeof buf, v == std::round(v) ? "%+.0f" : "%+.1f", v);
    }
    std::string s = buf;
    if (s == "+0" || s == "-0") s = "0";
    if (s == "+0%" || s == "-0%") s = "0%";
    return s;
}

// 1, 2, 5 x 10^k, the smallest >= v.
double niceCeil(double v) {
    if (!(v > 0)) return 1.0;
    const double e = std::pow(10.0, std::floor(std::log10(v)));
    for (double m : {1.0, 2.0, 5.0, 10.0})
        if (m * e >= v * (1 - 1e-12)) return m * e;
    return 10 * e;
}

}  // namespace

HeatmapLayout heatmapLayout(int regionWidth, int regionHeight) {
    HeatmapLayout l;
    const int longest = std::max(1, std::max(regionWidth, regionHeight));
    l.scale = std::clamp((256 + longest - 1) / longest, 1, 32);
    l.imageHeight = regionHeight * l.scale;
    l.width = std::max(regionWidth * l.scale, 256);
    const int margin = 24;
    l.barX0 = margin;
    l.barX1 = l.width - margin;
    l.barY0 = l.imageHeight + 8;
    l.barY1 = l.barY0 + 14;
    l.height = l.barY1 + 6 + kGlyphH + 6;
    return l;
}

void writeHeatmapPng(const std::string& path, const CompareResult& r) {
    const HeatmapLayout L = heatmapLayout(r.region.width, r.region.height);
    Canvas cv(L.width, L.height);
    cv.fill(0, 0, L.width, L.height, {32, 32, 32});
    const bool zMode = r.kind != TestKind::None;
    double range;
    if (zMode) {
        range = std::max(5.0, std::ceil(r.zThreshold + 1.0));
    } else {
        std::vector<float> a;
        for (size_t i = 0; i < r.relError.size(); ++i)
            if (r.status[i] == PixelStatus::NoVariance && std::isfinite(r.relError[i])) a.push_back(std::abs(r.relError[i]));
        double q = 0.01;
        if (!a.empty()) {
            const size_t k = std::min(a.size() - 1, size_t(0.99 * double(a.size())));
            std::nth_element(a.begin(), a.begin() + long(k), a.end());
            q = std::max(1e-3, double(a[k]));
        }
        range = niceCeil(q);
    }
    const std::array<uint8_t, 3> grey{96, 96, 96}, black{0, 0, 0}, magenta{255, 0, 255}, white{235, 235, 235},
        yellow{255, 220, 0};
    for (int ry = 0; ry < r.region.height; ++ry)
        for (int rx = 0; rx < r.region.width; ++rx) {
            const size_t i = size_t(r.region.y + ry) * size_t(r.width) + size_t(r.region.x + rx);
            std::array<uint8_t, 3> c;
            switch (r.status[i]) {
            case PixelStatus::Outside: c = black; break;
            case PixelStatus::NonFinite:
            case PixelStatus::Unequal: c = magenta; break;
            case PixelStatus::FewSamples:
            case PixelStatus::LowEffective: c = grey; break;
            case PixelStatus::Equal: c = diverging(0.0); break;
            case PixelStatus::Tested: c = diverging(double(r.pixelZ[i]) / range); break;
            case PixelStatus::NoVariance: c = diverging(double(r.relError[i]) / range); break;
            default: c = grey;
            }
            cv.fill(rx * L.scale, ry * L.scale, (rx + 1) * L.scale, (ry + 1) * L.scale, c);
        }
    // Outline the worst region.
    if (r.flagged > 0 && r.worstX1 >= r.worstX0) {
        const int x0 = (r.worstX0 - r.region.x) * L.scale, x1 = (r.worstX1 + 1 - r.region.x) * L.scale - 1;
        const int y0 = (r.worstY0 - r.region.y) * L.scale, y1 = (r.worstY1 + 1 - r.region.y) * L.scale - 1;
        for (int x = x0; x <= x1; ++x) {
            cv.set(x, y0, yellow);
            cv.set(x, y1, yellow);
        }
        for (int y = y0; y <= y1; ++y) {
            cv.set(x0, y, yellow);
            cv.set(x1, y, yellow);
        }
    }
    // Legend: the colour bar from -range to +range, its unit at the left, labels below.
    const int barW = L.barX1 - L.barX0;
    for (int x = L.barX0; x < L.barX1; ++x) {
        const double u = (double(x - L.barX0) + 0.5) / double(barW) * 2.0 - 1.0;
        cv.fill(x, L.barY0, x + 1, L.barY1, diverging(u));
    }
    drawText(cv, 6, L.barY0 + (L.barY1 - L.barY0 - kGlyphH) / 2, zMode ? "z" : "%", white);
    const int labelY = L.barY1 + 4;
    auto xOf = [&](double v) { return L.barX0 + int(std::lround((v / range + 1.0) * 0.5 * double(barW))); };
    struct Label {
        double v;
        std::string s;
    };
    std::vector<Label> labels = {{-range, shortNumber(-range, !zMode)}, {0.0, zMode ? "0" : "0%"},
                                 {range, shortNumber(range, !zMode)}};
    if (zMode && r.zThreshold > 0 && r.zThreshold < range) {
        labels.push_back({-r.zThreshold, shortNumber(-r.zThreshold, false)});
        labels.push_back({r.zThreshold, shortNumber(r.zThreshold, false)});
    }
    std::vector<std::pair<int, int>> used;  // occupied label spans
    for (const Label& lb : labels) {
        const int tw = textWidth(lb.s);
        const int cx = xOf(lb.v);
        const int x0 = std::clamp(cx - tw / 2, 0, L.width - tw);
        bool overlaps = false;
        for (const auto& u : used) overlaps = overlaps || !(x0 + tw + 4 <= u.first || x0 >= u.second + 4);
        cv.fill(std::clamp(cx, L.barX0, L.barX1 - 1), L.barY1, std::clamp(cx, L.barX0, L.barX1 - 1) + 1, L.barY1 + 3,
                white);  // tick
        if (overlaps) continue;
        drawText(cv, x0, labelY, lb.s, white);
        used.emplace_back(x0, x0 + tw);
    }

    writeRgb8Png(path, L.width, L.height, cv.px);
}

}  // namespace bdptref
