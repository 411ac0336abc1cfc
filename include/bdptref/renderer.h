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
    int spp = 16;  // passes to render: pixel samples firstSample .. firstSample + spp - 1
    // Index of the first pixel sample (`render --sample-range A:B`, resume). A film that already
    // holds samples must end exactly here, so that a resumed render equals an uninterrupted one.
    uint64_t firstSample = 0;
    // Stop at the first pass boundary at or after this many seconds (0: no time limit).
    double timeBudgetSeconds = 0;
    uint32_t seed = 0;
    int threads = 0;  // 0 = all cores
    int tileSize = 16;
    PassScheduler* scheduler = nullptr;  // computes each pass; null = the tile megakernel (pass_scheduler.h)
};

struct RenderProgress {
    int passesDone = 0;
    int passesTotal = 0;
    double seconds = 0;
    double secondsBudget = 0;  // RenderOptions::timeBudgetSeconds
};

struct RenderStats {
    int passesDone = 0;  // every pixel received exactly this many samples
    bool cancelled = false;
    bool timeLimited = false;  // stopped by timeBudgetSeconds before spp passes
    double seconds = 0;
};

// Renders options.spp samples per pixel into `film` (which must match the camera's resolution).
// Each pass adds one sample per pixel; a pass interrupted by `cancel` is discarded whole, so the
// film always holds complete passes. `progress` (optional) is called after every pass, with the
// film holding exactly the completed passes (film.samples() says which): a consistent state that
// can be saved as a checkpoint from inside the callback.
RenderStats renderImage(const Scene& scene, const Integrator& integrator, const RenderOptions& options, Film& film,
                        const std::atomic<bool>* cancel = nullptr,
                        const std::function<void(const RenderProgress&)>& progress = {});

// Pixel index used to key the RNG (full-image coordinates).
inline uint32_t pixelIndex(int x, int y, int width) { return uint32_t(y) * uint32_t(width) + uint32_t(x); }

}  // namespace bdptref
