// Ground-truth production in the library: the exact film state survives an EXR round trip bit
// for bit, a render resumed from it equals an uninterrupted one, parts of disjoint sample ranges
// merge to a single render to double precision, the time budget stops at a pass boundary.
#include "bdptref/checkpoint.h"
#include "bdptref/errors.h"
#include "bdptref/exr_io.h"
#include "bdptref/film_merge.h"
#include "bdptref/renderer.h"
#include "support/render_util.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

using namespace bdptref;
using namespace bdptref::test;

namespace {

struct Setup {
    Scene scene = loadTestScene("scenes/cornell-box.gltf", 16, 12);
    std::unique_ptr<Integrator> integrator;
    explicit Setup(bool strategies) {
        IntegratorSettings is;
        is.maxDepth = 3;
        is.recordStrategies = strategies;
        integrator = makeBdpt(is);
    }
    Film film(bool strategies) const {
        Film f(scene.camera.width(), scene.camera.height());
        if (strategies) f.enableStrategies(3);
        return f;
    }
    RenderStats render(Film& f, uint64_t first, int spp) const {
        RenderOptions ro;
        ro.firstSample = first;
        ro.spp = spp;
        ro.seed = 3;
        return renderImage(scene, *integrator, ro, f);
    }
};

// Every accumulator bit for bit (== on doubles; no NaN can occur: non-finite samples are zeroed).
bool identical(Film& a, Film& b) {
    const Film::Accumulators x = a.accumulators(), y = b.accumulators();
    bool same = x.sum == y.sum && x.sumSquares == y.sumSquares && x.count == y.count && x.lightSum == y.lightSum &&
                x.nonFinite == y.nonFinite && a.samples() == b.samples();
    const StrategyLayers &sa = a.strategies(), &sb = b.strategies();
    same = same && sa.maxDepth() == sb.maxDepth() && sa.passes() == sb.passes() &&
           sa.nonFiniteValues() == sb.nonFiniteValues();
    for (bool w : {true, false}) same = same && sa.sums(w) == sb.sums(w) && sa.sumSquares(w) == sb.sumSquares(w);
    return same;
}

FilmFile roundTrip(const Film& film, const std::string& path, const std::string& settings) {
    ExrMetadata md;
    md.strings = {{kAttrSettings, settings}, {"bdptref:sceneHash", "0123456789abcdef"}};
    writeFilmExr(path, film, md, true);
    return readFilmExr(path);
}

}  // namespace

TEST_CASE("Sample ranges join adjacent ranges, refuse overlaps and round-trip through text", "[groundtruth]") {
    SampleRanges r;
    CHECK(r.add({32, 64}));
    CHECK(r.add({0, 16}));
    CHECK_FALSE(r.contiguous());
    CHECK(r.text() == "0:16,32:64");
    CHECK_FALSE(r.add({10, 20}));  // overlaps 0:16
    CHECK(r.text() == "0:16,32:64");
    CHECK(r.add({16, 32}));
    CHECK(r.contiguous());
    CHECK(r.text() == "0:64");
    CHECK(r.total() == 64);
    CHECK(parseSampleRanges("0:16,32:64", "x").text() == "0:16,32:64");
    CHECK(parseSampleRange("18446744073709551614:18446744073709551615", "x").size() == 1);
    CHECK_THROWS_AS(parseSampleRange("5:5", "--sample-range"), InputError);
    CHECK_THROWS_AS(parseSampleRange("-1:5", "--sample-range"), InputError);
    CHECK_THROWS_AS(parseSampleRange("3", "--sample-range"), InputError);
    CHECK_THROWS_AS(parseSampleRanges("0:4,2:6", "x"), InputError);
}

TEST_CASE("The exact film state survives an EXR round trip bit for bit, strategy layers included", "[groundtruth]") {
    const Setup s(true);
    Film film = s.film(true);
    s.render(film, 5, 3);
    REQUIRE(film.samples().text() == "5:8");
    const std::string dir = makeTempDir("gt-roundtrip");
    FilmFile back = roundTrip(film, dir + "/f.exr", "k=v\n");
    CHECK(back.lightLayer);
    CHECK(back.attribute(kAttrSettings) == "k=v\n");
    CHECK(identical(film, back.film));
    // The round trip is not vacuous: the film has light and strategy contributions.
    CHECK(pooledMean(film).mean.x > 0.01);
    double light = 0, layers = 0;
    for (const DVec3& v : film.accumulators().lightSum) light += v.x;
    for (const DVec3& v : film.strategies().sums(true)) layers += v.x;
    CHECK(light > 0);
    CHECK(layers > 0);
}

TEST_CASE("Non-finite samples and layer values stay counted through a checkpoint and a merge", "[groundtruth]") {
    // A film with one NaN sample and one infinite strategy-layer value in sample 0, and clean sample 1.
    auto make = [](uint64_t sample, bool poisoned) {
        Film f(2, 1);
        f.enableStrategies(0);
        const float bad = poisoned ? std::numeric_limits<float>::quiet_NaN() : 1.f;
        f.addSample(0, 0, Rgb(bad, 0.f, 0.f));
        f.addSample(1, 0, Rgb(0.5f));
        std::vector<Rgb> w(size_t(f.strategies().layerCount()) * 2, Rgb(0.25f)), u = w;
        if (poisoned) u[1] = Rgb(std::numeric_limits<float>::infinity());
        f.strategies().addPass(w, u);
        f.samples().add(SampleRange{sample, sample + 1});
        return f;
    };
    Film a = make(0, true), b = make(1, false);
    REQUIRE(a.nonFiniteSamples() == 1);
    REQUIRE(a.strategies().nonFiniteValues() == 1);
    const std::string dir = makeTempDir("gt-nonfinite");
    FilmFile back = roundTrip(a, dir + "/a.exr", "k=v\n");
    CHECK(back.film.nonFiniteSamples() == 1);
    CHECK(back.film.strategies().nonFiniteValues() == 1);
    back.film.accumulate(b);
    CHECK(back.film.nonFiniteSamples() == 1);
    CHECK(back.film.strategies().nonFiniteValues() == 1);
    b.accumulate(a);  // merge order does not matter
    CHECK(b.strategies().nonFiniteValues() == 1);
}

TEST_CASE("A render resumed from a checkpoint file is bit-identical to an uninterrupted one", "[groundtruth][resume]") {
    const Setup s(true);
    Film whole = s.film(true);
    s.render(whole, 0, 6);
    Film first = s.film(true);
    s.render(first, 0, 2);
    const std::string dir = makeTempDir("gt-resume");
    FilmFile ck = roundTrip(first, dir + "/ck.exr", "k=v\n");
    const RenderStats st = s.render(ck.film, 2, 4);
    CHECK(st.passesDone == 4);
    CHECK(identical(whole, ck.film));
    // A film cannot continue anywhere but at its end (that would skip or repeat samples).
    Film other = s.film(true);
    s.render(other, 0, 2);
    CHECK_THROWS_AS(s.render(other, 3, 1), std::invalid_argument);
}

TEST_CASE("Merged sample ranges 0:32 and 32:64 equal a single 0:64 render to double precision", "[groundtruth][merge]") {
    const Setup s(true);
    Film single = s.film(true), a = s.film(true), b = s.film(true);
    s.render(single, 0, 64);
    s.render(a, 0, 32);
    s.render(b, 32, 32);
    const std::string dir = makeTempDir("gt-merge");
    const std::vector<FilmFile> parts = {roundTrip(b, dir + "/b.exr", "k=v\n"), roundTrip(a, dir + "/a.exr", "k=v\n")};
    MergedFilm m = mergeFilms(parts);
    CHECK(m.order == std::vector<size_t>{1, 0});  // added in sample order whatever the argument order
    CHECK(m.film.samples().text() == "0:64");
    const Film::Accumulators x = single.accumulators(), y = m.film.accumulators();
    CHECK(x.count == y.count);  // counts exact
    // Sums of n = 64 non-negative terms in two different orders differ by at most
    // 2 (n - 1) u sum|x|, u = 2^-53 (each is within (n - 1) u sum|x| of the exact sum).
    const double bound = 2.0 * 63.0 * std::ldexp(1.0, -53);
    double worst = 0;  // largest |difference| / (bound * value)
    auto within = [&](const std::vector<DVec3>& p, const std::vector<DVec3>& q) {
        for (size_t i = 0; i < p.size(); ++i)
            for (int c = 0; c < 3; ++c) {
                const double d = std::abs(p[i][c] - q[i][c]), lim = bound * std::abs(p[i][c]);
                if (d > 0) worst = std::max(worst, d / lim);
                if (d > lim) return false;
            }
        return true;
    };
    CHECK(within(x.sum, y.sum));
    CHECK(within(x.sumSquares, y.sumSquares));
    CHECK(within(x.lightSum, y.lightSum));
    for (bool w : {true, false}) {
        CHECK(within(single.strategies().sums(w), m.film.strategies().sums(w)));
        CHECK(within(single.strategies().sumSquares(w), m.film.strategies().sumSquares(w)));
    }
    CHECK(m.film.strategies().passes() == 64);
    INFO("largest difference relative to the bound: " << worst);
    CHECK(worst <= 1.0);
}

TEST_CASE("Merge refuses parts with other settings or scene, overlapping parts, and gaps unless allowed", "[groundtruth][merge]") {
    const Setup s(false);
    Film a = s.film(false), b = s.film(false), c = s.film(false);
    s.render(a, 0, 2);
    s.render(b, 2, 2);
    s.render(c, 6, 2);
    const std::string dir = makeTempDir("gt-merge-refuse");
    const FilmFile fa = roundTrip(a, dir + "/a.exr", "seed=3\n"), fb = roundTrip(b, dir + "/b.exr", "seed=3\n"),
                   fc = roundTrip(c, dir + "/c.exr", "seed=3\n");
    CHECK(mergeFilms({fa, fb}).film.samples().text() == "0:4");
    FilmFile otherSeed = fb;
    otherSeed.attributes[kAttrSettings] = "seed=4\n";
    CHECK_THROWS_WITH(mergeFilms({fa, otherSeed}), Catch::Contains("seed: 4 vs 3"));
    FilmFile otherScene = fb;
    otherScene.attributes["bdptref:sceneHash"] = "ffffffffffffffff";
    CHECK_THROWS_WITH(mergeFilms({fa, otherScene}), Catch::Contains("another scene"));
    CHECK_THROWS_WITH(mergeFilms({fa, fb, fa}), Catch::Contains("overlapping"));
    CHECK_THROWS_WITH(mergeFilms({fa, fc}), Catch::Contains("2:6"));
    MergeOptions gaps;
    gaps.allowGaps = true;
    CHECK(mergeFilms({fa, fc}, gaps).film.samples().text() == "0:2,6:8");
}

TEST_CASE("A time budget stops at the first pass boundary after it", "[groundtruth][time]") {
    const Setup s(false);
    Film f = s.film(false);
    RenderOptions ro;
    ro.spp = 1000000;
    ro.timeBudgetSeconds = 1e-9;  // over after any pass: exactly one pass
    RenderStats st = renderImage(s.scene, *s.integrator, ro, f);
    CHECK(st.timeLimited);
    CHECK(st.passesDone == 1);
    CHECK(f.samples().text() == "0:1");
    Film g = s.film(false);
    ro.timeBudgetSeconds = 0.3;
    st = renderImage(s.scene, *s.integrator, ro, g);
    CHECK(st.timeLimited);
    CHECK(st.seconds >= 0.3);
    CHECK(g.samples().total() == uint64_t(st.passesDone));
    CHECK(g.minCount() == uint64_t(st.passesDone));
    CHECK(g.maxCount() == uint64_t(st.passesDone));
}
