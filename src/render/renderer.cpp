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
            to.clear();
            for (int y = L.tileY0(t); y < L.tileY1(t); ++y)
                for (int x = L.tileX0(t); x < L.tileX1(t); ++x) {
                    const uint32_t pixel = pixelIndex(x, y, L.width);
                    const PixelSampler sampler(seed, pixel, s);
                    out.clear();
                    integrator.samplePixel(scene, x, y, sampler, out);
                    passL[L.local(x, y)] = out.L;
                    to.splats.insert(to.splats.end(), out.splats.begin(), out.splats.end());
                    for (const StrategyContribution& c : out.strategies) to.strategies.emplace_back(pixel, c);
                    for (const DepthContribution& c : out.depths) to.depths.emplace_back(pixel, c);
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
    // The film holds the crop window (or more of the image, e.g. all of it): per-pass buffers are
    // sized by the window, so a small crop of a huge image needs little memory.
    const FilmWindow& fw = film.window();
    if (fw.fullWidth != width || fw.fullHeight != height || fw.x0 > cam.cropX0() || fw.y0 > cam.cropY0() ||
        fw.x0 + fw.width < cam.cropX1() || fw.y0 + fw.height < cam.cropY1())
        throw std::invalid_argument("the film (" + fw.text() + ") does not hold the camera's crop window");
    std::unique_ptr<tbb::global_control> threadLimit;
    if (options.threads > 0)
        threadLimit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                            size_t(options.threads));

    // Only the camera's crop window is sampled (the whole image by default).
    const int x0 = cam.cropX0(), y0 = cam.cropY0(), x1 = cam.cropX1(), y1 = cam.cropY1();
    const int tile = std::max(1, options.tileSize);
    const int tilesX = (x1 - x0 + tile - 1) / tile, tilesY = (y1 - y0 + tile - 1) / tile;
    const PassLayout layout{width, x0, y0, x1, y1, tile, tilesX, tilesY};
    const size_t nPixels = layout.windowPixels();
    std::vector<Rgb> passL(nPixels), passLight(nPixels);
    std::vector<TileOutput> tiles(size_t(tilesX) * size_t(tilesY));
    StrategyLayers& layers = film.strategies();
    DepthLayers& depths = film.depths();
    // Strategy and depth layers are indexed like the film (which may hold more than the window).
    const size_t filmPixels = film.pixelCount();
    auto filmIndex = [&](int x, int y) { return size_t(y - fw.y0) * size_t(fw.width) + size_t(x - fw.x0); };
    std::vector<Rgb> passW, passU, passD;
    if (layers.enabled()) {
        passW.resize(size_t(layers.layerCount()) * filmPixels);
        passU.resize(passW.size());
    }
    if (depths.enabled()) passD.resize(size_t(depths.layerCount()) * filmPixels);
    const bool splats = integrator.producesSplats();
    const auto start = std::chrono::steady_clock::now();
    auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
    // Splats outside the crop window are dropped: the camera's importance is zero there
    // (docs/camera.md, "Crop windows").
    // The window is tested in float before the conversion to int: a NaN or huge raster position
    // would make that conversion undefined behaviour (in practice INT_MIN, which passes no test,
    // but UB all the same).
    auto pixelOf = [&](Vec2 raster, int* px, int* py) {
        const float fx = std::floor(raster.x), fy = std::floor(raster.y);
        if (!(fx >= float(x0) && fx < float(x1) && fy >= float(y0) && fy < float(y1))) return false;
        *px = int(fx);
        *py = int(fy);
        return true;
    };
    // The film pixel a layer contribution lands in: its own pixel, or a splat's (false: outside the window).
    auto layerPixel = [&](uint32_t own, bool splat, Vec2 raster, size_t* i) {
        int px = int(own % uint32_t(width)), py = int(own / uint32_t(width));
        if (splat && !pixelOf(raster, &px, &py)) return false;
        *i = filmIndex(px, py);
        return true;
    };

    if (!film.samples().empty() && film.samples().endIndex() != options.firstSample)
        throw std::invalid_argument("the film's samples end at " + std::to_string(film.samples().endIndex()) +
                                    ", not at the first sample to render (" + std::to_string(options.firstSample) + ")");

    RenderStats stats;
    for (int pass = 0; pass < options.spp; ++pass) {
        const uint64_t s = options.firstSample + uint64_t(pass);
        const bool interrupted =
            !(options.scheduler ? options.scheduler->renderPass(scene, integrator, layout, options.seed, s, passL, tiles, cancel)
                                : renderPassMegakernel(scene, integrator, layout, options.seed, s, passL, tiles, cancel));
        if (interrupted) {  // an incomplete pass is dropped: every pixel keeps the same count
            stats.cancelled = true;
            break;
        }
        // Splats and layers are gathered in tile order: the sums do not depend on the threads.
        if (splats) std::fill(passLight.begin(), passLight.end(), Rgb(0.f));
        std::fill(passW.begin(), passW.end(), Rgb(0.f));
        std::fill(passU.begin(), passU.end(), Rgb(0.f));
        std::fill(passD.begin(), passD.end(), Rgb(0.f));
        for (const TileOutput& to : tiles) {
            for (const Splat& sp : to.splats) {
                int px, py;
                if (pixelOf(sp.raster, &px, &py)) passLight[layout.local(px, py)] += sp.value;
            }
            size_t p;
            if (layers.enabled())
                for (const auto& [own, c] : to.strategies) {
                    if (!layerPixel(own, c.splat, c.raster, &p)) continue;
                    const size_t i = size_t(StrategyLayers::index(c.s, c.t)) * filmPixels + p;
                    passW[i] += c.weighted;
                    passU[i] += c.unweighted;
                }
            if (depths.enabled())
                for (const auto& [own, c] : to.depths) {
                    if (c.depth < 0 || c.depth > depths.maxDepth())
                        throw std::invalid_argument("a contribution of depth " + std::to_string(c.depth) +
                                                    " does not fit the film's depth layers (0.." + std::to_string(depths.maxDepth()) + ")");
                    if (layerPixel(own, c.splat, c.raster, &p)) passD[size_t(c.depth) * filmPixels + p] += c.value;
                }
        }
        for (int y = y0; y < y1; ++y)
            for (int x = x0; x < x1; ++x) {
                const size_t p = layout.local(x, y);
                film.addSample(x - fw.x0, y - fw.y0, splats ? passL[p] + passLight[p] : passL[p]);
                if (splats) film.addLight(x - fw.x0, y - fw.y0, passLight[p]);
            }
        if (layers.enabled()) layers.addPass(passW, passU);
        if (depths.enabled()) depths.addPass(passD);
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
