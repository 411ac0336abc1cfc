// A pixel at the image's border judged by as many neighbours as one inside it (docs/compare.md,
// "Neighbourhood lower bound"): the 3 x 3 window is shifted to lie inside the image, so a corner
// pixel is judged by 8 neighbours, not 3. Measured in a clean validate (a path tracer on
// sphere-point-light, 6 renders of 2 spp): pixel (63, 0) and its 3 neighbours all missed the
// indirect light, the corner read -12% with a variance of 3e-6 and was flagged at p = 1e-83.
#include "support/render_util.h"

#include "bdptref/image_compare.h"

#include <catch2/catch.hpp>

#include <random>

using namespace bdptref;
using namespace bdptref::test;

namespace {

constexpr int kSize = 16;
constexpr int kRenders = 6, kSpp = 2;
// Each sample: a smooth part plus, with chance 1/4, a value 50 times it (per-sample C ~ 2.6).
constexpr double kBase = 0.1, kRare = 5.0, kChance = 0.25;

// The corner (0, 0) and its three neighbours inside the clipped 3 x 3 window.
bool missesEverything(int x, int y) { return x <= 1 && y <= 1; }

double sample(std::mt19937_64& rng, int x, int y, bool forceMiss) {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const double v = kBase * (1.0 + 0.01 * (2.0 * u(rng) - 1.0));
    if (forceMiss && missesEverything(x, y)) return v;
    return u(rng) < kChance ? v + kRare : v;
}

}  // namespace

TEST_CASE("compare: a corner pixel is judged by eight neighbours, as one inside the image", "[compare][statistics]") {
    std::mt19937_64 rng(20261202);
    std::vector<ExrImage> renders;
    for (int k = 0; k < kRenders; ++k)
        renders.push_back(greyImageOfSamples(kSize, kSpp, false, [&](int x, int y) { return sample(rng, x, y, true); }));
    const ExrImage test = combineRenders(renders, {});
    const ExrImage reference = greyImageOfSamples(kSize, 4096, true, [&](int x, int y) { return sample(rng, x, y, false); });
    CompareOptions options;
    options.samplesPerRender = kSpp;
    options.minEffectiveSamples = 0;  // test every pixel: the corner's verdict is the point
    const CompareResult r = compareImages(test, reference, options);
    INFO(r.sentence);
    // The premise: the four pixels read the smooth part alone (0.1 against a mean of 1.35), each
    // with a variance near 0; only farther neighbours hold the estimator's rare values.
    CHECK(test.at("R", 0, 0) == Approx(kBase).epsilon(0.02));
    CHECK(r.pMinX != 0);  // the corner is not the most significant pixel
    REQUIRE(r.hasVerdict);
    CHECK(r.flagged == 0);
    CHECK(r.consistent);
}
