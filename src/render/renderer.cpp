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

// One pass's film-side buffers and the rules that map a contribution to a film pixel: the pixel
// values, the splats and the strategy and depth layers, gathered in tile order.
struct PassBuffers {
    const FilmWindow& fw;
    PassLayout layout;
    size_t filmPixels;  // strategy and depth layers are indexed like the film (which may hold more than the window)
    bool splats;
    std::vector<Rgb> passL, passLight, passW, passU, passD;
    std::vector<TileOutput> tiles;

    size_t filmIndex(int x, int y) const { return size_t(y - fw.y0) * size_t(fw.width) + size_t(x - fw.x0); }
    // Splats outside the crop window are dropped: the camera's importance is zero there
    // (docs/camera.md, "Crop windows"). The window is tested in float before the conversion to
    // int: a NaN or huge raster position would make that conversion undefined behaviour (in
    // practice INT_MIN, which passes no test, but UB all the same).
    bool pixelOf(Vec2 raster, int* px, int* py) const {
        const float fx = std::floor(raster.x), fy = std::floor(raster.y);
        if (!(fx >= float(layout.x0) && fx < float(layout.x1) && fy >= float(layout.y0) && fy < float(layout.y1)))
            return false;
        *px = int(fx);
        *py = int(fy);
        return true;
    }
    // The film pixel a layer contribution lands in: its own pixel, or a splat's (false: outside the window).
    bool layerPixel(uint32_t own, bool splat, Vec2 raster, size_t* i) const {
        int px = int(own % uint32_t(layout.width)), py = int(own / uint32_t(layout.width));
        if (splat && !pixelOf(raster, &px, &py)) return false;
        *i = filmIndex(px, py);
        return true;
    }
};

// The film must hold the camera's crop window (or more of the image, e.g. all of it): per-pass
// buffers are sized by the window, so a small crop of a huge image needs little memory.
void requireFilmHoldsCrop(const Camera& cam, const FilmWindow& fw) {
    if (fw.fullWidth != cam.width() || fw.fullHeight != cam.height() || fw.x0 > cam.cropX0() || fw.y0 > cam.cropY0() ||
        fw.x0 + fw.width < cam.cropX1() || fw.y0 + fw.height < cam.cropY1())
        throw std::invalid_argument("the film (" + fw.text() + ") does not hold the camera's crop window");
}

// Only the camera's crop window is sampled (the whole image by default), in tiles.
PassBuffers passBuffers(const Scene& scene, const Integrator& integrator, const RenderOptions& options, Film& film) {
    const Camera& cam = scene.camera;
    const int x0 = cam.cropX0(), y0 = cam.cropY0(), x1 = cam.cropX1(), y1 = cam.cropY1();
    const int tile = std::max(1, options.tileSize);
    const int tilesX = (x1 - x0 + tile - 1) / tile, tilesY = (y1 - y0 + tile - 1) / tile;
    PassBuffers b{film.window(), PassLayout{cam.width(), x0, y0, x1, y1, tile, tilesX, tilesY}, film.pixelCount(),
                  integrator.producesSplats(), {}, {}, {}, {}, {}, {}};
    const size_t nPixels = b.layout.windowPixels();
    b.passL.resize(nPixels);
    b.passLight.resize(nPixels);
    b.tiles.resize(size_t(tilesX) * size_t(tilesY));
    if (film.strategies().enabled()) {
        b.passW.resize(size_t(film.strategies().layerCount()) * b.filmPixels);
        b.passU.resize(b.passW.size());
    }
    if (film.depths().enabled()) b.passD.resize(size_t(film.depths().layerCount()) * b.filmPixels);
    return b;
}

// Splats and layers of the pass's tiles, gathered in tile order: the sums do not depend on the threads.
void gatherTileOutputs(PassBuffers& b, const StrategyLayers& layers, const DepthLayers& depths) {
    if (b.splats) std::fill(b.passLight.begin(), b.passLight.end(), Rgb(0.f));
    std::fill(b.passW.begin(), b.passW.end(), Rgb(0.f));
    std::fill(b.passU.begin(), b.passU.end(), Rgb(0.f));
    std::fill(b.passD.begin(), b.passD.end(), Rgb(0.f));
    for (const TileOutput& to : b.tiles) {
        for (const Splat& sp : to.splats) {
            int px, py;
            if (b.pixelOf(sp.raster, &px, &py)) b.passLight[b.layout.local(px, py)] += sp.value;
        }
        size_t p;
        if (layers.enabled())
            for (const auto& [own, c] : to.strategies) {
                if (!b.layerPixel(own, c.splat, c.raster, &p)) continue;
                const size_t i = size_t(StrategyLayers::index(c.s, c.t)) * b.filmPixels + p;
                b.passW[i] += c.weighted;
                b.passU[i] += c.unweighted;
            }
        if (depths.enabled())
            for (const auto& [own, c] : to.depths) {
                if (c.depth < 0 || c.depth > depths.maxDepth())
                    throw std::invalid_argument("a contribution of depth " + std::to_string(c.depth) +
                                                " does not fit the film's depth layers (0.." +
                                                std::to_string(depths.maxDepth()) + ")");
                if (b.layerPixel(own, c.splat, c.raster, &p)) b.passD[size_t(c.depth) * b.filmPixels + p] += c.value;
            }
    }
}

// The pass's pixel values (camera side plus splats), its light image and layers, and its sample index.
void addPassToFilm(const PassBuffers& b, uint64_t s, Film& film) {
    const PassLayout& L = b.layout;
    for (int y = L.y0; y < L.y1; ++y)
        for (int x = L.x0; x < L.x1; ++x) {
            const size_t p = L.local(x, y);
            film.addSample(x - b.fw.x0, y - b.fw.y0, b.splats ? b.passL[p] + b.passLight[p] : b.passL[p]);
            if (b.splats) film.addLight(x - b.fw.x0, y - b.fw.y0, b.passLight[p]);
        }
    if (film.strategies().enabled()) film.strategies().addPass(b.passW, b.passU);
    if (film.depths().enabled()) film.depths().addPass(b.passD);
    film.samples().add(SampleRange{s, s + 1});
}

}  // namespace

RenderStats renderImage(const Scene& scene, const Integrator& integrator, const RenderOptions& options, Film& film,
                        const std::atomic<bool>* cancel, const std::function<void(const RenderProgress&)>& progress) {
    requireFilmHoldsCrop(scene.camera, film.window());
    if (!film.samples().empty() && film.samples().endIndex() != options.firstSample)
        throw std::invalid_argument("the film's samples end at " + std::to_string(film.samples().endIndex()) +
                                    ", not at the first sample to render (" + std::to_string(options.firstSample) + ")");
    std::unique_ptr<tbb::global_control> threadLimit;
    if (options.threads > 0)
        threadLimit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                            size_t(options.threads));
    PassBuffers b = passBuffers(scene, integrator, options, film);
    const auto start = std::chrono::steady_clock::now();
    auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };

    RenderStats stats;
    for (int pass = 0; pass < options.spp; ++pass) {
        const uint64_t s = options.firstSample + uint64_t(pass);
        const bool interrupted =
            !(options.scheduler
                  ? options.scheduler->renderPass(scene, integrator, b.layout, options.seed, s, b.passL, b.tiles, cancel)
                  : renderPassMegakernel(scene, integrator, b.layout, options.seed, s, b.passL, b.tiles, cancel));
        if (interrupted) {  // an incomplete pass is dropped: every pixel keeps the same count
            stats.cancelled = true;
            break;
        }
        gatherTileOutputs(b, film.strategies(), film.depths());
        addPassToFilm(b, s, film);
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
