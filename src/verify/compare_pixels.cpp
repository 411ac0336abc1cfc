// The per-pixel pass of the comparison: input checks, the per-pixel and per-channel t-tests and
// the plain error metrics (include/bdptref/image_compare.h; docs/compare.md derives the tests).
#include "verify/compare_internal.h"

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

// One image's neighbourhood shape nbSelf raised by the other image's excess at the pixel: the
// factor by which that image's own relative per-sample variance exceeds twice its neighbourhood's
// (a ratio, so that the two images' shapes may be in different units and of different
// estimators; twice, so that the noise of a variance estimate, about sqrt(2 / n_eff) relative,
// does not raise ordinary pixels and make the local test conservative). With a neighbourhood of
// no variance (all deterministic) the other image's own C itself.
double raisedShape(double nbSelf, double ownOther, double nbOther) {
    if (nbOther > 0) return nbSelf * std::max(1.0, ownOther / (2.0 * nbOther));
    return std::max(nbSelf, ownOther);
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

}  // namespace

void testPixels(const ExrImage& test, const ExrImage& ref, const CompareOptions& options, CompareResult& r, CompareWork& w) {
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
    const bool haveTestShape = !options.testShape[0].empty() || !options.testShape[1].empty() || !options.testShape[2].empty();
    for (const std::vector<float>& s : options.testShape)
        if (haveTestShape && s.size() != size_t(test.width) * size_t(test.height))
            throw InputError("the test's estimator shape is " + std::to_string(s.size()) + " values per channel, the images " +
                             std::to_string(test.width) + "x" + std::to_string(test.height) + " pixels");

    const int W = test.width, H = test.height;
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

    const bool tVar = hasVariance(test), rVar = hasVariance(ref);
    r.testHasCount = test.has("count");
    r.refHasCount = ref.has("count");
    r.kind = tVar && rVar ? TestKind::Welch : rVar ? TestKind::RefVariance : tVar ? TestKind::TestVariance : TestKind::None;
    r.biasFromVariances = r.kind != TestKind::None;

    const std::vector<float>** tm = w.tm;
    const std::vector<float>** rm = w.rm;
    const std::vector<float>** tv = w.tv;
    const std::vector<float>** rv = w.rv;
    for (int c = 0; c < 3; ++c) {
        tm[c] = &test.channels.at(kChannelNames[c]);
        rm[c] = &ref.channels.at(kChannelNames[c]);
        if (tVar) tv[c] = &test.channels.at(kVarianceNames[c]);
        if (rVar) rv[c] = &ref.channels.at(kVarianceNames[c]);
    }
    const std::vector<float>* tn = w.tn = r.testHasCount ? &test.channels.at("count") : nullptr;
    const std::vector<float>* rn = w.rn = r.refHasCount ? &ref.channels.at("count") : nullptr;
    const bool useTestVar = w.useTestVar = r.kind == TestKind::Welch || r.kind == TestKind::TestVariance;
    const bool useRefVar = w.useRefVar = r.kind == TestKind::Welch || r.kind == TestKind::RefVariance;

    r.status.assign(N, PixelStatus::Outside);
    r.pixelP.assign(N, std::numeric_limits<float>::quiet_NaN());
    r.pixelZ.assign(N, std::numeric_limits<float>::quiet_NaN());
    r.relError.assign(N, std::numeric_limits<float>::quiet_NaN());
    r.isFlagged.assign(N, 0);
    std::vector<double>& pixelPd = w.pixelPd;
    pixelPd.assign(N, 1.0);  // double-precision pixel p-values (tested pixels)

    // Bias test and metric accumulators (double, in pixel order: deterministic).
    // Per channel: t - r and the variance of t - r of every t-tested pixel (NaN elsewhere).
    // The variance excludes the precision floor, kept apart as a standard deviation: rounding may
    // be systematic, so the bias test adds the floors of many pixels linearly, not in quadrature.
    std::array<std::vector<double>, 3>&diff = w.diff, &diffVar = w.diffVar, &diffFloor = w.diffFloor;
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
    // N renders combined (combineRenders): the test's variances have N - 1 degrees of freedom and
    // there is no per-sample count. Their variance estimates rest on few renders, so (as the pooled
    // bound does for counts) a pixel's test variance is taken as at least kappa times the
    // reference's, kappa the image's median test/reference ratio of the variances of the means.
    r.testRenders = rendersOf(test);
    const bool renders = r.testRenders >= 2 && !tn;
    const double testDof = renders ? double(r.testRenders - 1) : std::numeric_limits<double>::infinity();
    const bool rendersGuard = renders && r.kind == TestKind::Welch;
    // The test's estimator shape (CompareOptions::testShape) counts only where the test's samples
    // per pixel are known: a count layer with the reference's, or N renders of known spp.
    const bool useTestShape = haveTestShape && (pooled || (rendersGuard && rn && options.samplesPerRender > 0));
    if (haveTestShape && !useTestShape)
        throw InputError("the test's estimator shape (--test-shape) needs the test's samples per pixel: a count layer "
                         "in both images, or N renders with --samples-per-render, and a reference with variances and "
                         "a count");
    // Each pixel takes the largest shape of its 3 x 3 neighbourhood: a long render's estimate of a
    // heavy tail is itself noisy (it may have missed the rarest samples of one pixel and caught
    // them in the next), and heavy tails come in shapes (edges, caustics) larger than a pixel.
    std::array<std::vector<float>, 3> testShape;
    if (useTestShape)
        for (int c = 0; c < 3; ++c) testShape[size_t(c)] = neighbourhoodMax(options.testShape[size_t(c)], W, H);
    auto testShapeAt = [&](int c, size_t i) { return useTestShape ? double(testShape[size_t(c)][i]) : 0.0; };
    w.neededFactor.assign(N, 0.0);
    if (rendersGuard) {
        std::vector<double> ratios;
        for (int c = 0; c < 3; ++c) {
            ratios.clear();
            for (int y = r.region.y; y < r.region.y + r.region.height; ++y)
                for (int x = r.region.x; x < r.region.x + r.region.width; ++x) {
                    const size_t i = size_t(y) * size_t(W) + size_t(x);
                    if (!options.mask.empty() && !options.mask[i]) continue;
                    const double va = (*tv[c])[i], vb = (*rv[c])[i];
                    if (va > 0 && vb > 0 && std::isfinite(va) && std::isfinite(vb)) ratios.push_back(va / vb);
                }
            if (!ratios.empty()) {
                std::nth_element(ratios.begin(), ratios.begin() + long(ratios.size() / 2), ratios.end());
                // va estimates the variance with k = N - 1 degrees of freedom: its median is the
                // variance times median(chi^2_k) / k (0.455 for k = 1), which is divided out.
                const double med = ratios[ratios.size() / 2] / chiSquareMedianOverDof(double(r.testRenders - 1));
                if (med > 0 && std::isfinite(med)) r.varianceRatio[size_t(c)] = med;
            }
        }
    }
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

    // Each image's estimator shape around every pixel, from its own neighbours (compare_neighbourhood.cpp):
    // it decides the effective samples and bounds the variances below.
    // N renders against a reference with counts: the same, with each render as one sample of the
    // test (its shape is the renders' relative variance s^2 / m^2, s^2 = N v with N - 1 dof).
    const bool rendersShape = rendersGuard && rn;
    const double nRenders = double(r.testRenders);
    const bool fewRenders = rendersShape && r.testRenders < 4;
    std::array<NeighbourShape, 3> shapeT, shapeR;
    if (pooled)
        for (int c = 0; c < 3; ++c) {
            shapeT[size_t(c)] = neighbourShape(r, options, W, *tm[c], *tv[c], *tn);
            shapeR[size_t(c)] = neighbourShape(r, options, W, *rm[c], *rv[c], *rn);
        }
    if (rendersShape) {
        // neighbourShape takes (n - 1) v as the per-sample variance: with v = s^2 / N, scaled by
        // N / (N - 1) that is s^2, unbiased (the factor (N - 1) / N is 1/2 for two renders).
        const std::vector<float> renderCount(N, float(nRenders));
        std::vector<float> renderVar;
        for (int c = 0; c < 3; ++c) {
            renderVar = *tv[c];
            for (float& v : renderVar) v = float(double(v) * nRenders / (nRenders - 1.0));
            shapeT[size_t(c)] = neighbourShape(r, options, W, *tm[c], renderVar, renderCount);
            shapeR[size_t(c)] = neighbourShape(r, options, W, *rm[c], *rv[c], *rn);
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
                // Two samples in the pixel would do.
                const double nMin = std::min(fewT ? nT : 2.0, fewR ? nR : 2.0);
                w.neededFactor[i] = nMin > 0 ? 2.0 / nMin : kNoFactor;
                r.status[i] = PixelStatus::FewSamples;
                ++r.fewSamples;
                continue;
            }
            ChannelTest ct[3];
            for (int c = 0; c < 3; ++c) {
                ChannelTest& o = ct[c];
                double shapeMean = 0.0;  // the pixel's level for the neighbourhood bound
                const double a = tvals[c], b = rvals[c], va = vt[c], vb = vr[c];
                const double scale = std::max(std::abs(a), std::abs(b));
                if (va == 0.0 && vb == 0.0) {
                    const double tol = options.precision * scale;
                    o.kind = std::abs(a - b) <= tol ? ChannelTest::Equal : ChannelTest::Unequal;
                    continue;
                }
                // With counts in both images: n_eff = n / (1 + C) with C the larger of the two
                // images' relative per-sample variances judged from the pixel's neighbours (the
                // pixel's own noise would select the pixels that missed their rare samples; the
                // larger of the two, because the other image may have caught in the region the
                // rare samples this one missed everywhere there; it can only exclude more);
                // alone in its region, the pixel's own C. The two means weighted by n_eff are the
                // pixel's level for the variance bound below.
                double nEffA = 0.0, nEffB = 0.0;
                // Each image's own relative per-sample variance at this pixel, min((n - 1) v / m^2, n).
                double ownA = 0.0, ownB = 0.0;
                if (pooled) {
                    ownA = a != 0 ? std::min((nT - 1.0) * va / (a * a), nT) : va > 0 ? nT : 0.0;
                    ownB = b != 0 ? std::min((nR - 1.0) * vb / (b * b), nR) : vb > 0 ? nR : 0.0;
                    double cA = shapeT[size_t(c)].meanOfRatios[i], cB = shapeR[size_t(c)].meanOfRatios[i];
                    if (std::isnan(cA)) cA = ownA;
                    if (std::isnan(cB)) cB = ownB;
                    nEffA = nT / (1.0 + std::max({cA, cB, testShapeAt(c, i)}));
                    nEffB = nR / (1.0 + std::max(cA, cB));
                    shapeMean = (nEffA * a + nEffB * b) / (nEffA + nEffB);
                }
                // N renders: each image's shape in its own unit (a render, a sample); the level is
                // the two means weighted by the inverse relative variances of the means.
                double rendersVarA = 0.0, rendersVarB = 0.0, rendersDofA = 0.0, rendersEffB = 0.0, rendersCA = 0.0;
                double rendersRefShape = 0.0;  // per-sample shape here: max(reference neighbours, own, test shape)
                if (rendersShape) {
                    ownA = a != 0 ? std::min(nRenders * va / (a * a), nRenders) : va > 0 ? nRenders : 0.0;
                    ownB = b != 0 ? std::min((nR - 1.0) * vb / (b * b), nR) : vb > 0 ? nR : 0.0;
                    double mA = shapeT[size_t(c)].meanOfRatios[i], mB = shapeR[size_t(c)].meanOfRatios[i];
                    if (std::isnan(mA)) mA = ownA;
                    if (std::isnan(mB)) mB = ownB;
                    const double relA = mA / nRenders, relB = mB / nR;
                    shapeMean = relA + relB > 0 ? (a * relB + b * relA) / (relA + relB) : 0.5 * (a + b);
                    const double mu2 = shapeMean * shapeMean;
                    const double sA = shapeT[size_t(c)].ratioOfSums[i], sB = shapeR[size_t(c)].ratioOfSums[i];
                    const double nbA = std::isnan(sA) ? 0.0 : sA, nbB = std::isnan(sB) ? 0.0 : sB;
                    const double cA = raisedShape(nbA, ownB, nbB), cB = raisedShape(nbB, ownA, nbA);
                    rendersCA = cA;
                    rendersVarA = std::max(va, cA * mu2 / nRenders);
                    // The test's estimator shape, per sample: N S samples (useTestShape needs S).
                    if (useTestShape)
                        rendersVarA = std::max(rendersVarA, testShapeAt(c, i) * mu2 / (nRenders * options.samplesPerRender));
                    rendersVarB = std::max(vb, cB * mu2 / nR);
                    // The bound rests on the 8 neighbours' N - 1 degrees of freedom each; with fewer
                    // than 4 renders it is taken with the pixel's own N - 1 (docs/compare.md,
                    // "Calibration": 8 (N - 1) over-rejected with 2 renders).
                    rendersDofA = (rendersVarA > va && !fewRenders ? 8.0 : 1.0) * (nRenders - 1.0);
                    rendersEffB = nR / (1.0 + mB);
                    rendersRefShape = std::max({mB, ownB, testShapeAt(c, i)});
                }
                if (thr > 0.0) {
                    double effA = std::numeric_limits<double>::infinity(), effB = effA;
                    if (pooled) {
                        effA = nEffA;
                        effB = nEffB;
                    } else if (rendersShape) {
                        // The test's n_eff in its large-n form mu^2 / v = N / C with the variance its
                        // neighbourhood predicts, not its own spread: a rule on the pixel's own
                        // spread drops the pixels whose renders caught rare values and keeps those
                        // that missed them, biasing the tested pixels low (64 x 64, 4 path-traced
                        // renders of 16 spp: mean bias-test Z -2.2, 14 false alarms of 40 at 0.01).
                        // Without a neighbourhood (all deterministic) its own spread, a^2 / v.
                        if (rendersCA > 0) effA = nRenders / rendersCA;
                        else if (va > 0) effA = a * a / va;
                        effB = rendersEffB;
                        // With the renders' samples known, the reference's own shape at the pixel
                        // (from many samples, independent of the test: it selects no test pixel by
                        // its noise) also bounds the test's n_eff, as if the test's estimator had
                        // the reference's shape. Renders that all missed a rare contribution look
                        // smooth, and so do their neighbours when those missed it too (64 samples
                        // of a pixel whose reference says C = 18: p = 6e-11 at 8 renders x 8 spp).
                        // It can only leave more pixels untested.
                        if (options.samplesPerRender > 0)
                            effA = std::min(effA, nRenders * options.samplesPerRender / (1.0 + rendersRefShape));
                    } else if (rendersGuard) {
                        // The test's n_eff under H0: its variance from the reference's shape and the
                        // image's noise ratio when larger (a pixel whose renders all missed a rare
                        // contribution has a small or zero spread).
                        const double mu = 0.5 * (a + b);
                        effA = effectiveSamples(nT, mu, std::max(va, r.varianceRatio[size_t(c)] * vb));
                        effB = effectiveSamples(nR, mu, vb);
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
                        // n_eff grows in proportion to the samples: this many times more would do.
                        o.neededFactor = std::min(effA, effB) > 0 ? thr / std::min(effA, effB) : kNoFactor;
                        continue;
                    }
                }
                // Welch: V = va + vb with the Welch-Satterthwaite degrees of freedom; an image without
                // counts or without variance contributes no term (its n is taken as infinite / it is
                // exact).
                double v = va + vb;
                const double welchV = v;
                double den = 0.0;
                if (va > 0 && std::isfinite(nT)) den += va * va / (nT - 1.0);
                else if (va > 0 && renders) den += va * va / testDof;
                if (vb > 0 && std::isfinite(nR)) den += vb * vb / (nR - 1.0);
                double dof = den > 0 ? v * v / den : std::numeric_limits<double>::infinity();
                // Guard against a variance estimate that is low because the mean is low (a skewed
                // pixel estimator that missed its rare large samples; docs/compare.md): the variance
                // of t - r under H0 is at least what the per-sample variances pooled from both
                // images give, with the test/reference ratio rho of the whole image.
                if (rendersShape) {
                    // The neighbourhood bound of the N renders (above), as for images with counts.
                    if (rendersVarA + rendersVarB > v) {
                        v = rendersVarA + rendersVarB;
                        const double d2 = rendersVarA * rendersVarA / rendersDofA +
                                          (std::isfinite(nR) ? rendersVarB * rendersVarB / (nR - 1.0) : 0.0);
                        dof = d2 > 0 ? v * v / d2 : std::numeric_limits<double>::infinity();
                        ++r.pooledChannels;
                    }
                } else if (rendersGuard) {
                    const double vGuard = r.varianceRatio[size_t(c)] * vb + vb;
                    if (vGuard > v) {
                        v = vGuard;
                        // As for the reference alone: the guard's variance is the reference's, scaled.
                        dof = std::isfinite(nR) ? nR - 1.0 : std::numeric_limits<double>::infinity();
                        ++r.pooledChannels;
                    }
                }
                // Guard against a variance estimate that is low because the mean is low (a skewed
                // pixel estimator whose few samples missed its rare large values; docs/compare.md):
                // each image's variance of the mean is at least C mu^2 / n at this pixel's level mu
                // (the two means weighted by their n_eff), C its neighbourhood's relative
                // per-sample variance, raised by the factor by which the OTHER image's own pixel
                // is heavier-tailed than that image's neighbourhood. The neighbours miss a pixel
                // unlike them (the corner of a light, partly covered by it, between neighbours
                // fully lit or not at all), and only the other image's own samples, if it has many,
                // show the rare values this one missed; the factor carries over how the pixel
                // differs from its neighbours, not the other estimator's shape. It only raises
                // variances of the local test (the bias test uses Welch's, below): it cannot select
                // pixels by their noise.
                if (pooled) {
                    const double mu2 = shapeMean * shapeMean;
                    const double sA = shapeT[size_t(c)].ratioOfSums[i], sB = shapeR[size_t(c)].ratioOfSums[i];
                    const double nbA = std::isnan(sA) ? 0.0 : sA, nbB = std::isnan(sB) ? 0.0 : sB;
                    const double cA = raisedShape(nbA, ownB, nbB), cB = raisedShape(nbB, ownA, nbA);
                    const double fa = std::max({va, cA * mu2 / nT, testShapeAt(c, i) * mu2 / nT});
                    const double fb = std::max(vb, cB * mu2 / nR);
                    if (fa + fb > v) {
                        v = fa + fb;
                        const double d2 = fa * fa / (nT - 1.0) + fb * fb / (nR - 1.0);
                        dof = d2 > 0 ? v * v / d2 : std::numeric_limits<double>::infinity();
                        ++r.pooledChannels;
                    }
                }
                // The precision floor: differences below precision * |value| are float rounding
                // (32-bit storage, float accumulation in the renderer), not Monte Carlo noise.
                o.floorSd = options.precision * scale;
                // The bias test sums these over many pixels with weights that do not depend on
                // them: there the unbiased Welch variance is the right one (the bound above would
                // make it conservative); its per-pixel shortfall is a tail problem of the local test.
                // With fewer than 4 renders the spread of each pixel rests on 1 or 2 degrees of
                // freedom and is correlated with its mean (skewed renders: those that missed the
                // rare values are low and close together): the bias test over-rejected with
                // Welch's variance (2 renders: 7 - 8 alarms of 100 at its level 0.025), so there it
                // takes the bounded variance (conservative).
                o.var = pooled || (rendersShape && !fewRenders) ? welchV : v;
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
}

}  // namespace bdptref::compare_detail
