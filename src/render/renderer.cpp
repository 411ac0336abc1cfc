#include "bdptref/renderer.h"

#include "bdptref/pass_scheduler.h"
#include "bdptref/scene.h"
#include "scene/accel.h"

#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <chrono>
#include <memory>
#include <stdexcept>

namespace bdptref {

namespace {

// The default pass: tiles in parallel, each pixel sample by one samplePixel call (a megakernel).
bool renderPassMegakernel(const Scene& scene, const Integrator& integrator, const PassLayout& L, uint32_t seed,
                          uint64_t s, std::vector<Rgb>& passL, std::vector<TileOutput>& tiles,
                          const std::atomic<bool>* cancel) {
    std::atomic<bool> interrupted{false};
    tbb::parallel_for(tbb::blocked_range<int>(0, L.tileCount(), 1), [&](const tbb::blocked_range<int>& r) {
        setFlushDenormals();
        thread_local SampleOutput out;
        for (int t = r.begin(); t != r.end(); ++t) {
            if (cancel && cancel->load(std::memory_order_relaxed)) {
                interrupted = true;
                return;
            }
            TileOutput& to = tiles[size_t(t)];
            to.splats.clear();
            to.strategies.clear();
            for (int y = L.tileY0(t); y < L.tileY1(t); ++y)
                for (int x = L.tileX0(t); x < L.tileX1(t); ++x) {
                    const uint32_t pixel = pixelIndex(x, y, L.width);
                    const PixelSampler sampler(seed, pixel, s);
                    out.clear();
                    integrator.samplePixel(scene, x, y, sampler, out);
                    passL[pixel] = out.L;
                    to.splats.insert(to.splats.end(), out.splats.begin(), out.splats.end());
                    for (const StrategyContribution& c : out.strategies) to.strategies.emplace_back(pixel, c);
                }
        }
    });
    return !interrupted;
}

}  // namespace

RenderStats renderImage(const Scene& scene, const Integrator& integrator, const RenderOptions& options, Film& film,
                        const std::atomic<bool>* cancel, const std::function<void(const RenderProgress&)>& progress) {
    const Camera& cam = scene.camera;
    const int width = cam.width(), height = cam.height();
    if (film.width() != width || film.height() != height)
        throw std::invalid_argument("film resolution differs from the camera's");
    std::unique_ptr<tbb::global_control> threadLimit;
    if (options.threads > 0)
        threadLimit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                            size_t(options.threads));

    // Only the camera's crop window is sampled (the whole image by default).
    const int x0 = cam.cropX0(), y0 = cam.cropY0(), x1 = cam.cropX1(), y1 = cam.cropY1();
    const int tile = std::max(1, options.tileSize);
    const int tilesX = (x1 - x0 + tile - 1) / tile, tilesY = (y1 - y0 + tile - 1) / tile;
    const size_t nPixels = film.pixelCount();
    std::vector<Rgb> passL(nPixels), passLight(nPixels);
    std::vector<TileOutput> tiles(size_t(tilesX) * size_t(tilesY));
    StrategyLayers& layers = film.strategies();
    std::vector<Rgb> passW, passU;
    if (layers.enabled()) {
        passW.resize(size_t(layers.layerCount()) * nPixels);
        passU.resize(passW.size());
    }
    const bool splats = integrator.producesSplats();
    const auto start = std::chrono::steady_clock::now();
    auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
    auto pixelOf = [&](Vec2 raster, uint32_t* index) {
        const int px = int(std::floor(raster.x)), py = int(std::floor(raster.y));
        if (px < x0 || px >= x1 || py < y0 || py >= y1) return false;
        *index = uint32_t(py) * uint32_t(width) + uint32_t(px);
        return true;
    };

    if (!film.samples().empty() && film.samples().endIndex() != options.firstSample)
        throw std::invalid_argument("the film's samples end at " + std::to_string(film.samples().endIndex()) +
                                    ", not at the first sample to render (" + std::to_string(options.firstSample) + ")");

    RenderStats stats;
    for (int pass = 0; pass < options.spp; ++pass) {
        const uint64_t s = options.firstSample + uint64_t(pass);
        const PassLayout layout{width, x0, y0, x1, y1, tile, tilesX, tilesY};
        const bool interrupted =
            !(options.scheduler ? options.scheduler->renderPass(scene, integrator, layout, options.seed, s, passL, tiles, cancel)
                                : renderPassMegakernel(scene, integrator, layout, options.seed, s, passL, tiles, cancel));
        if (interrupted) {  // an incomplete pass is dropped: every pixel keeps the same count
            stats.cancelled = true;
            break;
        }
        // Splats and layers are gathered in tile order: the sums do not depend on the threads.
        if (splats) std::fill(passLight.begin(), passLight.end(), Rgb(0.f));
        if (layers.enabled()) {
            std::fill(passW.begin(), passW.end(), Rgb(0.f));
            std::fill(passU.begin(), passU.end(), Rgb(0.f));
        }
        for (const TileOutput& to : tiles) {
            for (const Splat& sp : to.splats) {
                uint32_t p;
                if (pixelOf(sp.raster, &p)) passLight[p] += sp.value;
            }
            for (const auto& [own, c] : to.strategies) {
                uint32_t p = own;
                if (c.splat && !pixelOf(c.raster, &p)) continue;
                const size_t i = size_t(StrategyLayers::index(c.s, c.t)) * nPixels + p;
                passW[i] += c.weighted;
                passU[i] += c.unweighted;
            }
        }
        for (int y = y0; y < y1; ++y)
            for (int x = x0; x < x1; ++x) {
                const size_t p = size_t(y) * size_t(width) + size_t(x);
                film.addSample(x, y, splats ? passL[p] + passLight[p] : passL[p]);
                if (splats) film.addLight(x, y, passLight[p]);
            }
        if (layers.enabled()) layers.addPass(passW, passU);
        film.samples().add(SampleRange{s, s + 1});
        stats.passesDone = pass + 1;
        const bool last = stats.passesDone == options.spp;
        const double now = elapsed();
        if (progress) progress(RenderProgress{stats.passesDone, options.spp, now, options.timeBudgetSeconds});
        if (cancel && cancel->load() && !last) {
            stats.cancelled = true;
            break;
        }
        if (options.timeBudgetSeconds > 0 && now >= options.timeBudgetSeconds && !last) {
            stats.timeLimited = true;
            break;
        }
    }
    stats.seconds = elapsed();
    return stats;
}

}  // namespace bdptref
