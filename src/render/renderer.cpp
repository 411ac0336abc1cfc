#include "bdptref/renderer.h"

#include "bdptref/scene.h"
#include "scene/accel.h"

#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <chrono>
#include <memory>
#include <stdexcept>

namespace bdptref {

RenderStats renderImage(const Scene& scene, const Integrator& integrator, const RenderOptions& options, Film& film,
                        const std::atomic<bool>* cancel, const std::function<void(const RenderProgress&)>& progress) {
    const int width = scene.camera.width(), height = scene.camera.height();
    if (film.width() != width || film.height() != height)
        throw std::invalid_argument("film resolution differs from the camera's");
    std::unique_ptr<tbb::global_control> threadLimit;
    if (options.threads > 0)
        threadLimit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                            size_t(options.threads));

    const int tile = std::max(1, options.tileSize);
    const int tilesX = (width + tile - 1) / tile, tilesY = (height + tile - 1) / tile;
    std::vector<Rgb> pass(film.pixelCount());
    const auto start = std::chrono::steady_clock::now();
    auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };

    RenderStats stats;
    for (int s = 0; s < options.spp; ++s) {
        std::atomic<bool> interrupted{false};
        tbb::parallel_for(tbb::blocked_range<int>(0, tilesX * tilesY, 1), [&](const tbb::blocked_range<int>& r) {
            setFlushDenormals();
            for (int t = r.begin(); t != r.end(); ++t) {
                if (cancel && cancel->load(std::memory_order_relaxed)) {
                    interrupted = true;
                    return;
                }
                const int x0 = (t % tilesX) * tile, y0 = (t / tilesX) * tile;
                for (int y = y0; y < std::min(y0 + tile, height); ++y)
                    for (int x = x0; x < std::min(x0 + tile, width); ++x) {
                        const PixelSampler sampler(options.seed, pixelIndex(x, y, width), uint64_t(s));
                        pass[size_t(y) * size_t(width) + size_t(x)] = integrator.samplePixel(scene, x, y, sampler);
                    }
            }
        });
        if (interrupted) {  // an incomplete pass is dropped: every pixel keeps the same count
            stats.cancelled = true;
            break;
        }
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x) film.addSample(x, y, pass[size_t(y) * size_t(width) + size_t(x)]);
        stats.passesDone = s + 1;
        if (progress) progress(RenderProgress{stats.passesDone, options.spp, elapsed()});
        if (cancel && cancel->load()) {
            stats.cancelled = s + 1 < options.spp;
            if (stats.cancelled) break;
        }
    }
    stats.seconds = elapsed();
    return stats;
}

}  // namespace bdptref
