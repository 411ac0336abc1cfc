// The seam between the render loop (renderImage: passes, accumulation, progress) and the code
// that computes one pass (one sample for every pixel of the crop window). The default is the tile
// megakernel (one call of Integrator::samplePixel per pixel sample); the wavefront mode
// (bdptref/wavefront.h) is another implementation that must produce the same outputs bit for bit.
#pragma once

#include "bdptref/integrator.h"

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <utility>
#include <vector>

namespace bdptref {

class Scene;

// What one tile of a pass hands to the accumulation, in canonical order (pixel order within the
// tile, the integrator's connection order within a pixel sample).
struct TileOutput {
    std::vector<Splat> splats;
    std::vector<std::pair<uint32_t, StrategyContribution>> strategies;  // (own pixel, contribution)
    std::vector<std::pair<uint32_t, DepthContribution>> depths;         // (own pixel, contribution)
    void clear() {
        splats.clear();
        strategies.clear();
        depths.clear();
    }
};

// The tiling of the crop window [x0, x1) x [y0, y1). Canonical sample order of a pass: tiles in
// index order, pixels row by row inside a tile.
struct PassLayout {
    int width = 0;  // full image width (pixel indices)
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    int tile = 16, tilesX = 0, tilesY = 0;
    int tileCount() const { return tilesX * tilesY; }
    int tileX0(int t) const { return x0 + (t % tilesX) * tile; }
    int tileY0(int t) const { return y0 + (t / tilesX) * tile; }
    int tileX1(int t) const { return std::min(tileX0(t) + tile, x1); }
    int tileY1(int t) const { return std::min(tileY0(t) + tile, y1); }
    int tilePixels(int t) const { return (tileX1(t) - tileX0(t)) * (tileY1(t) - tileY0(t)); }
    // Per-pass buffers (passL) hold the crop window only: their index of full-image pixel (x, y).
    size_t windowPixels() const { return size_t(x1 - x0) * size_t(y1 - y0); }
    size_t local(int x, int y) const { return size_t(y - y0) * size_t(x1 - x0) + size_t(x - x0); }
};

class PassScheduler {
public:
    virtual ~PassScheduler() = default;
    // Computes pass `sample`: passL[layout.local(x, y)] = the camera estimate of every pixel (x, y) of
    // the crop window (the RNG keys and TileOutput's own pixels stay full-image pixel indices),
    // tiles[t] = tile t's splats, strategy and depth contributions (cleared first). Returns false when
    // `cancel` was seen (the pass is then incomplete and is discarded by the caller).
    virtual bool renderPass(const Scene& scene, const Integrator& integrator, const PassLayout& layout, uint32_t seed,
                            uint64_t sample, std::vector<Rgb>& passL, std::vector<TileOutput>& tiles,
                            const std::atomic<bool>* cancel) = 0;
};

}  // namespace bdptref
