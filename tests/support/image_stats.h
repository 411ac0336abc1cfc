// Per-pixel statistical comparison of two rendered images: "do these two estimators have the
// same expected value in every pixel?" (Jung et al., JCGT 2020: Welch's t-test per pixel from
// sums and sums of squares).
//
// Method:
//  * Each image gives, per pixel and channel, the sample mean m, the unbiased variance of that
//    mean v = s^2 / n and the number of samples n (for a Film: one sample per pass, so splats
//    landing in the pixel during a pass are part of that pass's sample and v is exact).
//  * Per channel, Welch's t = (m_a - m_b) / sqrt(v_a + v_b) with the Welch-Satterthwaite degrees
//    of freedom nu = (v_a + v_b)^2 / (v_a^2 / (n_a - 1) + v_b^2 / (n_b - 1)); the two-sided
//    p-value is P(|T_nu| >= |t|) = I_{nu / (nu + t^2)}(nu / 2, 1 / 2), I the regularised
//    incomplete beta function (implemented here, Numerical Recipes' continued fraction).
//  * A pixel is REJECTED when any of its k tested channels has p < alpha / k (Bonferroni over the
//    channels, which are correlated): whatever that correlation, a pixel where both images have
//    the same expectation is rejected with probability <= alpha.
//  * A channel where both variances are 0 (e.g. black in both images, or a deterministic value)
//    is not t-tested but checked for EXACT equality of the means; any mismatch fails the whole
//    comparison. Pixels with fewer than 2 samples in either image are skipped (counted).
//  * Rare events: the samples are non-negative (radiance), and a pixel whose mean rests on a
//    handful of large samples (a small light hit by BSDF sampling, a caustic) has a strongly
//    skewed mean, for which the t statistic is far from Student's t: an image where no sample
//    hit has variance 0, and the test would reject a perfectly good pair. So a channel is
//    t-tested only when BOTH images have at least `minEffectiveSamples` effective samples,
//    n_eff = (sum x)^2 / (sum x^2) = n m^2 / ((n - 1) v + m^2), v the variance of the mean
//    (n_eff = n for a constant, k for k equal hits among zeros); the others are counted
//    in `lowEffective` and not tested. The threshold (10) only removes pixels where the t-test
//    is meaningless; a render meant to be compared per pixel must have n_eff well above it in
//    (almost) every pixel, which the callers check through `tested`.
//  * Under H0 (equal expectations everywhere) and independent pixels, the number of rejected
//    pixels among the m tested ones is stochastically at most Binomial(m, alpha). The comparison
//    PASSES when rejected <= q, q the smallest integer with P(Binomial(m, alpha) <= q) >= 1 - 1e-4
//    (computed exactly from the binomial cdf; alpha = kPixelAlpha = 0.01 by default, e.g. q = 16
//    for m = 576, q = 8 for m = 144): a false failure has probability <= 1e-4 per comparison,
//    while a systematic bias that shifts many pixels' t-statistics is caught.
//    (Pixels of a light-tracing or BDPT image are slightly dependent within a pass, since one
//    light path can splat into several pixels; that widens the rejection count's distribution a
//    little beyond the binomial, which the 1e-4 tail leaves room for.)
//  * Welch's t-test assumes normal pixel means; with hundreds of samples per pixel the CLT makes
//    that accurate enough at alpha = 0.01 for the scenes here (moderately skewed estimators:
//    correct PT, LT and BDPT renders of the Cornell boxes reject 0-8 of 576 pixels, 5.76
//    expected at the nominal level; Bonferroni makes the test a little conservative).
//    It needs a FINITE variance: an estimator whose contributions are unbounded with an
//    infinite variance (e.g. an unweighted interior BDPT connection near a concave edge, where
//    G = cos cos / d^2 blows up) has skewed sample means that no test on means and variances can
//    judge; compare such estimators where their variance is finite.
#pragma once

#include "bdptref/film.h"
#include "bdptref/math.h"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace bdptref::test {

// ---- distributions ------------------------------------------------------------------------

// Regularised incomplete beta function I_x(a, b), a, b > 0, 0 <= x <= 1.
double regularizedBeta(double a, double b, double x);
// Two-sided p-value of Student's t with `dof` (> 0, real) degrees of freedom: P(|T| >= |t|).
double studentTTwoSidedP(double t, double dof);
// P(X <= k) for X ~ Binomial(m, p), summed exactly term by term (log-space pmf).
double binomialCdf(uint64_t k, uint64_t m, double p);
// Smallest q with P(Binomial(m, p) <= q) >= level.
uint64_t binomialQuantile(uint64_t m, double p, double level);

// ---- images of per-pixel moments ----------------------------------------------------------

struct PixelMoments {
    DVec3 mean{0.0};
    DVec3 varianceOfMean{0.0};
    uint64_t count = 0;
};

struct MomentImage {
    int width = 0, height = 0;
    std::vector<PixelMoments> pixels;  // row-major
    const PixelMoments& at(int x, int y) const { return pixels[size_t(y) * size_t(width) + size_t(x)]; }
};

// Pixel rectangle [x0, x1) x [y0, y1).
struct PixelRect {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    int width() const { return x1 - x0; }
    int height() const { return y1 - y0; }
};

MomentImage momentsOf(const Film& film);
MomentImage momentsOf(const Film& film, const PixelRect& region);
// Any other source (e.g. a strategy layer): f(x, y) gives the moments of pixel (x, y).
MomentImage momentsFrom(int width, int height, const std::function<PixelMoments(int x, int y)>& f);

// Blocks of block x block pixels merged into one (the image's size must be a multiple of
// `block`): mean = average of the means, variance of the mean = sum of the variances / block^4.
// Exact when the pixels of a pass are independent (camera-side strategies: each pixel has its
// own subpaths) and conservative when they are negatively correlated (a single t = 1 strategy
// layer: each light path splats into at most one pixel of it). NOT valid for an image whose pass
// puts correlated values into several pixels (a light-tracing or BDPT beauty image).
MomentImage mergeBlocks(const MomentImage& img, int block);

// ---- the comparison -----------------------------------------------------------------------

// Default per-pixel significance level and the level of the binomial bound (see above).
constexpr double kPixelAlpha = 0.01;
constexpr double kBinomialLevel = 1.0 - 1e-4;
constexpr double kMinEffectiveSamples = 10.0;

// Effective number of samples (sum x)^2 / (sum x^2) of a channel, from its moments.
double effectiveSamples(double mean, double varianceOfMean, uint64_t count);

struct ImageComparison {
    double alpha = kPixelAlpha;
    uint64_t pixels = 0;            // pixels compared
    uint64_t skipped = 0;           // fewer than 2 samples in either image
    uint64_t exactOnly = 0;         // every channel has zero variance in both: equality only
    uint64_t lowEffective = 0;      // pixels with no channel testable (too few effective samples)
    uint64_t lowEffectiveChannels = 0;  // channels (of all pixels) not t-tested for that reason
    uint64_t tested = 0;            // m: pixels with at least one t-tested channel
    uint64_t rejected = 0;          // tested pixels with min_c p_c < alpha / k
    uint64_t bound = 0;             // binomial quantile of Binomial(tested, alpha) at kBinomialLevel
    uint64_t exactMismatches = 0;   // zero-variance channels whose means differ (hard failure)
    double minP = 1.0;              // smallest per-channel p-value seen
    std::string report;             // summary and the worst pixels, for INFO()
    bool passed() const { return exactMismatches == 0 && rejected <= bound; }
};

// a and b must have the same size. Labels name the two images in the report.
ImageComparison compareImages(const MomentImage& a, const MomentImage& b, double alpha = kPixelAlpha,
                              const std::string& labelA = "a", const std::string& labelB = "b",
                              double minEffectiveSamples = kMinEffectiveSamples);
// Whole films (same resolution).
ImageComparison compareFilms(const Film& a, const Film& b, double alpha = kPixelAlpha,
                             const std::string& labelA = "a", const std::string& labelB = "b");
// Region `ra` of film a against region `rb` of film b (same size; e.g. a crop render against
// the same pixels of a full render, whatever the two films' own resolutions and offsets).
ImageComparison compareFilmRegions(const Film& a, const PixelRect& ra, const Film& b, const PixelRect& rb,
                                   double alpha = kPixelAlpha, const std::string& labelA = "a",
                                   const std::string& labelB = "b");

}  // namespace bdptref::test
