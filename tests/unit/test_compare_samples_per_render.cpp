// compare with N renders and their samples per render known (CompareOptions::samplesPerRender,
// `compare --samples-per-render`, what validate passes): the reference's own shape at a pixel
// bounds the renders' effective samples (docs/compare.md, "Too few samples").
#include "support/render_util.h"

#include "bdptref/exr_io.h"
#include "bdptref/image_compare.h"

#include <catch2/catch.hpp>

#include <random>

using namespace bdptref;
using namespace bdptref::test;

namespace {

constexpr int kSize = 16;
constexpr int kRenders = 8, kSpp = 8, kRefSpp = 8192;
constexpr double kBackground = 0.1;   // every pixel's smooth part
constexpr double kRareValue = 2.5;    // a rare sample of the 2 x 2 pixels at the centre...
constexpr double kRareChance = 1.0 / 18.0;  // ...drawn with this chance: mean +0.139, per-sample C ~ 13

bool centre(int x, int y) { return (x == 7 || x == 8) && (y == 7 || y == 8); }

// A sample: the background with a little noise (uniform, +-10%), plus at the centre the rare value.
double sample(std::mt19937_64& rng, int x, int y, bool rareAllowed) {
    double v = kBackground * (1.0 + 0.1 * std::uniform_real_distribution<double>(-1.0, 1.0)(rng));
    if (rareAllowed && centre(x, y) && std::uniform_real_distribution<double>(0.0, 1.0)(rng) < kRareChance) v += kRareValue;
    return v;
}

// An image of `spp` samples per pixel (grey); with `stats` its variance of the mean and count.
ExrImage render(std::mt19937_64& rng, int spp, bool rareAllowed, bool stats) {
    return greyImageOfSamples(kSize, spp, stats, [&](int x, int y) { return sample(rng, x, y, rareAllowed); });
}

}  // namespace

TEST_CASE("compare: renders that all missed a rare contribution are not tested when their samples are known", "[compare][statistics]") {
    // Eight renders of 8 spp whose centre pixels all missed the rare sample (64 samples miss it
    // with probability (17/18)^64 = 2.6%: here by construction), against a correct 8192-spp
    // reference. The renders' centre looks as smooth as its neighbours, so without the samples
    // per render the test is far too sure; with them, the reference's own shape there
    // (C ~ 13: 64 samples hold ~5 effective ones) leaves those pixels untested.
    std::mt19937_64 rng(20261125);
    std::vector<ExrImage> renders;
    for (int k = 0; k < kRenders; ++k) renders.push_back(render(rng, kSpp, false, false));
    const ExrImage reference = render(rng, kRefSpp, true, true);
    const ExrImage test = combineRenders(renders);

    CompareOptions unknown;
    const CompareResult blind = compareImages(test, reference, unknown);
    INFO(blind.sentence);
    CHECK_FALSE(blind.consistent);  // the premise: the missed rare samples fool the plain test
    CHECK(blind.pGlobal < 1e-6);

    CompareOptions known;
    known.samplesPerRender = kSpp;
    const CompareResult r = compareImages(test, reference, known);
    INFO(r.sentence);
    CHECK(r.hasVerdict);
    CHECK(r.consistent);
    // Exactly the four centre pixels are excluded: everywhere else the reference is smooth.
    CHECK(r.lowEffective == 4);
    CHECK(r.tested == blind.tested - 4);
    for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x)
            CHECK((r.status[size_t(y) * kSize + size_t(x)] == PixelStatus::LowEffective) == centre(x, y));

    // With 64 renders of 8 spp (512 samples: ~39 effective) the centre is tested again, and the
    // renders there caught the rare samples: consistent, with every pixel tested.
    std::vector<ExrImage> many;
    for (int k = 0; k < 64; ++k) many.push_back(render(rng, kSpp, true, false));
    const CompareResult enough = compareImages(combineRenders(many), reference, known);
    INFO(enough.sentence);
    CHECK(enough.consistent);
    CHECK(enough.lowEffective == 0);
}

TEST_CASE("compare --samples-per-render: refused without N renders, and bad values are input errors", "[compare][cli]") {
    const std::string dir = makeTempDir("samples-per-render");
    std::mt19937_64 rng(7);
    for (int k = 0; k < 2; ++k) writeImageChannels(dir + "/r" + std::to_string(k) + ".exr", render(rng, kSpp, true, false));
    writeImageChannels(dir + "/ref.exr", render(rng, 256, true, true));
    const std::string two = dir + "/r0.exr " + dir + "/r1.exr " + dir + "/ref.exr";
    checkInputError("compare " + dir + "/r0.exr " + dir + "/ref.exr --samples-per-render 8", "applies to N >= 2 renders");
    checkInputError("compare " + two + " --samples-per-render -1", "--samples-per-render");
    std::string out;
    const int rc = runCli("compare " + two + " --samples-per-render 8", &out);
    INFO(out);
    CHECK((rc == 0 || rc == 1 || rc == 2));  // a verdict or "insufficient samples", never an input error
    CHECK(out.find("pixels:") != std::string::npos);
}
