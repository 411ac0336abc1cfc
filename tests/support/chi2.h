// Pearson chi-square goodness-of-fit tests of samplers against their densities, for the unit
// tests of every sampling routine (BSDFs, warps, light samplers, discrete distributions).
//
// Method (the same as Mitsuba's chi2 test):
//  * draw n samples from the sampler and histogram them into cells;
//  * expected count of a cell = n * (integral of the pdf over the cell), integrated numerically by
//    error-controlled adaptive midpoint quadrature (so narrow lobes, ridges and horizons are
//    resolved) to 0.02 standard errors of the cell's count; the pdf is NOT renormalised;
//  * samples the sampler reports as failed (returns false, e.g. absorbed or delta samples) go to an
//    extra "lost" cell whose expected count is n * (1 - integral of the pdf over the domain), so a
//    sampler that loses more (or less) mass than its pdf says is caught too;
//  * cells with expected count < 5 are pooled into one cell (Cochran's rule); if the pool is still
//    below 5 it is merged into the smallest remaining cell;
//  * statistic = sum (O - E)^2 / E, dof = cells - 1, p-value = Q(dof/2, statistic/2) with Q the
//    regularised upper incomplete gamma function (implemented here, Numerical Recipes' series and
//    continued fraction).
// Hard failures (p = 0, explained in the report): a sample where the pdf is zero or not finite, a
// non-finite or non-unit direction, a point outside the domain, a pdf that integrates above 1.
//
// Use: REQUIRE(result.pValue > sidakAlpha(0.01, k)) where k is the number of chi-square tests in
// the file, so that the whole file has a 1% false-failure rate. Seeds are fixed, so each test
// is deterministic; `report` says what went wrong (print it with INFO(result.report)).
#pragma once

#include "bdptref/math.h"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace bdptref {
namespace test {

struct Chi2Result {
    double pValue = 0.0;
    double statistic = 0.0;
    int dof = 0;
    std::string report;
};

// Per-test significance level that gives a family-wise false-rejection rate of familyAlpha over
// numTests independent tests (Šidák): 1 - (1 - familyAlpha)^(1 / numTests).
double sidakAlpha(double familyAlpha, int numTests);

// Regularised incomplete gamma functions P(a, x) and Q(a, x) = 1 - P(a, x), a > 0, x >= 0.
double regularizedGammaP(double a, double x);
double regularizedGammaQ(double a, double x);
// P(X >= statistic) for X ~ chi-square with dof degrees of freedom (1 when dof <= 0).
double chi2Survival(double statistic, int dof);

// Pearson's test from cell counts (observed and expected must have equal totals for the test to
// be meaningful). A cell with expected 0 and observed > 0 is a hard failure.
Chi2Result chi2FromCounts(const std::vector<double>& observed, const std::vector<double>& expected,
                          double minExpected = 5.0);

// --- Unit directions ------------------------------------------------------------------------

enum class ThetaBinning {
    UniformCos,      // thetaBins equal bins of cos(theta) in [-1, 1]
    LogOneMinusCos,  // bin 0: 1 - cos(theta) in [0, minOneMinusCos]; bins 1..thetaBins-1 equal
                     // in log(1 - cos(theta)) up to 1 - cos(theta) = 2: resolves narrow lobes
                     // centred on frame.n (e.g. glossy reflection about the mirror direction)
};

struct DirectionBinning {
    Frame frame;  // theta is measured from frame.n, phi from frame.s towards frame.t
    int thetaBins = 10;
    int phiBins = 20;
    ThetaBinning theta = ThetaBinning::UniformCos;
    double minOneMinusCos = 1e-6;  // LogOneMinusCos only
};

// sample(i, &dir): the i-th sample (a pure function of i); false = no direction (lost mass).
using DirectionSampler = std::function<bool(uint64_t sampleIndex, Vec3* dir)>;
// Solid-angle density of the directions the sampler returns true for.
using DirectionPdf = std::function<double(const Vec3& dir)>;

// Bins over (cos theta in [-1,1]) x (phi in [0, 2 pi)) about +z.
Chi2Result chi2DirectionTest(const DirectionSampler& sample, const DirectionPdf& pdf, uint64_t n, int thetaBins,
                             int phiBins);
Chi2Result chi2DirectionTest(const DirectionSampler& sample, const DirectionPdf& pdf, uint64_t n,
                             const DirectionBinning& binning);

// --- Points in a rectangle (unit square by default) ------------------------------------------

using PointSampler = std::function<bool(uint64_t sampleIndex, Vec2* point)>;
using PointPdf = std::function<double(const Vec2& point)>;  // density w.r.t. area in the rectangle

// Bins the rectangle [lo, hi] into xBins x yBins equal cells. Points outside it are a failure.
Chi2Result chi2Test2D(const PointSampler& sample, const PointPdf& pdf, uint64_t n, int xBins, int yBins,
                      Vec2 lo = Vec2(0.f), Vec2 hi = Vec2(1.f));

// --- Discrete distributions -------------------------------------------------------------------

// sample(i, &index); expected frequency of index k is n * pmf[k]; 1 - sum(pmf) is lost mass.
Chi2Result chi2DiscreteTest(const std::function<bool(uint64_t sampleIndex, size_t* index)>& sample,
                            const std::vector<double>& pmf, uint64_t n);

// --- Random numbers for tests -----------------------------------------------------------------

// A counter-based generator for tests: the stream of (seed, index) is a pure function of both,
// so sample i of a test does not depend on the other samples. splitmix64 (Steele et al. 2014).
class TestRng {
public:
    TestRng(uint64_t seed, uint64_t index) : state_(mix(mix(seed + 0x632be59bd9b4e019ull) ^ (index * kGolden))) {}
    uint64_t nextU64() {
        state_ += kGolden;
        return mix(state_);
    }
    float uniform() { return float(nextU64() >> 40) * 0x1p-24f; }  // [0,1), 24 bits
    Vec2 uniform2D() {
        const float a = uniform();
        return Vec2(a, uniform());
    }
    double uniformDouble() { return double(nextU64() >> 11) * 0x1p-53; }

private:
    static constexpr uint64_t kGolden = 0x9e3779b97f4a7c15ull;
    static uint64_t mix(uint64_t z) {
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
        return z ^ (z >> 31);
    }
    uint64_t state_;
};

}  // namespace test
}  // namespace bdptref
