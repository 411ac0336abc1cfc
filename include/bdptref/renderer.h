// Drives an integrator over the image: passes of one sample per pixel, tiles in parallel (TBB),
// deterministic accumulation into the Film, cancellation at any time with an exact sample count.
#pragma once

#include "bdptref/film.h"
#include "bdptref/integrator.h"

#include <atomic>
#include <cstdint>
#include <functional>

namespace bdptref {

class Scene;
class PassScheduler;

struct RenderOptions {
    int spp = 16;
    uint32_t seed = 0;
    int threads = 0;  // 0 = all cores
    int tileSize = 16;
    PassScheduler* scheduler = nullptr;  // computes each pass; null = the tile megakernel (pass_scheduler.h)
};

struct RenderProgress {
    int passesDone = 0;
    int passesTotal = 0;
    double seconds = 0;
};

struct RenderStats {
    int passesDone = 0;  // every pixel received exactly this many samples
    bool cancelled = false;
    double seconds = 0;
};

// Renders options.spp samples per pixel into `film` (which must match the camera's resolution).
// Each pass adds one sample per pixel; a pass interrupted by `cancel` is discarded whole, so the
// film always holds complete passes. `progress` (optional) is called after every pass.
RenderStats renderImage(const Scene& scene, const Integrator& integrator, const RenderOptions& options, Film& film,
                        const std::atomic<bool>* cancel = nullptr,
                        const std::function<void(const RenderProgress&)>& progress = {});

// Pixel index used to key the RNG (full-image coordinates).
inline uint32_t pixelIndex(int x, int y, int width) { return uint32_t(y) * uint32_t(width) + uint32_t(x); }

}  // namespace bdptref
