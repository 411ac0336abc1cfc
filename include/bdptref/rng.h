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

// Random numbers of one pixel sample. key = (pixel index, seed); a dimension is one 32-bit word
// of its stream: word (dimension % 4) of the Philox block with counter = (dimension / 4, sample
// index low, sample index high, stream). get2D takes two consecutive words of one block (the map
// below never lets a 2D draw straddle two blocks). The last block drawn is kept, so the draws of one
// decision group (a vertex's lobe, direction and roulette; its light choice and light point) cost
// one Philox evaluation; the numbers do not depend on it (docs/rng.md).
class PixelSampler {
public:
    PixelSampler(uint32_t seed, uint32_t pixelIndex, uint64_t sampleIndex)
        : key_{pixelIndex, seed}, sampleLo_(uint32_t(sampleIndex)), sampleHi_(uint32_t(sampleIndex >> 32)) {}

    PhiloxCounter block(RngStream stream, uint32_t blockIndex) const {
        const uint64_t tag = (uint64_t(stream) << 32) | blockIndex;
        if (tag != lastTag_) {
            last_ = philox4x32_10({blockIndex, sampleLo_, sampleHi_, uint32_t(stream)}, key_);
            lastTag_ = tag;
        }
        return last_;
    }
    float get1D(RngStream stream, uint32_t dimension) const {
        return uintToUnitFloat(block(stream, dimension >> 2)[dimension & 3u]);
    }
    Vec2 get2D(RngStream stream, uint32_t dimension) const {
        const PhiloxCounter b = block(stream, dimension >> 2);
        return Vec2(uintToUnitFloat(b[dimension & 3u]), uintToUnitFloat(b[(dimension & 3u) + 1u]));
    }

private:
    PhiloxKey key_;
    uint32_t sampleLo_, sampleHi_;
    mutable uint64_t lastTag_ = ~uint64_t(0);  // (stream, block) of last_; none yet
    mutable PhiloxCounter last_{};
};

// The dimension map (docs/rng.md). Dimensions are fixed slots, not a running counter, so a
// decision that is skipped (a path that ends early) never shifts the numbers of later ones.
// A dimension is one word: a 2D slot uses it and the next one, inside the same block of four.
namespace dim {
// Camera stream, block 0.
constexpr uint32_t kFilm = 0;  // 2D: jitter inside the pixel
constexpr uint32_t kLens = 2;  // 2D: reserved for a thin lens
// Light stream: block 0 the light and the point on it, block 1 the direction.
constexpr uint32_t kLightChoice = 0;    // 1D: which light emits the light subpath
constexpr uint32_t kEmitPosition = 1;   // 2D: point on the light
constexpr uint32_t kEmitDirection = 4;  // 2D: direction of emission
// Per vertex, in both streams: slot `s` of the vertex reached after `bounce` scattering events
// (bounce 0 is the first surface hit) is dimension kVertexBase + bounce * kPerVertex + s: two
// blocks per vertex, the scattering decision's and next-event estimation's.
constexpr uint32_t kVertexBase = 8;
constexpr uint32_t kPerVertex = 8;
enum Slot : uint32_t {
    kBsdfLobe = 0,       // 1D: which BSDF lobe
    kBsdfDirection = 1,  // 2D: direction within the lobe
    kRoulette = 3,       // 1D: Russian roulette
    kNeeLight = 4,       // 1D: which light for next-event estimation
    kNeePosition = 5,    // 2D: point on that light
};
inline uint32_t vertex(uint32_t bounce, Slot slot) { return kVertexBase + bounce * kPerVertex + slot; }
constexpr bool within(uint32_t dimension2D) { return dimension2D % 4u != 3u; }
static_assert(within(kFilm) && within(kLens) && within(kEmitPosition) && within(kEmitDirection) &&
                  within(kVertexBase + kBsdfDirection) && within(kVertexBase + kNeePosition) && kVertexBase % 4u == 0 &&
                  kPerVertex % 4u == 0,
              "a 2D draw must not straddle two Philox blocks");
}  // namespace dim

}  // namespace bdptref
