// Not a unit test: the comparison step of tools/ci/distributed-check.sh, which renders one image
// through a real Slurm array and a real GNU parallel and asks this hidden case whether each merged
// EXR equals the single-run render. It reads the films' exact state with readFilmExr, so it follows
// the EXR layout wherever docs/exr.md puts that state (a shell tool reading channels would not).
//
//   BDPTREF_MERGED=merged.exr BDPTREF_SINGLE=single.exr bdptref_tests "[.distributed-check]"
//
// "Equal" is docs/ground-truth.md's merge contract: same sample ranges, counts bit-identical, and
// every double sum within 2 (n-1) u sum|x| of the single render's (u = 2^-53, n passes): merge adds
// the same per-pass values, only in another order.
#include "bdptref/checkpoint.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

using namespace bdptref;

namespace {

// Counts the values of `m` farther from `s` than the summation-order bound for n passes. Every
// accumulated value here is a sum of non-negative terms (radiance, its square), so sum|x| is the
// sum itself; the larger of the two computed sums, times (1 + n u), is at least the exact one.
size_t outsideBound(const std::vector<DVec3>& m, const std::vector<DVec3>& s, uint64_t n) {
    const double u = 0x1p-53, rel = 2.0 * double(n - 1) * u;
    size_t bad = m.size() == s.size() ? 0 : m.size() + s.size();
    for (size_t i = 0; i < std::min(m.size(), s.size()); ++i)
        for (int c = 0; c < 3; ++c) {
            const double a = m[i][c], b = s[i][c];
            const double sumAbs = std::max(a, b) * (1.0 + double(n) * u);
            if (!(a >= 0.0 && b >= 0.0 && std::abs(a - b) <= rel * sumAbs)) ++bad;
        }
    return bad;
}

}  // namespace

TEST_CASE("distributed-check: the merged EXR equals the single render", "[.distributed-check]") {
    const char* mergedPath = std::getenv("BDPTREF_MERGED");
    const char* singlePath = std::getenv("BDPTREF_SINGLE");
    REQUIRE(mergedPath != nullptr);
    REQUIRE(singlePath != nullptr);
    INFO("merged " << mergedPath << ", single " << singlePath);
    FilmFile m = readFilmExr(mergedPath), s = readFilmExr(singlePath);
    REQUIRE(m.film.width() == s.film.width());
    REQUIRE(m.film.height() == s.film.height());
    REQUIRE(s.film.samples().total() > 0);
    CHECK(m.film.samples().text() == s.film.samples().text());
    CHECK(m.attribute(kAttrSettings) == s.attribute(kAttrSettings));
    const uint64_t n = s.film.samples().total();
    Film::Accumulators ma = m.film.accumulators(), sa = s.film.accumulators();
    CHECK(ma.count == sa.count);
    CHECK(ma.nonFinite == sa.nonFinite);
    CHECK(outsideBound(ma.sum, sa.sum, n) == 0);
    CHECK(outsideBound(ma.sumSquares, sa.sumSquares, n) == 0);
    CHECK(m.lightLayer == s.lightLayer);
    CHECK(outsideBound(ma.lightSum, sa.lightSum, n) == 0);
    const StrategyLayers &ml = m.film.strategies(), &sl = s.film.strategies();
    CHECK(ml.maxDepth() == sl.maxDepth());
    CHECK(ml.passes() == sl.passes());
    if (sl.enabled())
        for (const bool weighted : {true, false}) {
            CHECK(outsideBound(ml.sums(weighted), sl.sums(weighted), sl.passes()) == 0);
            CHECK(outsideBound(ml.sumSquares(weighted), sl.sumSquares(weighted), sl.passes()) == 0);
        }
}
