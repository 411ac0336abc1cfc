// Shared by the compare_*.cpp files (not installed): the formatting helpers, the working state of
// one comparison and its stages. compareImages (compare_global.cpp) runs
//   testPixels (compare_pixels.cpp; each channel's test in compare_channel_test.cpp) ->
//   globalTests (compare_global.cpp) -> addWarnings, writeSentence (compare_report.cpp).
#pragma once

#include "bdptref/image_compare.h"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace bdptref::compare_detail {

extern const char* const kChannelNames[3];   // R, G, B
extern const char* const kVarianceNames[3];  // variance.R, variance.G, variance.B

bool hasRgb(const ExrImage& img);
bool hasVariance(const ExrImage& img);
std::string channelList(const ExrImage& img);  // "R, G, B, count" or "none"

// The attribute combineRenders writes: N, the number of renders the image is the mean of.
inline constexpr const char* kRendersAttribute = "bdptref:renders";
int rendersOf(const ExrImage& img);  // N, or 0 when the image is not a combination of renders

std::string fmtP(double p);
std::string pIs(double p);  // "p = 0.43", or "p < 1e-300" when the p-value underflowed
std::string fmtG(double v, int digits = 4);
std::string fmtPercent(double v);

// Effective number of samples (sum x)^2 / sum x^2 from n, the mean and the variance of the mean
// (s^2 / n); without a count (n = infinity) mean^2 / variance, its large-n value.
double effectiveSamples(double n, double mean, double varOfMean);

// Channel test of one pixel.
struct ChannelTest {
    enum Kind : uint8_t { None, Tested, Equal, Unequal, LowEffective } kind = None;
    double p = 1.0, stat = 0.0, var = 0.0, floorSd = 0.0;  // p-value, t statistic, variance of t - r
                                                          // (without the floor), precision floor
    double neededFactor = 0.0;  // LowEffective: how many times the samples would make it testable
};

// The pair of N >= 3 renders whose noise is most alike (compare_render_independence.cpp): the mean
// over pixels of the product of their standardised deviations from the renders' mean, against the
// -1 / N of independent renders, with its standard error and z-score. first < 0 when nothing was
// measured (fewer than 3 renders or fewer than 30 pixels whose renders differ).
struct RenderCorrelation {
    int first = -1, second = -1;
    size_t pixels = 0;
    double correlation = 0.0, expected = 0.0, standardError = 0.0, zScore = 0.0;
};
RenderCorrelation strongestRenderCorrelation(const std::vector<const std::vector<float>*>& perPixelValues);
// Refusal thresholds of requireIndependentRenders: certain (z above) and material (excess above).
inline constexpr double kSharedNoiseZ = 6.0, kSharedNoiseExcess = 0.05;
// Throws InputError, naming the pair and the likely cause, when two renders share noise.
void requireIndependentRenders(const std::vector<ExrImage>& renders, const std::vector<std::string>& names);

// "No number of samples is known to suffice" (a pixel with no samples or no effective samples).
inline constexpr double kNoFactor = 1e300;

// The working state one stage hands to the next.
struct CompareWork {
    int W = 0, H = 0;
    size_t N = 0;
    const std::vector<float>* tm[3] = {nullptr, nullptr, nullptr};  // test means
    const std::vector<float>* rm[3] = {nullptr, nullptr, nullptr};  // reference means
    const std::vector<float>* tv[3] = {nullptr, nullptr, nullptr};  // test variances of the mean
    const std::vector<float>* rv[3] = {nullptr, nullptr, nullptr};  // reference variances of the mean
    const std::vector<float>* tn = nullptr;                         // counts (or null)
    const std::vector<float>* rn = nullptr;
    bool useTestVar = false, useRefVar = false;
    std::vector<double> pixelPd;  // double-precision pixel p-values (tested pixels)
    // Per channel: t - r, its variance (without the precision floor) and the floor of every
    // t-tested pixel (NaN / 0 elsewhere), for the bias test.
    std::array<std::vector<double>, 3> diff, diffVar, diffFloor;
    // Per pixel not tested for lack of samples: how many times its samples would make it testable
    // (kNoFactor: unknown); 0 elsewhere.
    std::vector<double> neededFactor;
};

// One image's estimator shape around each pixel of the region, from its 8 neighbours j that are
// compared, finite, have count >= 2 and are not all-zero (compare_neighbourhood.cpp); NaN outside
// the region and where no neighbour qualifies.
struct NeighbourShape {
    // mean_j min((n_j - 1) v_j / m_j^2, n_j): every neighbour's shape counts alike, so one that
    // caught a rare large sample, or a dark one next to bright ones, raises it (for n_eff).
    std::vector<double> meanOfRatios;
    // sum_j (n_j - 1) v_j / sum_j m_j^2: the neighbourhood as one pool of samples, ruled by its
    // bright pixels (for the variance bound, which is scaled by the pixel's own level).
    std::vector<double> ratioOfSums;
};
NeighbourShape neighbourShape(const CompareResult& r, const CompareOptions& options, int W,
                              const std::vector<float>& mean, const std::vector<float>& var,
                              const std::vector<float>& count);

void testPixels(const ExrImage& test, const ExrImage& ref, const CompareOptions& options, CompareResult& r,
                CompareWork& w);
void globalTests(const CompareOptions& options, CompareResult& r, const CompareWork& w);
void addWarnings(const ExrImage& test, const ExrImage& ref, CompareResult& r);
void writeSentence(CompareResult& r);

const char* statusName(PixelStatus s);
std::string methodDescription(const CompareResult& r);
int exitCodeOf(const CompareResult& r);

}  // namespace bdptref::compare_detail
