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

// A shape stored in half floats: the variance of the mean of a dark, heavy-tailed channel
// underflows to 0 (below 6e-8) while its brighter siblings keep theirs.
TEST_CASE("estimatorShape: a channel whose variance was lost takes its noisiest sibling's C", "[compare]") {
    ExrImage img;
    img.width = 1;
    img.height = 1;
    img.window = FilmWindow::full(1, 1);
    img.channels["R"] = {0.0059f};
    img.channels["G"] = {0.0023f};
    img.channels["B"] = {0.0006f};
    img.channels["variance.R"] = {4.0e-7f};
    img.channels["variance.G"] = {1.2e-7f};
    img.channels["variance.B"] = {0.f};
    img.channels["count"] = {4096.f};
    const auto s = estimatorShape(img, "shape");
    const double cR = 4095.0 * 4.0e-7 / (0.0059 * 0.0059), cG = 4095.0 * 1.2e-7 / (0.0023 * 0.0023);
    CHECK(s[0][0] == Approx(cR).epsilon(1e-5));
    CHECK(s[1][0] == Approx(cG).epsilon(1e-5));
    CHECK(s[2][0] == Approx(std::max(cR, cG)).epsilon(1e-5));  // not 0: "smooth" would be a lie
    // A pixel whose every channel has no variance is deterministic: C stays 0.
    img.channels["variance.R"] = {0.f};
    img.channels["variance.G"] = {0.f};
    const auto d = estimatorShape(img, "shape");
    CHECK(d[0][0] == 0.f);
    CHECK(d[2][0] == 0.f);
}

TEST_CASE("halfVarianceWarning: variances that lost their bits in half floats are named", "[compare]") {
    ExrImage img;
    img.width = 8;
    img.height = 4;
    img.window = FilmWindow::full(8, 4);
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<float> u(0.5f, 1.5f);
    for (const char* c : {"R", "G", "B"}) {
        std::vector<float> m(32), v(32);
        for (size_t i = 0; i < 32; ++i) {
            m[i] = 0.01f * u(rng);
            v[i] = 1e-5f * u(rng);  // 32-bit values: not representable in half
        }
        img.channels[c] = m;
        img.channels[std::string("variance.") + c] = v;
    }
    CHECK(halfVarianceWarning(img, "x").empty());
    // The same variances rounded as a half would store them (10 mantissa bits; steps of 2^-24 below
    // 2^-14), two of them to 0.
    for (const char* c : {"R", "G", "B"})
        for (float& v : img.channels[std::string("variance.") + c]) v = std::ldexp(std::round(std::ldexp(v, 24)), -24);
    img.channels["variance.B"][3] = 0.f;
    img.channels["variance.B"][4] = 0.f;
    const std::string w = halfVarianceWarning(img, "shape.exr");
    INFO(w);
    CHECK(w.find("shape.exr") != std::string::npos);
    CHECK(w.find("half") != std::string::npos);
    CHECK(w.find("96 variances") != std::string::npos);  // every one is below 6.1e-5
    // Variances that are exactly halves but all in the normal range lose nothing worth a warning.
    for (const char* c : {"R", "G", "B"})
        for (float& v : img.channels[std::string("variance.") + c]) v = 0.25f;
    CHECK(halfVarianceWarning(img, "x").empty());
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
