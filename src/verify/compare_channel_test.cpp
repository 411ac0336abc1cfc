// The test of one channel of one pixel (docs/compare.md, "Per pixel and channel"): the
// zero-variance rule, each image's shape at the pixel, the effective-sample rule, Welch's variance
// and degrees of freedom, the bounds that raise the variance, the precision floor. testChannel
// reads as that list.
#include "verify/compare_channel_test.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace bdptref::compare_detail {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

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

// The two images' shapes at the pixel, for the effective-sample rule and the variance bounds.
struct ChannelShape {
    double shapeMean = 0.0;  // the pixel's level for the neighbourhood bound
    // Each image's own relative per-sample variance at this pixel, min((n - 1) v / m^2, n).
    double ownA = 0.0, ownB = 0.0;
    double nEffA = 0.0, nEffB = 0.0;  // pooled: each image's n_eff
    // N renders: the bounded variances of the means, the test's bound's degrees of freedom, the
    // reference's n_eff, the test's raised shape and the per-sample shape at the pixel
    // (max(reference neighbours, own, test shape)).
    double rendersVarA = 0.0, rendersVarB = 0.0, rendersDofA = 0.0, rendersEffB = 0.0, rendersCA = 0.0;
    double rendersRefShape = 0.0;
};

// The variance of t - r and its degrees of freedom.
struct ChannelVariance {
    double v = 0.0;       // bounded (the local test)
    double welchV = 0.0;  // Welch's v_a + v_b (the bias test)
    double dof = kInf;
};

// docs/compare.md "Per pixel and channel", zero variance in both images: equal up to the precision.
ChannelTest::Kind zeroVarianceKind(const PixelRules& rules, const ChannelValues& v) {
    const double scale = std::max(std::abs(v.a), std::abs(v.b));
    const double tol = rules.precision * scale;
    return std::abs(v.a - v.b) <= tol ? ChannelTest::Equal : ChannelTest::Unequal;
}

// docs/compare.md "Per pixel and channel", too few samples: n_eff of both images with counts.
void pooledShape(const PixelRules& rules, const ChannelValues& v, ChannelShape& s) {
    // With counts in both images: n_eff = n / (1 + C) with C the larger of the two
    // images' relative per-sample variances judged from the pixel's neighbours (the
    // pixel's own noise would select the pixels that missed their rare samples; the
    // larger of the two, because the other image may have caught in the region the
    // rare samples this one missed everywhere there; it can only exclude more);
    // alone in its region, the pixel's own C. The two means weighted by n_eff are the
    // pixel's level for the variance bound below.
    const double a = v.a, b = v.b, va = v.va, vb = v.vb, nT = v.nT, nR = v.nR;
    const size_t c = size_t(v.c), i = v.i;
    s.ownA = a != 0 ? std::min((nT - 1.0) * va / (a * a), nT) : va > 0 ? nT : 0.0;
    s.ownB = b != 0 ? std::min((nR - 1.0) * vb / (b * b), nR) : vb > 0 ? nR : 0.0;
    double cA = rules.shapeT[c].meanOfRatios[i], cB = rules.shapeR[c].meanOfRatios[i];
    if (std::isnan(cA)) cA = s.ownA;
    if (std::isnan(cB)) cB = s.ownB;
    s.nEffA = nT / (1.0 + std::max({cA, cB, rules.testShapeAt(v.c, i)}));
    s.nEffB = nR / (1.0 + std::max(cA, cB));
    s.shapeMean = (s.nEffA * a + s.nEffB * b) / (s.nEffA + s.nEffB);
}

// docs/compare.md "Per pixel and channel", neighbourhood lower bound with N renders (and "Inputs"):
// each image's shape in its own unit.
void rendersShape(const PixelRules& rules, const ChannelValues& v, ChannelShape& s) {
    // N renders: each image's shape in its own unit (a render, a sample); the level is
    // the two means weighted by the inverse relative variances of the means.
    const double a = v.a, b = v.b, va = v.va, vb = v.vb, nR = v.nR, nRenders = rules.nRenders;
    const size_t c = size_t(v.c), i = v.i;
    s.ownA = a != 0 ? std::min(nRenders * va / (a * a), nRenders) : va > 0 ? nRenders : 0.0;
    s.ownB = b != 0 ? std::min((nR - 1.0) * vb / (b * b), nR) : vb > 0 ? nR : 0.0;
    double mA = rules.shapeT[c].meanOfRatios[i], mB = rules.shapeR[c].meanOfRatios[i];
    if (std::isnan(mA)) mA = s.ownA;
    if (std::isnan(mB)) mB = s.ownB;
    const double relA = mA / nRenders, relB = mB / nR;
    s.shapeMean = relA + relB > 0 ? (a * relB + b * relA) / (relA + relB) : 0.5 * (a + b);
    const double mu2 = s.shapeMean * s.shapeMean;
    const double sA = rules.shapeT[c].ratioOfSums[i], sB = rules.shapeR[c].ratioOfSums[i];
    const double nbA = std::isnan(sA) ? 0.0 : sA, nbB = std::isnan(sB) ? 0.0 : sB;
    const double cA = raisedShape(nbA, s.ownB, nbB), cB = raisedShape(nbB, s.ownA, nbA);
    s.rendersCA = cA;
    s.rendersVarA = std::max(va, cA * mu2 / nRenders);
    // The test's estimator shape, per sample: N S samples (useTestShape needs S).
    if (rules.useTestShape)
        s.rendersVarA = std::max(s.rendersVarA, rules.testShapeAt(v.c, i) * mu2 / (nRenders * rules.samplesPerRender));
    s.rendersVarB = std::max(vb, cB * mu2 / nR);
    // The bound rests on the 8 neighbours' N - 1 degrees of freedom each; with fewer
    // than 4 renders it is taken with the pixel's own N - 1 (docs/compare.md,
    // "Calibration": 8 (N - 1) over-rejected with 2 renders).
    s.rendersDofA = (s.rendersVarA > va && !rules.fewRenders ? 8.0 : 1.0) * (nRenders - 1.0);
    s.rendersEffB = nR / (1.0 + mB);
    s.rendersRefShape = std::max({mB, s.ownB, rules.testShapeAt(v.c, i)});
}

// docs/compare.md "Per pixel and channel", too few samples: false (and o LowEffective) when one
// image is expected to hold fewer than --min-effective effective samples.
bool enoughEffectiveSamples(const PixelRules& rules, const ChannelValues& v, const ChannelShape& s,
                            const CompareResult& r, ChannelTest& o) {
    const double a = v.a, b = v.b, va = v.va, vb = v.vb, nT = v.nT, nR = v.nR;
    const double nRenders = rules.nRenders, thr = rules.minEffective;
    double effA = kInf, effB = effA;
    if (rules.pooled) {
        effA = s.nEffA;
        effB = s.nEffB;
    } else if (rules.rendersShape) {
        // The test's n_eff in its large-n form mu^2 / v = N / C with the variance its
        // neighbourhood predicts, not its own spread: a rule on the pixel's own
        // spread drops the pixels whose renders caught rare values and keeps those
        // that missed them, biasing the tested pixels low (64 x 64, 4 path-traced
        // renders of 16 spp: mean bias-test Z -2.2, 14 false alarms of 40 at 0.01).
        // Without a neighbourhood (all deterministic) its own spread, a^2 / v.
        if (s.rendersCA > 0) effA = nRenders / s.rendersCA;
        else if (va > 0) effA = a * a / va;
        effB = s.rendersEffB;
        // With the renders' samples known, the reference's own shape at the pixel
        // (from many samples, independent of the test: it selects no test pixel by
        // its noise) also bounds the test's n_eff, as if the test's estimator had
        // the reference's shape. Renders that all missed a rare contribution look
        // smooth, and so do their neighbours when those missed it too (64 samples
        // of a pixel whose reference says C = 18: p = 6e-11 at 8 renders x 8 spp).
        // It can only leave more pixels untested.
        if (rules.samplesPerRender > 0)
            effA = std::min(effA, nRenders * rules.samplesPerRender / (1.0 + s.rendersRefShape));
    } else if (rules.rendersGuard) {
        // The test's n_eff under H0: its variance from the reference's shape and the
        // image's noise ratio when larger (a pixel whose renders all missed a rare
        // contribution has a small or zero spread).
        const double mu = 0.5 * (a + b);
        effA = effectiveSamples(nT, mu, std::max(va, r.varianceRatio[size_t(v.c)] * vb));
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
        return false;
    }
    return true;
}

// docs/compare.md "Per pixel and channel", Welch's t-test: V = v_a + v_b, Welch-Satterthwaite dof.
ChannelVariance welchVariance(const PixelRules& rules, const ChannelValues& v) {
    // Welch: V = va + vb with the Welch-Satterthwaite degrees of freedom; an image without
    // counts or without variance contributes no term (its n is taken as infinite / it is
    // exact).
    const double va = v.va, vb = v.vb, nT = v.nT, nR = v.nR;
    ChannelVariance w;
    w.v = va + vb;
    w.welchV = w.v;
    double den = 0.0;
    if (va > 0 && std::isfinite(nT)) den += va * va / (nT - 1.0);
    else if (va > 0 && rules.renders) den += va * va / rules.testDof;
    if (vb > 0 && std::isfinite(nR)) den += vb * vb / (nR - 1.0);
    w.dof = den > 0 ? w.v * w.v / den : kInf;
    return w;
}

// docs/compare.md "Inputs" (N renders): the neighbourhood bound of the renders; true when it
// raised the variance.
bool rendersNeighbourhoodBound(const ChannelValues& v, const ChannelShape& s, ChannelVariance& w) {
    // The neighbourhood bound of the N renders (rendersShape), as for images with counts.
    const double nR = v.nR;
    if (s.rendersVarA + s.rendersVarB > w.v) {
        w.v = s.rendersVarA + s.rendersVarB;
        const double d2 = s.rendersVarA * s.rendersVarA / s.rendersDofA +
                          (std::isfinite(nR) ? s.rendersVarB * s.rendersVarB / (nR - 1.0) : 0.0);
        w.dof = d2 > 0 ? w.v * w.v / d2 : kInf;
        return true;
    }
    return false;
}

// docs/compare.md "Inputs" (N renders, a reference without a count: the kappa bound): the test's
// variance at least the image's noise ratio times the reference's; true when it raised it.
bool rendersRatioBound(const ChannelValues& v, const CompareResult& r, ChannelVariance& w) {
    // Guard against a variance estimate that is low because the mean is low (a skewed
    // pixel estimator that missed its rare large samples; docs/compare.md): the variance
    // of t - r under H0 is at least what the per-sample variances pooled from both
    // images give, with the test/reference ratio rho of the whole image.
    const double vb = v.vb, nR = v.nR;
    const double vGuard = r.varianceRatio[size_t(v.c)] * vb + vb;
    if (vGuard > w.v) {
        w.v = vGuard;
        // As for the reference alone: the guard's variance is the reference's, scaled.
        w.dof = std::isfinite(nR) ? nR - 1.0 : kInf;
        return true;
    }
    return false;
}

// docs/compare.md "Per pixel and channel", neighbourhood lower bound with counts in both images
// (raised by the other image's excess); true when it raised the variance.
bool pooledBound(const PixelRules& rules, const ChannelValues& v, const ChannelShape& s, ChannelVariance& w) {
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
    const double va = v.va, vb = v.vb, nT = v.nT, nR = v.nR;
    const size_t c = size_t(v.c), i = v.i;
    const double mu2 = s.shapeMean * s.shapeMean;
    const double sA = rules.shapeT[c].ratioOfSums[i], sB = rules.shapeR[c].ratioOfSums[i];
    const double nbA = std::isnan(sA) ? 0.0 : sA, nbB = std::isnan(sB) ? 0.0 : sB;
    const double cA = raisedShape(nbA, s.ownB, nbB), cB = raisedShape(nbB, s.ownA, nbA);
    const double fa = std::max({va, cA * mu2 / nT, rules.testShapeAt(v.c, i) * mu2 / nT});
    const double fb = std::max(vb, cB * mu2 / nR);
    if (fa + fb > w.v) {
        w.v = fa + fb;
        const double d2 = fa * fa / (nT - 1.0) + fb * fb / (nR - 1.0);
        w.dof = d2 > 0 ? w.v * w.v / d2 : kInf;
        return true;
    }
    return false;
}

// docs/compare.md "Per pixel and channel", precision floor: the t statistic and its p-value.
void precisionFloorAndP(const PixelRules& rules, const ChannelValues& v, const ChannelVariance& w, ChannelTest& o) {
    // The precision floor: differences below precision * |value| are float rounding
    // (32-bit storage, float accumulation in the renderer), not Monte Carlo noise.
    const double scale = std::max(std::abs(v.a), std::abs(v.b));
    o.floorSd = rules.precision * scale;
    // The bias test sums these over many pixels with weights that do not depend on
    // them: there the unbiased Welch variance is the right one (the bound above would
    // make it conservative); its per-pixel shortfall is a tail problem of the local test.
    // With fewer than 4 renders the spread of each pixel rests on 1 or 2 degrees of
    // freedom and is correlated with its mean (skewed renders: those that missed the
    // rare values are low and close together): the bias test over-rejected with
    // Welch's variance (2 renders: 7 - 8 alarms of 100 at its level 0.025), so there it
    // takes the bounded variance (conservative).
    o.var = rules.pooled || (rules.rendersShape && !rules.fewRenders) ? w.welchV : w.v;
    o.stat = (v.a - v.b) / std::sqrt(w.v + o.floorSd * o.floorSd);
    o.p = stats::studentTTwoSidedP(o.stat, w.dof);
    o.kind = ChannelTest::Tested;
}

}  // namespace

ChannelTest testChannel(const PixelRules& rules, const ChannelValues& v, CompareResult& r) {
    ChannelTest o;
    if (v.va == 0.0 && v.vb == 0.0) {
        o.kind = zeroVarianceKind(rules, v);
        return o;
    }
    ChannelShape s;
    if (rules.pooled) pooledShape(rules, v, s);
    if (rules.rendersShape) rendersShape(rules, v, s);
    if (rules.minEffective > 0.0 && !enoughEffectiveSamples(rules, v, s, r, o)) return o;
    ChannelVariance w = welchVariance(rules, v);
    bool raised = false;
    if (rules.rendersShape) raised = rendersNeighbourhoodBound(v, s, w);
    else if (rules.rendersGuard) raised = rendersRatioBound(v, r, w);
    if (raised) ++r.pooledChannels;
    if (rules.pooled && pooledBound(rules, v, s, w)) ++r.pooledChannels;
    precisionFloorAndP(rules, v, w, o);
    ++r.testedChannels;
    return o;
}

}  // namespace bdptref::compare_detail
