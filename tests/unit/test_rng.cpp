// Philox4x32-10 against the published Random123 known-answer vectors (Random123 1.x,
// tests/kat_vectors: "philox4x32 10" lines; columns counter[4], key[2], expected[4]).
#include "bdptref/rng.h"

#include <catch2/catch.hpp>

#include <set>

using namespace bdptref;

TEST_CASE("Philox4x32-10 reproduces the Random123 known-answer vectors", "[rng]") {
    struct Kat { PhiloxCounter ctr; PhiloxKey key; PhiloxCounter expected; };
    const Kat kats[] = {
        {{0x00000000u, 0x00000000u, 0x00000000u, 0x00000000u}, {0x00000000u, 0x00000000u},
         {0x6627e8d5u, 0xe169c58du, 0xbc57ac4cu, 0x9b00dbd8u}},
        {{0xffffffffu, 0xffffffffu, 0xffffffffu, 0xffffffffu}, {0xffffffffu, 0xffffffffu},
         {0x408f276du, 0x41c83b0eu, 0xa20bc7c6u, 0x6d5451fdu}},
        {{0x243f6a88u, 0x85a308d3u, 0x13198a2eu, 0x03707344u}, {0xa4093822u, 0x299f31d0u},
         {0xd16cfe09u, 0x94fdccebu, 0x5001e420u, 0x24126ea1u}},
    };
    for (const Kat& k : kats) CHECK(philox4x32_10(k.ctr, k.key) == k.expected);
}

TEST_CASE("PixelSampler lays out key and counter as docs/rng.md says", "[rng]") {
    const uint32_t seed = 7, pixel = 1234;
    const uint64_t sample = 0x100000005ull;  // exercises the high word of the sample index
    const PixelSampler s(seed, pixel, sample);
    const PhiloxCounter expected = philox4x32_10({42u, 5u, 1u, 1u}, {pixel, seed});
    CHECK(s.block(RngStream::Light, 42) == expected);
    CHECK(s.get1D(RngStream::Light, 42) == uintToUnitFloat(expected[0]));
    CHECK(s.get2D(RngStream::Light, 42).y == uintToUnitFloat(expected[1]));
}

TEST_CASE("uintToUnitFloat stays in 0 to 1 (1 excluded) and keeps 24 bits", "[rng]") {
    CHECK(uintToUnitFloat(0u) == 0.f);
    CHECK(uintToUnitFloat(0xFFFFFFFFu) < 1.f);
    CHECK(uintToUnitFloat(0xFFFFFFFFu) == 1.f - 0x1p-24f);
    CHECK(uintToUnitFloat(0x80000000u) == 0.5f);
}

TEST_CASE("Different pixels, samples, streams and dimensions give different numbers", "[rng]") {
    std::set<uint32_t> seen;
    for (uint32_t p = 0; p < 8; ++p)
        for (uint64_t i = 0; i < 8; ++i)
            for (uint32_t d = 0; d < 8; ++d)
                for (RngStream st : {RngStream::Camera, RngStream::Light})
                    seen.insert(PixelSampler(1, p, i).block(st, d)[0]);
    // 1024 draws of 32-bit words: a collision has probability ~1e-4; the set must be (almost) full.
    CHECK(seen.size() >= 1023);
}

TEST_CASE("Unit floats from PixelSampler are uniform (mean and variance within 5 sigma)", "[rng]") {
    // For U(0,1): mean 1/2, variance 1/12. With n draws the standard error of the mean is
    // sqrt(1/12/n) and of the second moment sqrt((1/5 - 1/9)/n). k = 5.
    const int n = 200000;
    double s1 = 0, s2 = 0;
    for (int i = 0; i < n; ++i) {
        const float u = PixelSampler(3, uint32_t(i % 97), uint64_t(i / 97)).get1D(RngStream::Camera, uint32_t(i % 5));
        REQUIRE(u >= 0.f);
        REQUIRE(u < 1.f);
        s1 += u;
        s2 += double(u) * u;
    }
    CHECK(std::abs(s1 / n - 0.5) < 5 * std::sqrt(1.0 / 12.0 / n));
    CHECK(std::abs(s2 / n - 1.0 / 3.0) < 5 * std::sqrt((1.0 / 5.0 - 1.0 / 9.0) / n));
}
