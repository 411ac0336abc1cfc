// N plain renders must be independent (docs/compare.md, "Renders that share noise"): renders whose
// per-thread random streams overlap (a renderer seeding thread i with seed + i, rendered with
// consecutive seeds) share part of their samples, their spread underestimates the noise of their
// mean, and correct renders failed the per-pixel test (SmallVCM, 2 threads, seeds 1..8). compare
// refuses such a set and says why; independent renders pass the check.
#include "bdptref/errors.h"
#include "bdptref/image_compare.h"

#include "verify/compare_internal.h"

#include <catch2/catch.hpp>

#include <random>

using namespace bdptref;

namespace {

constexpr int kSize = 48;
constexpr int kStreams = 12;  // independent sample streams, each a half-render of every pixel

// Stream j's half-render: per pixel the mean of 32 skewed samples (exponential, so that the
// statistic is exercised on the skewed pixels renders have).
std::vector<float> stream(int j) {
    std::mt19937_64 rng(9000 + uint64_t(j));
    std::exponential_distribution<double> sample(1.0);
    std::vector<float> out(size_t(kSize) * kSize);
    for (float& v : out) {
        double s = 0;
        for (int k = 0; k < 32; ++k) s += sample(rng);
        v = float(s / 32.0);
    }
    return out;
}

// Render k averages streams a and b: like a 2-thread renderer whose threads use seeds a and b.
ExrImage render(const std::vector<std::vector<float>>& streams, int a, int b) {
    ExrImage img;
    img.width = img.height = kSize;
    img.window = FilmWindow::full(kSize, kSize);
    std::vector<float> v(streams[size_t(a)].size());
    for (size_t i = 0; i < v.size(); ++i) v[i] = 0.5f * (streams[size_t(a)][i] + streams[size_t(b)][i]);
    for (const char* c : {"R", "G", "B"}) img.channels[c] = v;
    return img;
}

}  // namespace

TEST_CASE("compare refuses N renders that share noise and names the pair and the cause", "[compare]") {
    std::vector<std::vector<float>> streams;
    for (int j = 0; j < kStreams; ++j) streams.push_back(stream(j));

    SECTION("independent renders (disjoint streams) are accepted") {
        std::vector<ExrImage> renders;
        for (int k = 0; k < 6; ++k) renders.push_back(render(streams, 2 * k, 2 * k + 1));
        CHECK_NOTHROW(combineRenders(renders));
    }
    SECTION("seeds s and s + 1 with two threads: consecutive renders share a stream and are refused") {
        std::vector<ExrImage> renders;
        for (int k = 0; k < 6; ++k) renders.push_back(render(streams, k, k + 1));
        try {
            combineRenders(renders, {"a.exr", "b.exr", "c.exr", "d.exr", "e.exr", "f.exr"});
            FAIL("renders sharing streams were accepted");
        } catch (const InputError& e) {
            const std::string m = e.what();
            INFO(m);
            CHECK(m.find("share noise") != std::string::npos);
            CHECK(m.find("seed + i") != std::string::npos);
            // The pair named is a consecutive one (every consecutive pair shares a stream).
            const bool consecutive = m.find("a.exr and b.exr") != std::string::npos ||
                                     m.find("b.exr and c.exr") != std::string::npos ||
                                     m.find("c.exr and d.exr") != std::string::npos ||
                                     m.find("d.exr and e.exr") != std::string::npos ||
                                     m.find("e.exr and f.exr") != std::string::npos;
            CHECK(consecutive);
        }
    }
    SECTION("two renders carry no evidence either way and are never refused for it") {
        std::vector<ExrImage> renders = {render(streams, 0, 1), render(streams, 1, 2)};
        CHECK_NOTHROW(combineRenders(renders));
    }
}

TEST_CASE("strongestRenderCorrelation: independent renders give -1/N, renders sharing a stream far more", "[compare]") {
    std::vector<std::vector<float>> streams;
    for (int j = 0; j < 16; ++j) streams.push_back(stream(j));
    std::vector<const std::vector<float>*> independent, sharing;
    std::vector<std::vector<float>> halves;  // render k = streams 2k, 2k+1 (independent) or k, k+1
    for (int k = 0; k < 8; ++k) {
        for (const auto& [a, b] : {std::pair{2 * k, 2 * k + 1}, std::pair{k, k + 1}}) {
            std::vector<float> v(streams[0].size());
            for (size_t i = 0; i < v.size(); ++i) v[i] = 0.5f * (streams[size_t(a)][i] + streams[size_t(b)][i]);
            halves.push_back(v);
        }
    }
    for (int k = 0; k < 8; ++k) {
        independent.push_back(&halves[size_t(2 * k)]);
        sharing.push_back(&halves[size_t(2 * k + 1)]);
    }
    const compare_detail::RenderCorrelation ind = compare_detail::strongestRenderCorrelation(independent);
    const compare_detail::RenderCorrelation sh = compare_detail::strongestRenderCorrelation(sharing);
    INFO("independent: " << ind.correlation << " +- " << ind.standardError << " (z " << ind.zScore << "); sharing: "
                         << sh.correlation << " (z " << sh.zScore << ")");
    CHECK(ind.pixels == size_t(kSize) * kSize);
    CHECK(ind.expected == Approx(-1.0 / 8.0));
    // The largest of 28 pair z-scores of independent renders: P(max > 4) < 28 * 3.2e-5 = 1e-3.
    CHECK(ind.zScore < 4.0);
    // Renders k and k + 1 share half their samples: their true correlation is 1/2.
    CHECK(sh.second == sh.first + 1);
    CHECK(sh.correlation - sh.expected > 0.3);
    CHECK(sh.zScore > compare_detail::kSharedNoiseZ);
}
