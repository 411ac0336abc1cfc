// Statistical comparison of a rendered image against a reference: "is this image consistent with
// the reference, up to Monte Carlo noise?" with a p-value, plus plain error metrics. This is what
// `bdptref compare` runs, and what a GPU port's own C++ tests can call. The statistics, their
// assumptions and the layer names a renderer should write are in docs/compare.md.
//
// Inputs are images as read by readImage (EXR, PFM, anything OpenImageIO reads):
//   R, G, B                                the pixel mean (required)
//   variance.R, variance.G, variance.B     the variance OF THE MEAN, s^2 / n (optional)
//   count                                  n, the number of samples in the pixel (optional)
// or, for a renderer that writes only R, G, B: N >= 2 independent renders (different seeds)
// combined by combineRenders (mean over the renders, variance of that mean with N - 1 degrees of
// freedom). A test image without variances is refused by the file loaders (readCompareInput).
//
// The test:
//  * per pixel and channel: Welch's t-test when both images have variances (Welch-Satterthwaite
//    degrees of freedom from the counts; with counts, each image's variance of the mean is at
//    least what the relative per-sample variance of ITS OWN 8 neighbouring pixels predicts at the
//    pixel's level, which keeps a skewed small sample that missed its rare large values from
//    looking significant), otherwise a one-sample t-test (a "z-test" when the count is unknown)
//    of the image without variances against the mean and variance of the one with them;
//    (precision * |value|)^2 is added to every variance; channels with zero variance in both
//    images: equality up to `precision`; pixels with count < 2 or too few effective samples
//    (n_eff = n / (1 + C), C each image's neighbourhood relative variance) are excluded and
//    counted;
//  * the channels of a pixel are combined with the Cauchy combination test (valid whatever the
//    correlation between R, G and B);
//  * local test: the smallest pixel p-value, Sidak-corrected over the m tested pixels,
//    p_local = 1 - (1 - p_min)^m; bias test: per channel, the region is cut into ~64 tiles
//    (biasTileSize), Z = sum_T w_T D_T / sqrt(sum_T w_T^2 V_T) with D_T = sum(t - r) and V_T the
//    summed variance of t - r over the tile's tested pixels, and the weight w_T = 1 / sqrt(V~_T)
//    taken from the NEIGHBOURING tiles' variance (so that it does not depend on the tile's own
//    noise; the precision floors are added linearly); Cauchy-combined over the channels;
//  * global p = 1 - (1 - min(p_local, p_bias))^2 (Sidak over the two tests); the images are
//    consistent when p >= alpha and no zero-variance pixel differs and no pixel is non-finite;
//  * flagged pixels: Benjamini-Hochberg at false discovery rate alpha over the tested pixels,
//    plus every zero-variance mismatch and every non-finite pixel.
#pragma once

#include "bdptref/exr_io.h"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace bdptref {

// ---- distributions (exposed for tests and ports) -------------------------------------------
namespace stats {
// Regularised incomplete beta function I_x(a, b), a, b > 0, x in [0, 1].
double regularizedIncompleteBeta(double a, double b, double x);
// Two-sided p-value P(|T| >= |t|) of Student's t with `dof` > 0 degrees of freedom (real);
// dof = infinity gives the normal distribution.
double studentTTwoSidedP(double t, double dof);
// Two-sided p-value of a standard normal statistic: P(|Z| >= |z|) = erfc(|z| / sqrt 2).
double normalTwoSidedP(double z);
// Standard normal quantile Phi^-1(p), 0 < p < 1 (accurate to ~1e-15 relative, tails included).
double normalQuantile(double p);
// |z| with P(|Z| >= |z|) = p (0 -> a large finite value, 1 -> 0).
double zFromTwoSidedP(double p);
// Sidak: 1 - (1 - p)^m, computed without cancellation.
double sidak(double p, double m);
// Cauchy combination test (Liu & Xie 2020) of k p-values with equal weights: exact for independent
// or identical p-values, and with an accurate tail under any correlation of normal statistics.
double cauchyCombination(const double* p, int k);
}  // namespace stats

// ---- options and results ---------------------------------------------------------------------

struct PixelRegion {
    int x = 0, y = 0, width = 0, height = 0;  // pixels [x, x + width) x [y, y + height)
};

struct CompareOptions {
    double alpha = 0.01;       // significance level of the global test and FDR of the flagged pixels
    double epsilon = 1e-2;     // relMSE = mean((t - r)^2 / (r^2 + epsilon))
    bool useRegion = false;    // compare only `region` (else the whole image)
    PixelRegion region;
    std::vector<uint8_t> mask;  // empty, or width * height of the full image: nonzero = compare
    // A channel is t-tested only when, under the null hypothesis, each image is expected to hold at
    // least this many effective samples n_eff = (sum x)^2 / sum x^2 (docs/compare.md): below that
    // the pixel mean rests on a few rare large samples and the t distribution does not apply.
    // 0 disables the check.
    double minEffectiveSamples = 10.0;
    // Relative precision of the pixel values: channels with zero variance in both images must agree
    // to this relative tolerance, and (precision * |value|)^2 is added to the variance of every
    // difference, so that float rounding (32-bit files, float accumulation) is not taken for a bias.
    double precision = 1e-5;
    int tileSize = 16;          // tiles for "the worst region"
    // With N renders as the test (combineRenders): the samples per pixel of each render, when known
    // (validate knows what it asked for; `compare --samples-per-render S`). Then a channel is also
    // left untested where the reference's own per-sample shape at the pixel says that N S samples
    // hold fewer than minEffectiveSamples effective ones: renders that all missed a rare large
    // contribution show neither it nor its noise (docs/compare.md, "Too few samples"). 0: unknown.
    double samplesPerRender = 0.0;
    // The shape of the test's estimator, when known from elsewhere: per channel (R, G, B), one value
    // per pixel of the full image, the per-sample relative variance C = sigma^2 / mu^2 of an
    // estimator like the test's (estimatorShape of a long render of it; `compare --test-shape`,
    // validate's suite). With the test's samples known (a count layer, or N renders and
    // samplesPerRender) it bounds the test's effective samples, n / (1 + C), and its variance of
    // the mean from below, C mu^2 / n: an estimator whose rare very large samples the test's few
    // samples all missed (light tracing seeing a glossy coat at a grazing angle) looks smooth in
    // the test and in its neighbours, and its reference, made by another estimator, is smooth there
    // (docs/compare.md, "The test's estimator shape"). Empty: unknown. A NaN or a value <= 0 at a
    // pixel: unknown there.
    std::array<std::vector<float>, 3> testShape;
};

enum class TestKind : uint8_t {
    Welch,          // both images have variance layers
    RefVariance,    // only the reference has them: the test image is taken as exact
    TestVariance,   // only the test image has them: the reference is taken as exact
    None,           // no variances: metrics only, no verdict
};
const char* testKindName(TestKind k);  // "welch", "z-ref", "z-test", "none"

// Per-pixel outcome.
enum class PixelStatus : uint8_t {
    Outside,        // outside the region or the mask
    NonFinite,      // NaN or infinity in either image (hard failure, flagged)
    FewSamples,     // count < 2 in an image that has a count layer: excluded
    LowEffective,   // no channel had enough effective samples: excluded
    Equal,          // every channel has zero variance in both images and they agree
    Unequal,        // a zero-variance channel differs (hard failure, flagged)
    Tested,         // at least one channel t-tested
    NoVariance,     // neither image has variances: in the metrics only
};

struct ChannelMetrics {
    double mse = 0, rmse = 0, relMse = 0, mae = 0;
    double maxAbs = 0;
    int maxX = -1, maxY = -1, maxChannel = -1;  // where max |t - r| is (maxChannel: overall only)
    double meanTest = 0, meanRef = 0;
    double bias = 0;                  // mean of t - r
    double biasLow = 0, biasHigh = 0; // its 95% confidence interval
    double relativeBias = 0;          // bias / meanRef (0 when meanRef is 0)
};

struct FlaggedPixel {
    int x = 0, y = 0;
    double p = 1;          // pixel p-value (0 for a hard failure)
    double z = 0;          // signed z-score (test - reference)
    std::array<double, 3> test{}, ref{}, testSigma{}, refSigma{};
    PixelStatus status = PixelStatus::Tested;
};

struct CompareResult {
    int width = 0, height = 0;  // of the full images
    PixelRegion region;         // the compared rectangle
    CompareOptions options;
    TestKind kind = TestKind::None;
    bool testHasCount = false, refHasCount = false;
    bool biasFromVariances = false;  // the bias CI: per-pixel variances (true) or spread of t - r

    std::array<ChannelMetrics, 3> channel;  // R, G, B
    ChannelMetrics overall;                 // all channels together (bias: mean of the three)
    uint64_t metricPixels = 0;              // pixels in the metrics (compared and finite)

    // pixel counts (within region and mask)
    uint64_t compared = 0, tested = 0, equal = 0, unequal = 0, fewSamples = 0, lowEffective = 0, nonFinite = 0;
    uint64_t lowEffectiveChannels = 0;  // channels (of tested pixels too) skipped for low n_eff

    // the tests
    // Welch with counts: the test/reference ratio of per-sample variances (median over pixels; for
    // information), and the number of channels whose variance was raised by the neighbourhood bound
    // (with N renders: by their neighbourhood or kappa bound; see src/verify/compare_channel_test.cpp).
    std::array<double, 3> varianceRatio{1.0, 1.0, 1.0};
    uint64_t pooledChannels = 0, testedChannels = 0;
    double pMin = 1;            // smallest pixel p-value
    int pMinX = -1, pMinY = -1;
    double pLocal = 1;          // Sidak of pMin over `tested` pixels
    std::array<double, 3> biasZ{};  // per channel: Stouffer over the bias tiles, see above
    std::array<double, 3> weightedRelativeBias{}, weightedRelativeBiasSigma{};  // the bias those tiles estimate
    int biasTile = 0, biasTiles = 0;  // side of the bias tiles, number of tiles used
    double pBias = 1;           // Cauchy combination of the three two-sided p-values
    double pGlobal = 1;         // Sidak over {pLocal, pBias}
    double zThreshold = 0;      // |z| a single pixel needs to reject alone (Sidak level)
    bool hasVerdict = false;    // a statistical verdict was possible
    bool consistent = true;     // meaningful only with hasVerdict
    std::string noVerdictReason;
    // No verdict because too few pixels could be tested (fewer than a quarter of those with noise and no
    // rejection among the tested ones); noVerdictReason then starts with "insufficient samples" and
    // says what would suffice: about `samplesFactorNeeded` times the samples in each image (0: n/a).
    bool insufficientSamples = false;
    double samplesFactorNeeded = 0;
    int testRenders = 0;        // N when the test image is the combination of N renders, else 0

    // flagged pixels (BH over tested pixels + hard failures)
    uint64_t flagged = 0;
    double bhThreshold = 0;     // largest pixel p-value that was flagged by BH (0: none)
    int boxX0 = 0, boxY0 = 0, boxX1 = -1, boxY1 = -1;  // bounding box of the flagged pixels (inclusive)
    // The worst region (inclusive): the bounding box when it spans at most two tiles each way, else
    // the tile (options.tileSize) with the most flagged pixels.
    int worstX0 = 0, worstY0 = 0, worstX1 = -1, worstY1 = -1;
    bool worstIsBoundingBox = false;
    uint64_t worstFlagged = 0;
    // Relative bias there: the median over its pixels of sum_c(t - r) / sum_c r.
    double worstRelativeBias = 0;
    std::vector<FlaggedPixel> worst;  // up to 10 most significant pixels, most significant first

    // per-pixel maps of the full image (row-major width * height)
    std::vector<PixelStatus> status;
    std::vector<float> pixelP;       // NaN where not tested
    std::vector<float> pixelZ;       // signed z; NaN where not tested
    std::vector<float> relError;     // mean over channels of (t - r) / (|r| + sqrt(epsilon))
    std::vector<uint8_t> isFlagged;

    std::vector<std::string> warnings;
    std::string sentence;  // "consistent with the reference (p = 0.43, 4096 pixels tested)" / "INCONSISTENT ..."
};

// The per-pixel mean of N >= 2 independent renders (different seeds) of the same image and the
// variance of that mean, s^2 / N with s^2 = sum_k (x_k - mean)^2 / (N - 1) over the renders, as
// R, G, B and variance.R/G/B, with the attribute "bdptref:renders" = N, which tells compareImages
// that these variances have N - 1 degrees of freedom and that the image has no per-sample count
// (each render's own sample count does not enter). Variance or count layers of the renders are
// ignored. `names` (optional, one per render) name the renders in errors. Throws InputError when
// N < 2, a render lacks R, G, B, the sizes or data windows differ.
ExrImage combineRenders(const std::vector<ExrImage>& renders, const std::vector<std::string>& names = {});

// The per-sample relative variance C = min((n - 1) v / m^2, n) of each pixel and channel of a render
// with variance layers and a count (CompareOptions::testShape): NaN where the render says nothing
// (fewer than 2 samples, or mean and variance both 0). A channel with a mean and no variance while
// another channel of the pixel varies (a variance lost in storage) takes that channel's largest C.
// Throws InputError without those layers.
std::array<std::vector<float>, 3> estimatorShape(const ExrImage& render, const std::string& role);

// A warning (empty when none) when an image's variance layers are stored in 16-bit floats with
// values below the half-float normal range (6.1e-5) or zero under a non-zero mean: such variances
// have lost most or all of their bits, and a test relying on them is too confident.
std::string halfVarianceWarning(const ExrImage& img, const std::string& role);

// Reads an image for compare and refuses (InputError naming the file and saying what to write
// instead) display-encoded or integer input: PNG, JPEG, BMP, GIF, TGA, PPM/PGM, WebP by their
// extension, and any other file whose R, G, B values are all multiples of 1/255 or 1/65535 in
// [0, 1] (an 8- or 16-bit integer encoding, e.g. an 8-bit TIFF). Linear float files (EXR, PFM,
// HDR, float TIFF) pass. `role` ("test", "reference") names the file in errors.
ExrImage readCompareInput(const std::string& path, const std::string& role);

// The layer `name` of an image as its beauty: name.R/G/B, name.variance.R/G/B (when present) and
// the count, e.g. "s1t2.weighted" of `render --strategies` or "depth3" of `render --depth-layers`.
// Throws InputError naming `role` ("test", "reference") when the image has no such layer.
ExrImage selectImageLayer(const ExrImage& img, const std::string& name, const std::string& role);

// Refuses (InputError) a test image that has no variance layers and is not a combination of
// renders: a single plain RGB render cannot be told from its noise. The message says what to
// write instead. `path` names the file.
void requireTestStatistics(const ExrImage& test, const std::string& path);

// Compares `test` against `ref` (same size, both with R, G, B). Throws InputError for unusable
// input: size mismatch, missing R/G/B, a region outside the image, a mask of another size, or a
// region and mask that leave no pixel.
CompareResult compareImages(const ExrImage& test, const ExrImage& ref, const CompareOptions& options = {});

// The result as a human-readable report (several lines, ending with the verdict sentence), and as
// JSON (every number of the result, the flagged pixels and the worst ones; no per-pixel maps).
std::string formatCompareReport(const CompareResult& r, const std::string& testName = "test",
                                const std::string& refName = "reference");
std::string compareResultJson(const CompareResult& r, const std::string& testName = "test",
                              const std::string& refName = "reference");

// Loads a mask image (EXR, PNG, ...): a pixel is compared where its first channel (R, Y or A when
// present) is > 0.5. Throws InputError if unreadable or not width x height.
std::vector<uint8_t> loadMask(const std::string& path, int width, int height);

// Parses "x,y,w,h"; throws InputError naming --region.
PixelRegion parseRegion(const std::string& text);

// A false-colour PNG of the compared region: signed per-pixel z-scores (blue: test darker, red:
// test brighter), or the signed relative error when there are no variances, with a legend bar and
// its labels below. Small images are enlarged by an integer factor. Written atomically.
struct HeatmapLayout {
    int scale = 1;              // each compared pixel is scale x scale PNG pixels
    int width = 0, height = 0;  // of the PNG
    int imageHeight = 0;        // rows [0, imageHeight) hold the map; the legend is below
    int barX0 = 0, barX1 = 0, barY0 = 0, barY1 = 0;  // the colour bar (x1, y1 exclusive)
};
// Side of the square tiles of the bias test: about 64 tiles, at least 4 x 4 pixels each.
int biasTileSize(int regionWidth, int regionHeight);

HeatmapLayout heatmapLayout(int regionWidth, int regionHeight);
void writeHeatmapPng(const std::string& path, const CompareResult& r);

}  // namespace bdptref
