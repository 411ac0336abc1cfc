// The local test's far tail when every pixel's estimator is skewed and the renders hold a few tens
// of effective samples (docs/compare.md, "The local test's far tail"): under H0 the local p-value
// must not be anti-conservative at the levels validate uses.
#include "bdptref/image_compare.h"

#include <catch2/catch.hpp>

#include <random>

using namespace bdptref;

namespace {

constexpr int kSize = 64;
constexpr int kRenders = 6, kSpp = 17;
constexpr long kRefSpp = 32768;
// Each sample: a small smooth part plus, with chance 1/6, a value 30 times it: per-sample C ~ 4,
// so 6 x 17 samples hold about 20 effective ones (n / (1 + C)).
constexpr double kBase = 0.01, kRare = 0.3, kChance = 1.0 / 6.0;

// The mean and variance of the mean of n samples, drawn through the binomial count of rare ones
// (the smooth part: uniform +-10%, its sum by the normal approximation).
void pixelMean(std::mt19937_64& rng, long n, double* mean, double* varOfMean) {
    const long hits = std::binomial_distribution<long>(n, kChance)(rng);
    const double sdBase = kBase * 0.1 / std::sqrt(3.0);
    const double base = kBase + sdBase / std::sqrt(double(n)) * std::normal_distribution<double>()(rng);
    const double m = base + kRare * double(hits) / double(n);
    const double pHat = double(hits) / double(n);
    const double s2 = kRare * kRare * pHat * (1.0 - pHat) * double(n) / double(n - 1) + sdBase * sdBase;
    *mean = m;
    *varOfMean = s2 / double(n);
}

ExrImage image(std::mt19937_64& rng, long n, bool stats) {
    ExrImage img;
    img.width = img.height = kSize;
    img.window = FilmWindow::full(kSize, kSize);
    const size_t count = size_t(kSize) * kSize;
    std::vector<float> mean(count), var(count);
    for (size_t i = 0; i < count; ++i) {
        double m, v;
        pixelMean(rng, n, &m, &v);
        mean[i] = float(m);
        var[i] = float(v);
    }
    for (const char* c : {"R", "G", "B"}) {
        img.channels[c] = mean;
        if (stats) img.channels[std::string("variance.") + c] = var;
    }
    if (stats) img.channels["count"].assign(count, float(n));
    return img;
}

}  // namespace

TEST_CASE("compare: the local test holds its level for skewed pixels at a few tens of effective samples",
          "[compare][statistics]") {
    std::mt19937_64 rng(20261125);
    const ExrImage reference = image(rng, kRefSpp, true);
    CompareOptions options;
    options.samplesPerRender = kSpp;
    const int trials = 100;
    int below01 = 0, below001 = 0, tested = 0;
    double pLocalMin = 1.0;
    for (int t = 0; t < trials; ++t) {
        std::vector<ExrImage> renders;
        for (int k = 0; k < kRenders; ++k) renders.push_back(image(rng, kSpp, false));
        const CompareResult r = compareImages(combineRenders(renders), reference, options);
        below01 += r.pLocal < 0.01;
        below001 += r.pLocal < 0.001;
        tested += r.tested > 0;
        pLocalMin = std::min(pLocalMin, r.pLocal);
    }
    INFO("trials " << trials << ", tested " << tested << ", pLocal < 0.01: " << below01 << ", < 0.001: " << below001
                   << ", min " << pLocalMin);
    CHECK(tested == trials);
    // Under H0, below01 ~ Binomial(100, 0.01): P(>= 6) = 5e-4.
    CHECK(below01 <= 5);
}
