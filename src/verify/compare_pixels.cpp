// The per-pixel pass of the comparison: input checks, the per-pixel tests (each channel's in
// compare_channel_test.cpp) and the plain error metrics (include/bdptref/image_compare.h;
// docs/compare.md derives the tests). testPixels reads as the list of its steps.
#include "verify/compare_channel_test.h"

#include "bdptref/errors.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace bdptref::compare_detail {

namespace {

// median(chi^2_k) / k: exact for k = 1, 2; Wilson-Hilferty (1 - 2 / (9k))^3 beyond (0.7% high at
// k = 3, less for larger k).
double chiSquareMedianOverDof(double k) {
    if (k <= 1.0) return 0.454936423119572;
    if (k <= 2.0) return 0.693147180559945;  // ln 2
    const double a = 1.0 - 2.0 / (9.0 * k);
    return a * a * a;
}

// The largest value over each pixel's 3 x 3 neighbourhood, of the values > 0 (NaN and values <= 0
// say nothing); 0 where none is.
std::vector<float> neighbourhoodMax(const std::vector<float>& v, int W, int H) {
    std::vector<float> out(v.size(), 0.f);
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            float m = 0.f;
            for (int yy = std::max(0, y - 1); yy <= std::min(H - 1, y + 1); ++yy)
                for (int xx = std::max(0, x - 1); xx <= std::min(W - 1, x + 1); ++xx) {
                    const float s = v[size_t(yy) * size_t(W) + size_t(xx)];
                    if (s > m && std::isfinite(s)) m = s;
                }
            out[size_t(y) * size_t(W) + size_t(x)] = m;
        }
    return out;
}

// The metric accumulators (double, in pixel order: deterministic), per channel and of the
// channel-averaged differences (spread CI of the overall bias).
struct MetricSums {
    struct Acc {
        double se = 0, rel = 0, ae = 0, sumT = 0, sumR = 0, sumD = 0, sumD2 = 0, sumV = 0, maxAbs = -1;
        int maxX = -1, maxY = -1;
    };
    std::array<Acc, 3> acc;
    double sumMeanD = 0, sumMeanD2 = 0;
};

// One compared pixel: the two images' means and variances of the mean (negative ones as 0; 0
// for an image whose variances the test does not use) and counts (infinite without a count layer).
struct PixelValues {
    size_t i = 0;
    int x = 0, y = 0;
    double t[3] = {0, 0, 0}, r[3] = {0, 0, 0}, vt[3] = {0, 0, 0}, vr[3] = {0, 0, 0};
    double nT = 0.0, nR = 0.0;
};

bool haveTestShape(const CompareOptions& options) {
    return !options.testShape[0].empty() || !options.testShape[1].empty() || !options.testShape[2].empty();
}

// docs/compare.md "Inputs": the refusals that need no more than the two images and the options.
void checkInputs(const ExrImage& test, const ExrImage& ref, const CompareOptions& options) {
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
    for (const std::vector<float>& s : options.testShape)
        if (haveTestShape(options) && s.size() != size_t(test.width) * size_t(test.height))
            throw InputError("the test's estimator shape is " + std::to_string(s.size()) + " values per channel, the images " +
                             std::to_string(test.width) + "x" + std::to_string(test.height) + " pixels");
}

// docs/compare.md "Inputs" (--region, --mask): the image's size and the region compared.
void setUpRegion(const CompareOptions& options, int W, int H, CompareResult& r, CompareWork& w) {
    const size_t N = size_t(W) * size_t(H);
    w.W = W;
    w.H = H;
    w.N = N;
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
}

// docs/compare.md "Layers of a test image with variances": the test kind from the layers each
// image has, and the channels it reads.
void bindChannels(const ExrImage& test, const ExrImage& ref, CompareResult& r, CompareWork& w) {
    const bool tVar = hasVariance(test), rVar = hasVariance(ref);
    r.testHasCount = test.has("count");
    r.refHasCount = ref.has("count");
    r.kind = tVar && rVar ? TestKind::Welch : rVar ? TestKind::RefVariance : tVar ? TestKind::TestVariance : TestKind::None;
    r.biasFromVariances = r.kind != TestKind::None;
    for (int c = 0; c < 3; ++c) {
        w.tm[c] = &test.channels.at(kChannelNames[c]);
        w.rm[c] = &ref.channels.at(kChannelNames[c]);
        if (tVar) w.tv[c] = &test.channels.at(kVarianceNames[c]);
        if (rVar) w.rv[c] = &ref.channels.at(kVarianceNames[c]);
    }
    w.tn = r.testHasCount ? &test.channels.at("count") : nullptr;
    w.rn = r.refHasCount ? &ref.channels.at("count") : nullptr;
    w.useTestVar = r.kind == TestKind::Welch || r.kind == TestKind::TestVariance;
    w.useRefVar = r.kind == TestKind::Welch || r.kind == TestKind::RefVariance;
}

// The per-pixel outputs, before any pixel is compared.
void clearPixelOutputs(CompareResult& r, CompareWork& w) {
    const size_t N = w.N;
    r.status.assign(N, PixelStatus::Outside);
    r.pixelP.assign(N, std::numeric_limits<float>::quiet_NaN());
    r.pixelZ.assign(N, std::numeric_limits<float>::quiet_NaN());
    r.relError.assign(N, std::numeric_limits<float>::quiet_NaN());
    r.isFlagged.assign(N, 0);
    w.pixelPd.assign(N, 1.0);  // double-precision pixel p-values (tested pixels)
    // Per channel: t - r and the variance of t - r of every t-tested pixel (NaN elsewhere), for
    // the bias test. The variance excludes the precision floor, kept apart as a standard
    // deviation: rounding may be systematic, so the bias test adds the floors of many pixels
    // linearly, not in quadrature.
    for (int c = 0; c < 3; ++c) {
        w.diff[size_t(c)].assign(N, std::numeric_limits<double>::quiet_NaN());
        w.diffVar[size_t(c)].assign(N, std::numeric_limits<double>::quiet_NaN());
        w.diffFloor[size_t(c)].assign(N, 0.0);
    }
    w.neededFactor.assign(N, 0.0);
}

// docs/compare.md "Per pixel and channel" and "Inputs" (N renders): which rules apply to the
// image: the neighbourhood bounds with counts, N renders, the test's estimator shape.
PixelRules chooseRules(const ExrImage& test, const CompareOptions& options, CompareResult& r, const CompareWork& w) {
    PixelRules rules;
    rules.minEffective = options.minEffectiveSamples;
    rules.precision = options.precision;
    rules.samplesPerRender = options.samplesPerRender;
    rules.pooled = r.kind == TestKind::Welch && w.tn && w.rn;
    r.varianceRatio = {1.0, 1.0, 1.0};
    // N renders combined (combineRenders): the test's variances have N - 1 degrees of freedom and
    // there is no per-sample count. Their variance estimates rest on few renders, so (as the pooled
    // bound does for counts) a pixel's test variance is taken as at least kappa times the
    // reference's, kappa the image's median test/reference ratio of the variances of the means.
    r.testRenders = rendersOf(test);
    rules.renders = r.testRenders >= 2 && !w.tn;
    rules.testDof = rules.renders ? double(r.testRenders - 1) : std::numeric_limits<double>::infinity();
    rules.rendersGuard = rules.renders && r.kind == TestKind::Welch;
    // The test's estimator shape (CompareOptions::testShape) counts only where the test's samples
    // per pixel are known: a count layer with the reference's, or N renders of known spp.
    rules.useTestShape =
        haveTestShape(options) && (rules.pooled || (rules.rendersGuard && w.rn && options.samplesPerRender > 0));
    if (haveTestShape(options) && !rules.useTestShape)
        throw InputError("the test's estimator shape (--test-shape) needs the test's samples per pixel: a count layer "
                         "in both images, or N renders with --samples-per-render, and a reference with variances and "
                         "a count");
    // Each pixel takes the largest shape of its 3 x 3 neighbourhood: a long render's estimate of a
    // heavy tail is itself noisy (it may have missed the rarest samples of one pixel and caught
    // them in the next), and heavy tails come in shapes (edges, caustics) larger than a pixel.
    if (rules.useTestShape)
        for (int c = 0; c < 3; ++c)
            rules.testShape[size_t(c)] = neighbourhoodMax(options.testShape[size_t(c)], w.W, w.H);
    // N renders against a reference with counts: the neighbourhood shapes, with each render as
    // one sample of the test (its shape is the renders' relative variance s^2 / m^2, s^2 = N v
    // with N - 1 dof).
    rules.rendersShape = rules.rendersGuard && w.rn;
    rules.nRenders = double(r.testRenders);
    rules.fewRenders = rules.rendersShape && r.testRenders < 4;
    return rules;
}

// The median over the compared pixels (region and mask) of ratio(c, i), per channel c, of the
// pixels where it is defined (ratio returns <= 0 elsewhere); 0 when no pixel has one.
template <class Ratio>
double medianRatio(const CompareOptions& options, const CompareWork& w, const CompareResult& r, int c, Ratio ratio,
                   std::vector<double>& ratios) {
    ratios.clear();
    for (int y = r.region.y; y < r.region.y + r.region.height; ++y)
        for (int x = r.region.x; x < r.region.x + r.region.width; ++x) {
            const size_t i = size_t(y) * size_t(w.W) + size_t(x);
            if (!options.mask.empty() && !options.mask[i]) continue;
            const double q = ratio(c, i);
            if (q > 0) ratios.push_back(q);
        }
    if (ratios.empty()) return 0.0;
    std::nth_element(ratios.begin(), ratios.begin() + long(ratios.size() / 2), ratios.end());
    return ratios[ratios.size() / 2];
}

// docs/compare.md "Inputs" (N renders, kappa): the renders' median test/reference ratio of the
// variances of the means, per channel, with the median of a variance of N - 1 dof divided out.
void rendersVarianceRatios(const CompareOptions& options, const CompareWork& w, CompareResult& r) {
    std::vector<double> ratios;
    auto ratio = [&](int c, size_t i) {
        const double va = (*w.tv[c])[i], vb = (*w.rv[c])[i];
        return va > 0 && vb > 0 && std::isfinite(va) && std::isfinite(vb) ? va / vb : 0.0;
    };
    for (int c = 0; c < 3; ++c) {
        const double m = medianRatio(options, w, r, c, ratio, ratios);
        if (ratios.empty()) continue;
        // va estimates the variance with k = N - 1 degrees of freedom: its median is the
        // variance times median(chi^2_k) / k (0.455 for k = 1), which is divided out.
        const double med = m / chiSquareMedianOverDof(double(r.testRenders - 1));
        if (med > 0 && std::isfinite(med)) r.varianceRatio[size_t(c)] = med;
    }
}

// docs/compare.md "Per pixel and channel" (counts in both images): the median test/reference
// ratio of the per-sample variances n v, per channel (reported; 1 where no pixel has both).
void pooledVarianceRatios(const CompareOptions& options, const CompareWork& w, CompareResult& r) {
    std::vector<double> ratios;
    auto ratio = [&](int c, size_t i) {
        const double nT = (*w.tn)[i], nR = (*w.rn)[i], va = (*w.tv[c])[i], vb = (*w.rv[c])[i];
        return nT >= 2 && nR >= 2 && va > 0 && vb > 0 && std::isfinite(va) && std::isfinite(vb) ? (nT * va) / (nR * vb)
                                                                                                 : 0.0;
    };
    for (int c = 0; c < 3; ++c) {
        const double med = medianRatio(options, w, r, c, ratio, ratios);
        if (!ratios.empty() && med > 0 && std::isfinite(med)) r.varianceRatio[size_t(c)] = med;
    }
}

// docs/compare.md "Per pixel and channel" (neighbourhood lower bound, too few samples): each
// image's estimator shape around every pixel, from its own neighbours (compare_neighbourhood.cpp).
void neighbourhoodShapes(const CompareOptions& options, const CompareResult& r, const CompareWork& w,
                         PixelRules& rules) {
    if (rules.pooled)
        for (int c = 0; c < 3; ++c) {
            rules.shapeT[size_t(c)] = neighbourShape(r, options, w.W, *w.tm[c], *w.tv[c], *w.tn);
            rules.shapeR[size_t(c)] = neighbourShape(r, options, w.W, *w.rm[c], *w.rv[c], *w.rn);
        }
    if (rules.rendersShape) {
        // neighbourShape takes (n - 1) v as the per-sample variance: with v = s^2 / N, scaled by
        // N / (N - 1) that is s^2, unbiased (the factor (N - 1) / N is 1/2 for two renders).
        const double nRenders = rules.nRenders;
        const std::vector<float> renderCount(w.N, float(nRenders));
        std::vector<float> renderVar;
        for (int c = 0; c < 3; ++c) {
            renderVar = *w.tv[c];
            for (float& v : renderVar) v = float(double(v) * nRenders / (nRenders - 1.0));
            rules.shapeT[size_t(c)] = neighbourShape(r, options, w.W, *w.tm[c], renderVar, renderCount);
            rules.shapeR[size_t(c)] = neighbourShape(r, options, w.W, *w.rm[c], *w.rv[c], *w.rn);
        }
    }
}

// docs/compare.md "Metrics" (finite in both images): the pixel's values; false when one is NaN or
// infinite.
bool readPixel(const CompareWork& w, size_t i, PixelValues& px) {
    bool finite = true;
    for (int c = 0; c < 3; ++c) {
        px.t[c] = (*w.tm[c])[i];
        px.r[c] = (*w.rm[c])[i];
        if (w.useTestVar) px.vt[c] = (*w.tv[c])[i];
        if (w.useRefVar) px.vr[c] = (*w.rv[c])[i];
        finite = finite && std::isfinite(px.t[c]) && std::isfinite(px.r[c]) && std::isfinite(px.vt[c]) &&
                 std::isfinite(px.vr[c]);
        px.vt[c] = std::max(0.0, px.vt[c]);  // a negative variance (rounding in a writer) is 0
        px.vr[c] = std::max(0.0, px.vr[c]);
    }
    // sample counts (infinity when the image has no count layer)
    px.nT = w.tn ? double((*w.tn)[i]) : std::numeric_limits<double>::infinity();
    px.nR = w.rn ? double((*w.rn)[i]) : std::numeric_limits<double>::infinity();
    return finite;
}

// docs/compare.md "Metrics": the pixel's share of the error metrics, and its relative error.
void accumulateMetrics(const PixelValues& px, double eps, MetricSums& m, CompareResult& r) {
    ++r.metricPixels;
    double meanD = 0, rel = 0;
    for (int c = 0; c < 3; ++c) {
        const double d = px.t[c] - px.r[c];
        MetricSums::Acc& a = m.acc[size_t(c)];
        a.se += d * d;
        a.rel += d * d / (px.r[c] * px.r[c] + eps);
        a.ae += std::abs(d);
        a.sumT += px.t[c];
        a.sumR += px.r[c];
        a.sumD += d;
        a.sumD2 += d * d;
        a.sumV += px.vt[c] + px.vr[c];
        if (std::abs(d) > a.maxAbs) {
            a.maxAbs = std::abs(d);
            a.maxX = px.x;
            a.maxY = px.y;
        }
        meanD += d / 3.0;
        rel += d / std::sqrt(px.r[c] * px.r[c] + eps) / 3.0;
    }
    m.sumMeanD += meanD;
    m.sumMeanD2 += meanD * meanD;
    r.relError[px.i] = float(rel);
}

// docs/compare.md "Per pixel and channel" (too few samples): true (the pixel excluded) when an
// image with a count layer holds fewer than 2 samples there.
bool tooFewSamples(const PixelValues& px, CompareResult& r, CompareWork& w) {
    const double nT = px.nT, nR = px.nR;
    const bool fewT = w.useTestVar && w.tn && !(nT >= 2.0);
    const bool fewR = w.useRefVar && w.rn && !(nR >= 2.0);
    if (!(fewT || fewR)) return false;
    // Two samples in the pixel would do.
    const double nMin = std::min(fewT ? nT : 2.0, fewR ? nR : 2.0);
    w.neededFactor[px.i] = nMin > 0 ? 2.0 / nMin : kNoFactor;
    r.status[px.i] = PixelStatus::FewSamples;
    ++r.fewSamples;
    return true;
}

// Channel c of the pixel, for its test.
ChannelValues channelValues(const PixelValues& px, int c) {
    ChannelValues v;
    v.c = c;
    v.i = px.i;
    v.a = px.t[c];
    v.b = px.r[c];
    v.va = px.vt[c];
    v.vb = px.vr[c];
    v.nT = px.nT;
    v.nR = px.nR;
    return v;
}

// docs/compare.md "Per pixel: combining R, G and B": the pixel's status, and for a tested pixel
// the Cauchy combination of its channels' p-values, its z-score and its terms of the bias test.
void combineChannels(const PixelValues& px, const ChannelTest (&ct)[3], CompareResult& r, CompareWork& w) {
    const size_t i = px.i;
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
        for (int c = 0; c < 3; ++c) dsum += px.t[c] - px.r[c];
        r.pixelZ[i] = float(dsum >= 0 ? 40.0 : -40.0);
        return;
    }
    if (nTested == 0) {
        r.status[i] = nLow > 0 ? PixelStatus::LowEffective : PixelStatus::Equal;
        if (nLow > 0) {  // one channel suffices to test the pixel
            double f = kNoFactor;
            for (int c = 0; c < 3; ++c)
                if (ct[c].kind == ChannelTest::LowEffective) f = std::min(f, ct[c].neededFactor);
            w.neededFactor[i] = f;
        }
        if (nLow > 0) ++r.lowEffective;
        else {
            ++r.equal;
            r.pixelZ[i] = 0.f;
        }
        return;
    }
    r.status[i] = PixelStatus::Tested;
    ++r.tested;
    const double p = stats::cauchyCombination(ps, nTested);
    w.pixelPd[i] = p;
    r.pixelP[i] = float(p);
    const double z = stats::zFromTwoSidedP(p);
    r.pixelZ[i] = float(bestStat >= 0 ? z : -z);
    for (int c = 0; c < 3; ++c)
        if (ct[c].kind == ChannelTest::Tested) {
            w.diff[size_t(c)][i] = px.t[c] - px.r[c];
            w.diffVar[size_t(c)][i] = ct[c].var;
            w.diffFloor[size_t(c)][i] = ct[c].floorSd;
        }
    if (p < r.pMin || r.pMinX < 0) {
        r.pMin = p;
        r.pMinX = px.x;
        r.pMinY = px.y;
    }
}

// docs/compare.md "The statistical test": one compared pixel, from its values to its status.
void testPixel(const PixelRules& rules, double eps, int x, int y, MetricSums& sums, CompareResult& r, CompareWork& w) {
    PixelValues px;
    px.i = size_t(y) * size_t(w.W) + size_t(x);
    px.x = x;
    px.y = y;
    ++r.compared;
    if (!readPixel(w, px.i, px)) {
        r.status[px.i] = PixelStatus::NonFinite;
        ++r.nonFinite;
        return;
    }
    accumulateMetrics(px, eps, sums, r);
    if (r.kind == TestKind::None) {
        r.status[px.i] = PixelStatus::NoVariance;
        return;
    }
    if (tooFewSamples(px, r, w)) return;
    ChannelTest ct[3];
    for (int c = 0; c < 3; ++c) ct[c] = testChannel(rules, channelValues(px, c), r);
    combineChannels(px, ct, r, w);
}

// docs/compare.md "Metrics": the metrics and the bias confidence intervals from the sums.
void summariseMetrics(const MetricSums& sums, CompareResult& r) {
    const double np = double(r.metricPixels);
    const double z95 = 1.959963984540054;
    if (r.metricPixels == 0) return;
    double overallSe = 0;
    for (int c = 0; c < 3; ++c) {
        const MetricSums::Acc& a = sums.acc[size_t(c)];
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
        se = np > 1 ? std::sqrt(std::max(0.0, (sums.sumMeanD2 - sums.sumMeanD * sums.sumMeanD / np) / (np - 1.0)) / np)
                    : 0.0;
    r.overall.biasLow = r.overall.bias - z95 * se;
    r.overall.biasHigh = r.overall.bias + z95 * se;
    r.overall.relativeBias = r.overall.meanRef != 0 ? r.overall.bias / r.overall.meanRef : 0.0;
}

}  // namespace

void testPixels(const ExrImage& test, const ExrImage& ref, const CompareOptions& options, CompareResult& r, CompareWork& w) {
    checkInputs(test, ref, options);
    setUpRegion(options, test.width, test.height, r, w);
    bindChannels(test, ref, r, w);
    clearPixelOutputs(r, w);
    PixelRules rules = chooseRules(test, options, r, w);
    if (rules.rendersGuard) rendersVarianceRatios(options, w, r);
    if (rules.pooled) pooledVarianceRatios(options, w, r);
    neighbourhoodShapes(options, r, w, rules);
    MetricSums sums;
    for (int y = r.region.y; y < r.region.y + r.region.height; ++y)
        for (int x = r.region.x; x < r.region.x + r.region.width; ++x) {
            const size_t i = size_t(y) * size_t(w.W) + size_t(x);
            if (!options.mask.empty() && !options.mask[i]) continue;
            testPixel(rules, options.epsilon, x, y, sums, r, w);
        }
    if (r.compared == 0) throw InputError("the region and the mask leave no pixel to compare");
    summariseMetrics(sums, r);
}

}  // namespace bdptref::compare_detail
