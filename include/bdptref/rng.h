// Counter-based random numbers: Philox4x32-10 (Salmon et al., SC'11, "Parallel random numbers:
// as easy as 1, 2, 3"). Every random decision of a pixel sample is a pure function of
// (seed, pixel, sample index, stream, dimension), so images do not depend on threads, tiles or
// scheduling. The layout of key and counter and the dimension map are specified in docs/rng.md.
#pragma once

#include "bdptref/math.h"

#include <array>
#include <cstdint>

namespace bdptref {

using PhiloxCounter = std::array<uint32_t, 4>;
using PhiloxKey = std::array<uint32_t, 2>;

// The raw bijection: 10 rounds of Philox4x32 (Random123's philox4x32 with R=10).
PhiloxCounter philox4x32_10(PhiloxCounter counter, PhiloxKey key);

// Maps the top 24 bits of a 32-bit word to a float in [0, 1): exactly representable, never 1.
inline float uintToUnitFloat(uint32_t x) { return float(x >> 8) * 0x1p-24f; }

// Which sequence of dimensions a draw belongs to (counter word 3).
enum class RngStream : uint32_t { Camera = 0, Light = 1 };

// Random numbers of one pixel sample. key = (pixel index, seed); counter = (dimension,
// sample index low, sample index high, stream). One Philox block per dimension: get1D uses
// word 0, get2D words 0 and 1.
class PixelSampler {
public:
    PixelSampler(uint32_t seed, uint32_t pixelIndex, uint64_t sampleIndex)
        : key_{pixelIndex, seed}, sampleLo_(uint32_t(sampleIndex)), sampleHi_(uint32_t(sampleIndex >> 32)) {}

    PhiloxCounter block(RngStream stream, uint32_t dimension) const {
        return philox4x32_10({dimension, sampleLo_, sampleHi_, uint32_t(stream)}, key_);
    }
    float get1D(RngStream stream, uint32_t dimension) const {
        return uintToUnitFloat(block(stream, dimension)[0]);
    }
    Vec2 get2D(RngStream stream, uint32_t dimension) const {
        const PhiloxCounter b = block(stream, dimension);
        return Vec2(uintToUnitFloat(b[0]), uintToUnitFloat(b[1]));
    }

private:
    PhiloxKey key_;
    uint32_t sampleLo_, sampleHi_;
};

// The dimension map (docs/rng.md). Dimensions are fixed slots, not a running counter, so a
// decision that is skipped (a path that ends early) never shifts the numbers of later ones.
namespace dim {
// Camera stream.
constexpr uint32_t kFilm = 0;  // 2D: jitter inside the pixel
constexpr uint32_t kLens = 1;  // 2D: reserved for a thin lens
// Light stream.
constexpr uint32_t kLightChoice = 0;    // 1D: which light emits the light subpath
constexpr uint32_t kEmitPosition = 1;   // 2D: point on the light
constexpr uint32_t kEmitDirection = 2;  // 2D: direction of emission
// Per vertex, in both streams: slot `s` of the vertex reached after `bounce` scattering events
// (bounce 0 is the first surface hit) is dimension kVertexBase + bounce * kPerVertex + s.
constexpr uint32_t kVertexBase = 3;
constexpr uint32_t kPerVertex = 8;
enum Slot : uint32_t {
    kBsdfLobe = 0,     // 1D: which BSDF lobe
    kBsdfDirection = 1,  // 2D: direction within the lobe
    kRoulette = 2,     // 1D: Russian roulette
    kNeeLight = 3,     // 1D: which light for next-event estimation
    kNeePosition = 4,  // 2D: point on that light
};
inline uint32_t vertex(uint32_t bounce, Slot slot) { return kVertexBase + bounce * kPerVertex + slot; }
}  // namespace dim

}  // namespace bdptref
