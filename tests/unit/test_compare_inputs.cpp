// `bdptref compare` with test images as users have them (docs/compare.md, "Inputs"): N >= 2 plain
// RGB renders combined into a mean and the variance of that mean, the refusal of a single plain
// render and of display-encoded files, and "insufficient samples" instead of a verdict on nothing.
#include "bdptref/bdptref.h"
#include "bdptref/exr_io.h"
#include "bdptref/film.h"
#include "bdptref/image_compare.h"
#include "support/render_util.h"

#include <OpenImageIO/imageio.h>
#include <catch2/catch.hpp>

#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <random>
#include <string>
#include <vector>

using namespace bdptref;
using namespace bdptref::test;

namespace {

const char* kRgb[3] = {"R", "G", "B"};
const char* kVar[3] = {"variance.R", "variance.G", "variance.B"};

std::string cli(const std::string& args, int* rc) {
    std::string out;
    *rc = runCli(args, &out);
    return out;
}

// A plain RGB image whose rows all differ: value(x, y, c) = 0.1 + 0.1 y + 0.01 x + 0.01 c.
ExrImage truthImage(int w, int h) {
    ExrImage img;
    img.width = w;
    img.height = h;
    for (int c = 0; c < 3; ++c) {
        std::vector<float>& ch = img.channels[kRgb[c]];
        ch.resize(size_t(w * h));
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) ch[size_t(y * w + x)] = 0.1f + 0.1f * float(y) + 0.01f * float(x) + 0.01f * float(c);
    }
    return img;
}

// `truth` * scale plus N(0, var) noise per pixel and channel: one render of an estimator whose
// pixel mean has variance `var`.
ExrImage noisyRender(const ExrImage& truth, double var, uint32_t seed, double scale = 1.0) {
    ExrImage img = truth;
    std::mt19937 rng(seed);
    std::normal_distribution<double> normal(0.0, std::sqrt(var));
    for (int c = 0; c < 3; ++c)
        for (float& v : img.channels[kRgb[c]]) v = float(double(v) * scale + normal(rng));
    return img;
}

// A PFM file by the format's definition: "PF", width height, -1 (little endian), float RGB rows
// from the BOTTOM row up (a reader that did not flip them would mismatch every row here).
void writePfm(const std::string& path, const ExrImage& img) {
    std::ofstream f(path, std::ios::binary);
    f << "PF\n" << img.width << " " << img.height << "\n-1.0\n";
    for (int y = img.height - 1; y >= 0; --y)
        for (int x = 0; x < img.width; ++x)
            for (int c = 0; c < 3; ++c) {
                const float v = img.channels.at(kRgb[c])[size_t(y * img.width + x)];
                f.write(reinterpret_cast<const char*>(&v), sizeof v);
            }
    REQUIRE(f.good());
}

}  // namespace

TEST_CASE("compare combineRenders: mean and variance of the mean over N renders, N - 1 degrees of freedom", "[compare]") {
    // Three renders of a 1x1 image with values 1, 2, 4 (R; G, B = twice that): mean 7/3,
    // s^2 = ((1 - 7/3)^2 + (2 - 7/3)^2 + (4 - 7/3)^2) / 2 = 7/3, variance of the mean s^2 / 3 = 7/9.
    std::vector<ExrImage> renders(3);
    const float vals[3] = {1.f, 2.f, 4.f};
    for (int k = 0; k < 3; ++k) {
        renders[size_t(k)].width = renders[size_t(k)].height = 1;
        renders[size_t(k)].channels["R"] = {vals[k]};
        renders[size_t(k)].channels["G"] = {2.f * vals[k]};
        renders[size_t(k)].channels["B"] = {2.f * vals[k]};
        renders[size_t(k)].channels["variance.R"] = {123.f};  // a render's own variance is ignored
    }
    const ExrImage m = combineRenders(renders);
    CHECK(m.at("R", 0, 0) == Approx(7.0 / 3.0).epsilon(1e-6));
    CHECK(m.at("variance.R", 0, 0) == Approx(7.0 / 9.0).epsilon(1e-6));
    CHECK(m.at("variance.G", 0, 0) == Approx(4.0 * 7.0 / 9.0).epsilon(1e-6));
    CHECK_FALSE(m.has("count"));
    CHECK(m.attributes.at("bdptref:renders") == "3");

    // The renders' variances enter the t-test with N - 1 = 2 degrees of freedom: a reference that is
    // exact at mean + 2 sd of the mean in every channel gives t = -2, p = 0.1835 (t, 2 dof),
    // not the normal 0.0455; the three equal channel p-values combine to the same p.
    ExrImage ref;
    ref.width = ref.height = 1;
    const double shift = 2.0 * std::sqrt(7.0 / 9.0);
    ref.channels["R"] = {float(7.0 / 3.0 + shift)};
    ref.channels["G"] = {float(14.0 / 3.0 + 2.0 * shift)};
    ref.channels["B"] = {float(14.0 / 3.0 + 2.0 * shift)};
    // (An exact reference, without variance layers: with them, the variance would also be bounded
    // below by the reference's times the image's ratio, which in a one-pixel image is this pixel's.)
    CompareOptions o;
    o.minEffectiveSamples = 0;
    const CompareResult r = compareImages(m, ref, o);
    CHECK(r.testRenders == 3);
    CHECK(r.kind == TestKind::TestVariance);
    REQUIRE(r.tested == 1);
    const double pT = stats::studentTTwoSidedP(-2.0, 2.0);
    CHECK(pT == Approx(0.1835).margin(1e-4));
    CHECK(r.pMin == Approx(pT).epsilon(1e-4));

    SECTION("unusable sets are refused") {
        CHECK_THROWS_WITH(combineRenders({renders[0]}), Catch::Contains("N >= 2"));
        CHECK_THROWS_WITH(combineRenders({renders[0], renders[0]}), Catch::Contains("identical"));
        ExrImage wide = renders[1];
        wide.width = 2;
        for (auto& kv : wide.channels) kv.second.resize(2);
        CHECK_THROWS_WITH(combineRenders({renders[0], wide}), Catch::Contains("the same image"));
        ExrImage noRgb = renders[1];
        noRgb.channels.erase("G");
        CHECK_THROWS_WITH(combineRenders({renders[0], noRgb}, {"a.exr", "b.exr"}), Catch::Contains("b.exr"));
    }
}

TEST_CASE("compare T1 ... TN REF: plain RGB PFM renders against a reference (CLI and library)", "[compare]") {
    // A renderer that writes only RGB: 4 renders whose pixel means have variance 1e-4, against a
    // reference with variances (1e-6, 1000 samples). A 2% scale is 20 sigma of the bias test.
    const std::string dir = makeTempDir("compare-renders");
    const int w = 16, h = 8;
    const ExrImage truth = truthImage(w, h);
    ExrImage ref = noisyRender(truth, 1e-6, 3);
    for (const char* v : kVar) ref.channels[v].assign(size_t(w * h), 1e-6f);
    ref.channels["count"].assign(size_t(w * h), 1000.f);
    writeImageChannels(dir + "/ref.exr", ref);
    std::string good, bright;
    std::vector<ExrImage> goodRenders;
    for (uint32_t k = 1; k <= 4; ++k) {
        goodRenders.push_back(noisyRender(truth, 1e-4, 100 + k));
        writePfm(dir + "/good" + std::to_string(k) + ".pfm", goodRenders.back());
        writePfm(dir + "/bright" + std::to_string(k) + ".pfm", noisyRender(truth, 1e-4, 100 + k, 1.02));
        good += dir + "/good" + std::to_string(k) + ".pfm ";
        bright += dir + "/bright" + std::to_string(k) + ".pfm ";
    }
    int rc = -1;
    std::string out = cli("compare " + good + dir + "/ref.exr", &rc);
    INFO(out);
    CHECK(rc == 0);
    CHECK(out.find("the mean of 4 renders") != std::string::npos);
    CHECK(out.find("3 degrees of freedom") != std::string::npos);
    out = cli("compare " + bright + dir + "/ref.exr", &rc);
    INFO(out);
    CHECK(rc == 1);

    // Black renders are identical whatever their seeds: a port that renders nothing is compared and
    // fails where the reference has light (exit 1), not refused as renders that share a seed (exit 2).
    std::string black;
    ExrImage dark = truth;
    for (const char* c : kRgb) std::fill(dark.channels[c].begin(), dark.channels[c].end(), 0.f);
    for (int k = 1; k <= 4; ++k) {
        writePfm(dir + "/black" + std::to_string(k) + ".pfm", dark);
        black += dir + "/black" + std::to_string(k) + ".pfm ";
    }
    out = cli("compare " + black + dir + "/ref.exr", &rc);
    INFO(out);
    CHECK(rc == 1);
    CHECK(out.find("identical") == std::string::npos);

    // One plain render alone is refused, saying what to write instead.
    out = cli("compare " + dir + "/good1.pfm " + dir + "/ref.exr", &rc);
    CHECK(rc == 2);
    CHECK(out.find("variance.R, variance.G, variance.B") != std::string::npos);
    CHECK(out.find("N >= 2 independent renders") != std::string::npos);
    // --metrics-only accepts it: the error metrics, no verdict, exit 0 (what benchmarks need).
    out = cli("compare --metrics-only --json " + dir + "/good1.pfm " + dir + "/ref.exr", &rc);
    CHECK(rc == 0);
    {
        const auto j = nlohmann::json::parse(out.substr(out.find('{')));
        CHECK(j.at("verdict") == "metrics only");
        CHECK(j.at("exitCode") == 0);
        // relMSE by its definition, mean over pixels and channels of (t - r)^2 / (r^2 + 0.01).
        double relMse = 0;
        for (int c = 0; c < 3; ++c)
            for (int i = 0; i < w * h; ++i) {
                const double t = goodRenders[0].channels.at(kRgb[c])[size_t(i)], r = ref.channels.at(kRgb[c])[size_t(i)];
                relMse += (t - r) * (t - r) / (r * r + 0.01) / double(3 * w * h);
            }
        CHECK(j.at("metrics").at("overall").at("relMse").get<double>() == Approx(relMse).epsilon(1e-5));
    }
    // The same seed twice is not two renders.
    out = cli("compare " + dir + "/good1.pfm " + dir + "/good1.pfm " + dir + "/ref.exr", &rc);
    CHECK(rc == 2);
    CHECK(out.find("identical") != std::string::npos);

    // Library: the PFM rows are read in the right order, and the renders give the same verdict.
    std::vector<ExrImage> read;
    for (int k = 1; k <= 4; ++k) read.push_back(readImage(dir + "/good" + std::to_string(k) + ".pfm"));
    CHECK(read[0].channels.at("R") == goodRenders[0].channels.at("R"));
    const CompareResult r = compareImages(combineRenders(read), ref);
    CHECK(r.kind == TestKind::Welch);
    CHECK(r.testRenders == 4);
    CHECK(r.tested == uint64_t(w * h));
    CHECK(r.consistent);
    CHECK_THROWS_WITH(compareImageFiles(dir + "/good1.pfm", dir + "/ref.exr"), Catch::Contains("N >= 2"));
}

TEST_CASE("compare refuses 8-bit and display-encoded images and says what to write", "[compare][errors]") {
    const std::string dir = makeTempDir("compare-display");
    const int w = 8, h = 8;
    ExrImage ref = truthImage(w, h);
    for (const char* v : kVar) ref.channels[v].assign(size_t(w * h), 1e-4f);
    ref.channels["count"].assign(size_t(w * h), 100.f);
    writeImageChannels(dir + "/ref.exr", ref);
    std::vector<uint8_t> rgb(size_t(w * h * 3));
    for (size_t i = 0; i < rgb.size(); ++i) rgb[i] = uint8_t(i * 7 % 256);
    writeRgb8Png(dir + "/a.png", w, h, rgb);
    writeRgb8Png(dir + "/b.png", w, h, rgb);
    // An 8-bit TIFF: only its values say it is integer data.
    auto writeTiff = [&](const std::string& path, OIIO::TypeDesc type) {
        auto out = OIIO::ImageOutput::create(path);
        REQUIRE(out);
        REQUIRE(out->open(path, OIIO::ImageSpec(w, h, 3, type)));
        std::vector<float> px(rgb.size());
        for (size_t i = 0; i < px.size(); ++i) px[i] = type == OIIO::TypeDesc::FLOAT ? 0.1234567f * float(i) : float(rgb[i]) / 255.f;
        REQUIRE(out->write_image(OIIO::TypeDesc::FLOAT, px.data()));
        out->close();
    };
    writeTiff(dir + "/c8.tif", OIIO::TypeDesc::UINT8);
    writeTiff(dir + "/f32.tif", OIIO::TypeDesc::FLOAT);
    int rc = -1;
    std::string out = cli("compare " + dir + "/a.png " + dir + "/b.png " + dir + "/ref.exr", &rc);
    INFO(out);
    CHECK(rc == 2);
    CHECK(out.find("a.png is a png file, an 8-bit display-encoded") != std::string::npos);
    CHECK(out.find("write a float EXR") != std::string::npos);
    out = cli("compare " + dir + "/ref.exr " + dir + "/a.png", &rc);  // as the reference too
    CHECK(rc == 2);
    CHECK(out.find("reference image") != std::string::npos);
    out = cli("compare " + dir + "/c8.tif " + dir + "/ref.exr", &rc);
    INFO(out);
    CHECK(rc == 2);
    CHECK(out.find("8-bit integer values") != std::string::npos);
    // A float TIFF is linear data: not refused as display-encoded (but, alone and without
    // variances, as a single plain render).
    out = cli("compare " + dir + "/f32.tif " + dir + "/ref.exr", &rc);
    INFO(out);
    CHECK(rc == 2);
    CHECK(out.find("integer values") == std::string::npos);
    CHECK(out.find("N >= 2 independent renders") != std::string::npos);
    CHECK_THROWS_WITH(readCompareInput(dir + "/c8.tif", "test"), Catch::Contains("c8.tif"));
    CHECK_NOTHROW(readCompareInput(dir + "/f32.tif", "test"));
}

TEST_CASE("compare with too few samples exits 2 with insufficient samples and what would suffice, never consistent", "[compare]") {
    // 16x16 Cornell box, 4 spp against 4 spp: almost no pixel holds 10 effective samples. Before,
    // this printed "consistent (p = 1, 0 pixels tested)" and exited 0.
    const std::string dir = makeTempDir("compare-few");
    const std::string scene = sourcePath("scenes/cornell-box.gltf");
    for (int s = 1; s <= 2; ++s)
        REQUIRE(runCli("render " + scene + " --width 16 --height 16 --spp 4 -q --seed " + std::to_string(s) + " -o " +
                       dir + "/c" + std::to_string(s) + ".exr") == 0);
    int rc = -1;
    const std::string out = cli("compare " + dir + "/c1.exr " + dir + "/c2.exr", &rc);
    INFO(out);
    CHECK(rc == 2);
    CHECK(out.find("insufficient samples") != std::string::npos);
    CHECK(out.find("at least about") != std::string::npos);
    CHECK(out.find("samples per pixel instead of 4") != std::string::npos);
    CHECK(out.find("consistent with the reference") == std::string::npos);

    const CompareResult r = compareImages(readImage(dir + "/c1.exr"), readImage(dir + "/c2.exr"));
    CHECK_FALSE(r.hasVerdict);
    CHECK_FALSE(r.consistent);
    CHECK(r.insufficientSamples);
    CHECK(4 * r.tested < r.tested + r.lowEffective + r.fewSamples);
    CHECK(r.samplesFactorNeeded > 1.0);
    CHECK(r.sentence.find("no statistical verdict: insufficient samples") == 0);

    SECTION("count < 2 everywhere: two samples per pixel are needed") {
        ExrImage a = readImage(dir + "/c1.exr"), b = readImage(dir + "/c2.exr");
        a.channels["count"].assign(a.channels["count"].size(), 1.f);
        const CompareResult one = compareImages(a, b);
        CHECK(one.insufficientSamples);
        CHECK(one.fewSamples == 256);
        CHECK(one.samplesFactorNeeded == Approx(2.0));
    }
    SECTION("a rejection among the few tested pixels stands") {
        // Synthetic: 64 pixels, 52 without effective samples (mean 0.01, huge variance) and a block
        // of 12 (x 4..7, y 5..7) 7 sigma off. A pixel is judged by its neighbours' shape, so only
        // the 6 whose 8 neighbours all lie in the block are tested (x 5..7, y 6..7): inconsistent
        // with a verdict, although fewer than a quarter were tested.
        ExrImage t, ref;
        t.width = ref.width = 8;
        t.height = ref.height = 8;
        for (int c = 0; c < 3; ++c) {
            t.channels[kRgb[c]].assign(64, 1.1f);
            ref.channels[kRgb[c]].assign(64, 1.f);
            t.channels[kVar[c]].assign(64, 1e-4f);
            ref.channels[kVar[c]].assign(64, 1e-4f);
            for (int i = 0; i < 64; ++i) {
                if (i % 8 >= 4 && i / 8 >= 5) continue;  // the block
                t.channels[kRgb[c]][size_t(i)] = ref.channels[kRgb[c]][size_t(i)] = 0.01f;
                t.channels[kVar[c]][size_t(i)] = ref.channels[kVar[c]][size_t(i)] = 1.f;
            }
        }
        t.channels["count"].assign(64, 100.f);
        ref.channels["count"].assign(64, 100.f);
        const CompareResult res = compareImages(t, ref);
        CHECK(res.tested == 6);
        CHECK(res.lowEffective == 58);
        CHECK(res.hasVerdict);
        CHECK_FALSE(res.consistent);
    }
}

TEST_CASE("compare T1 ... TN REF with bdptref's own renders: 8 path-traced renders agree with a BDPT reference, scaled by 1.05 they do not", "[compare]") {
    // The N-render mode on real (skewed, heavy-tailed) pixel estimators: 8 renders of 16 spp
    // written as plain RGB, a 512-spp BDPT reference with variances. The 5% scale is about 10 sigma
    // of the bias test at this noise level (measured 0.4-0.5% per channel).
    const Scene scene = loadTestScene("scenes/cornell-box.gltf", 16, 16);
    // A film as a bdptref EXR holds it (mean, variance of the mean, count), or as plain RGB.
    auto imageOf = [](const Film& f, bool withVariance, float scale) {
        ExrImage img;
        img.width = f.width();
        img.height = f.height();
        for (int y = 0; y < f.height(); ++y)
            for (int x = 0; x < f.width(); ++x) {
                const DVec3 m = f.mean(x, y), v = f.varianceOfMean(x, y);
                for (int c = 0; c < 3; ++c) {
                    img.channels[kRgb[c]].push_back(float(m[c]) * scale);
                    if (withVariance) img.channels[kVar[c]].push_back(float(v[c]));
                }
                if (withVariance) img.channels["count"].push_back(float(f.count(x, y)));
            }
        return img;
    };
    const ExrImage ref = imageOf(renderFilm(scene, "bdpt", 512, 5, 99), true, 1.f);
    std::vector<ExrImage> renders, scaled;
    for (uint32_t s = 1; s <= 8; ++s) {
        const Film f = renderFilm(scene, "path", 16, 5, s);
        renders.push_back(imageOf(f, false, 1.f));
        scaled.push_back(imageOf(f, false, 1.05f));
    }
    const CompareResult good = compareImages(combineRenders(renders), ref);
    INFO(formatCompareReport(good));
    CHECK(good.hasVerdict);
    CHECK(good.consistent);
    const CompareResult bad = compareImages(combineRenders(scaled), ref);
    INFO(formatCompareReport(bad));
    CHECK(bad.hasVerdict);
    CHECK_FALSE(bad.consistent);
}

TEST_CASE("compare N renders: the test/reference variance ratio is unbiased for N = 2, 4, 8 (median corrected by chi-square)", "[compare]") {
    // 64x64 synthetic renders with per-render variance 1.6e-3 per pixel and channel, a reference with
    // variance of the mean 1e-4: the ratio of the variances of the means is 16 / N. The median of
    // va / vb alone would be 0.455 (N = 2), 0.79 (N = 4), 0.91 (N = 8) of it. Tolerance: 10%,
    // about 3 standard errors of a median over 4096 pixels of a chi-square with 1 degree of freedom.
    const int w = 64, h = 64;
    const ExrImage truth = truthImage(w, h);
    ExrImage ref = noisyRender(truth, 1e-4, 7);
    for (const char* v : kVar) ref.channels[v].assign(size_t(w * h), 1e-4f);
    ref.channels["count"].assign(size_t(w * h), 1000.f);
    for (const int n : {2, 4, 8}) {
        std::vector<ExrImage> renders;
        for (int k = 0; k < n; ++k) renders.push_back(noisyRender(truth, 1.6e-3, uint32_t(1000 * n + k)));
        const CompareResult r = compareImages(combineRenders(renders), ref);
        INFO("N = " << n << "\n" << formatCompareReport(r));
        for (int c = 0; c < 3; ++c) CHECK(r.varianceRatio[size_t(c)] == Approx(16.0 / n).epsilon(0.10));
        CHECK(r.consistent);
    }
}
