// compare with the test's estimator shape known from a long render of a like estimator
// (CompareOptions::testShape, `compare --test-shape`, what validate passes from its suite): where
// that estimator is heavy-tailed and the reference's (another estimator) is not, renders that all
// missed its rare samples are not taken for a bias (docs/compare.md, "The test's estimator shape").
#include "support/render_util.h"

#include "bdptref/errors.h"
#include "bdptref/exr_io.h"
#include "bdptref/image_compare.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <random>

using namespace bdptref;
using namespace bdptref::test;

namespace {

constexpr int kSize = 16;
constexpr int kRenders = 8, kSpp = 8;
constexpr double kBackground = 0.1;
constexpr double kRareValue = 5.0, kRareChance = 1.0 / 36.0;  // the test estimator's centre: C ~ 11.8

bool centre(int x, int y) { return (x == 7 || x == 8) && (y == 7 || y == 8); }
// The centre and its ring: compare takes each pixel's largest shape over its 3 x 3 neighbourhood.
bool nearCentre(int x, int y) { return x >= 6 && x <= 9 && y >= 6 && y <= 9; }

enum class Estimator { Test, Reference };

// A sample of the test's estimator (at the centre: the background plus, rarely, a large value) or
// of the reference's (at the centre the same mean from a smooth sample: another estimator).
// `missRare`: the test's samples that drew no rare value (renders that all missed it).
double sample(std::mt19937_64& rng, int x, int y, Estimator e, bool missRare) {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    double v = kBackground * (1.0 + 0.1 * (2.0 * u(rng) - 1.0));
    if (!centre(x, y)) return v;
    if (e == Estimator::Reference) return v + kRareValue * kRareChance * (1.0 + 0.1 * (2.0 * u(rng) - 1.0));
    if (!missRare && u(rng) < kRareChance) v += kRareValue;
    return v;
}

ExrImage render(std::mt19937_64& rng, int spp, Estimator e, bool missRare, bool stats, double scale = 1.0) {
    return greyImageOfSamples(kSize, spp, stats, [&](int x, int y) { return scale * sample(rng, x, y, e, missRare); });
}

}  // namespace

TEST_CASE("compare: the test's estimator shape keeps renders that missed its rare samples from a false alarm",
          "[compare][statistics]") {
    std::mt19937_64 rng(20261125);
    std::vector<ExrImage> missed;
    for (int k = 0; k < kRenders; ++k) missed.push_back(render(rng, kSpp, Estimator::Test, true, false));
    const ExrImage test = combineRenders(missed);
    const ExrImage reference = render(rng, 8192, Estimator::Reference, false, true);
    const ExrImage longTest = render(rng, 8192, Estimator::Test, false, true);

    // The premise: the reference is smooth at the centre (another estimator), so the samples per
    // render alone do not save the renders that missed the test estimator's rare values.
    CompareOptions known;
    known.samplesPerRender = kSpp;
    const CompareResult blind = compareImages(test, reference, known);
    INFO(blind.sentence);
    CHECK_FALSE(blind.consistent);
    CHECK(blind.pGlobal < 1e-6);

    // The shape of the test's estimator, from its long render: C ~ 11.8 at the centre, so 64 samples
    // hold about 5 effective ones (< 10): exactly the centre and the ring around it (the shape is
    // taken as the largest of each pixel's 3 x 3 neighbourhood) are left untested.
    CompareOptions shaped = known;
    shaped.testShape = estimatorShape(longTest, "long test render");
    const double cCentre = shaped.testShape[0][size_t(7) * kSize + 7];
    CHECK(cCentre > 8.0);
    CHECK(cCentre < 16.0);
    const CompareResult r = compareImages(test, reference, shaped);
    INFO(r.sentence);
    CHECK(r.hasVerdict);
    CHECK(r.consistent);
    CHECK(r.lowEffective == 16);
    for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x)
            CHECK((r.status[size_t(y) * kSize + size_t(x)] == PixelStatus::LowEffective) == nearCentre(x, y));

    // The power is kept: the same renders 3% too bright are flagged with the shape.
    std::vector<ExrImage> bright;
    for (int k = 0; k < kRenders; ++k) bright.push_back(render(rng, kSpp, Estimator::Test, true, false, 1.03));
    const CompareResult scaled = compareImages(combineRenders(bright), reference, shaped);
    INFO(scaled.sentence);
    CHECK_FALSE(scaled.consistent);
    CHECK(scaled.pGlobal < 1e-6);

    // One test image with its own counts: the shape bounds its effective samples the same way.
    const ExrImage single = render(rng, kRenders * kSpp, Estimator::Test, true, true);
    CompareOptions plain;
    CHECK_FALSE(compareImages(single, reference, plain).consistent);
    plain.testShape = shaped.testShape;
    const CompareResult withCounts = compareImages(single, reference, plain);
    INFO(withCounts.sentence);
    CHECK(withCounts.consistent);
    CHECK(withCounts.lowEffective == 16);
}

TEST_CASE("estimatorShape: C per pixel, NaN where a render says nothing, and refusals", "[compare]") {
    ExrImage img;
    img.width = 2;
    img.height = 1;
    img.window = FilmWindow::full(2, 1);
    for (const char* c : {"R", "G", "B"}) {
        img.channels[c] = {0.5f, 0.f};
        img.channels[std::string("variance.") + c] = {0.001f, 0.f};
    }
    img.channels["count"] = {101.f, 64.f};
    const auto s = estimatorShape(img, "shape");
    CHECK(s[1][0] == Approx(100.0 * 0.001 / 0.25).epsilon(1e-6));  // (n - 1) v / m^2 = 0.4
    CHECK(std::isnan(s[1][1]));                                    // all samples 0: nothing known
    img.channels.erase("count");
    CHECK_THROWS_AS(estimatorShape(img, "shape"), InputError);
}

TEST_CASE("compare --test-shape: what it needs, and bad files are input errors", "[compare][cli]") {
    const std::string dir = makeTempDir("test-shape");
    std::mt19937_64 rng(11);
    for (int k = 0; k < 2; ++k)
        writeImageChannels(dir + "/r" + std::to_string(k) + ".exr", render(rng, kSpp, Estimator::Test, false, false));
    writeImageChannels(dir + "/ref.exr", render(rng, 256, Estimator::Reference, false, true));
    writeImageChannels(dir + "/shape.exr", render(rng, 256, Estimator::Test, false, true));
    ExrImage small = render(rng, 64, Estimator::Test, false, true);
    small.width = small.height = 4;
    small.window = FilmWindow::full(4, 4);
    for (auto& [name, pixels] : small.channels) pixels.resize(16);
    writeImageChannels(dir + "/small.exr", small);
    const std::string two = dir + "/r0.exr " + dir + "/r1.exr " + dir + "/ref.exr";
    checkInputError("compare " + two + " --test-shape " + dir + "/shape.exr", "needs the test's samples per pixel");
    checkInputError("compare " + two + " --samples-per-render 8 --test-shape " + dir + "/small.exr", "same size");
    checkInputError("compare " + two + " --samples-per-render 8 --test-shape " + dir + "/r0.exr", "variance layers and a count");
    checkInputError("compare " + two + " --samples-per-render 8 --test-shape " + dir + "/none.exr", "none.exr");
    std::string out;
    const int rc = runCli("compare " + two + " --samples-per-render 8 --test-shape " + dir + "/shape.exr", &out);
    INFO(out);
    CHECK((rc == 0 || rc == 1 || rc == 2));
    CHECK(out.find("pixels:") != std::string::npos);
}
