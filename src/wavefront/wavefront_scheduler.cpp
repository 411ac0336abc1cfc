// The wavefront schedule of one pass (docs/wavefront.md). Samples of the pass are taken in the
// canonical order (tiles, then pixels row by row in a tile) and processed in pool passes of at
// most `pool` paths. Every stage is a tbb::parallel_for over the entries of its input queue; the
// light transport is done by the same functions the megakernel calls (bdpt.h, path_tracer.h).
// Nothing depends on the slot an entry got in a queue: results are written at the path's (or the
// connection's) own index, and the accumulation walks paths and connections in canonical order.
#include "bdptref/wavefront.h"

#include "bdptref/bdpt.h"
#include "bdptref/errors.h"
#include "bdptref/renderer.h"
#include "bdptref/scene.h"
#include "render/path_tracer.h"
#include "scene/accel.h"
#include "wavefront/work_queue.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <xmmintrin.h>

#include <algorithm>

namespace bdptref {

namespace {

enum class Kind { Path, Light, Bdpt };

constexpr uint64_t kWarpSize = 32;

// Output of the extend stage for one walk: what the closest-hit query found.
struct HitRecord {
    SurfaceHit hit;
    bool found = false;
};

// One entry of the connection queue: strategy (s, t) of the path in pool slot `path`.
struct ConnectionRecord {
    uint32_t path = 0;
    int32_t s = 0, t = 0;
};

enum ConnectionStatus : uint8_t { kNoContribution, kAwaitingShadow, kContributes, kOccluded };

struct PtShadowEntry {
    uint32_t path = 0;
    PtShadowRecord record;
};

// Embree and the megakernel workers run with denormals flushed; the stages must compute under
// the same floating-point mode (on the calling thread too), or results could differ in the last bit.
class FlushDenormalsScope {
public:
    FlushDenormalsScope() : saved_(_mm_getcsr()) { setFlushDenormals(); }
    ~FlushDenormalsScope() { _mm_setcsr(saved_); }
    FlushDenormalsScope(const FlushDenormalsScope&) = delete;
    FlushDenormalsScope& operator=(const FlushDenormalsScope&) = delete;

private:
    unsigned saved_;
};

Kind parseKind(const std::string& name) {
    if (name == "path" || name == "pt") return Kind::Path;
    if (name == "lt" || name == "light") return Kind::Light;
    if (name == "bdpt") return Kind::Bdpt;
    throw InputError("--integrator: unknown integrator '" + name + "' (available: path, lt, bdpt)");
}

uint64_t roundUpToWarp(uint64_t n) { return (n + kWarpSize - 1) / kWarpSize * kWarpSize; }

}  // namespace

struct WavefrontScheduler::Impl {
    Kind kind = Kind::Path;
    IntegratorSettings settings;
    BdptSettings bdpt;
    WavefrontOptions options;
    GpuReport report;
    int maxCam = 0, maxLight = 0;
    uint32_t pool = 0, shadowCapacity = 0, connectionCapacity = 0;

    // Per-path buffers of the pool (index = pool slot).
    std::vector<uint32_t> pixelOf, tileOf;
    std::vector<int32_t> xOf, yOf;
    std::vector<PathVertex> cameraVertices, lightVertices;  // maxCam / maxLight per path
    std::vector<Bsdf> cameraBsdfs, lightBsdfs;              // their BSDF side arrays (SubpathBsdfs)
    std::vector<SubpathWalk> walks;                         // BDPT/LT: 2 per path (camera, light)
    std::vector<PtPathState> ptStates;                      // PT: 1 per path
    std::vector<Rgb> ptDepthL;                              // PT with depth layers: maxDepth + 1 per path
    std::vector<HitRecord> hits;                            // 1 per walk
    std::vector<uint32_t> steps;                            // rays traced per walk (SIMT model)
    std::vector<Rgb> pathL;
    std::vector<uint64_t> connectionOffset;  // exclusive prefix sum of connections per path (+ total)
    // Queues.
    WorkQueue<uint32_t> rays, nextRays;  // walk (BDPT/LT) or path (PT) indices
    WorkQueue<PtShadowEntry> ptShadow;
    WorkQueue<uint32_t> shadow, finish;  // connection-queue indices
    std::vector<ConnectionRecord> connections;
    std::vector<PendingConnection> pending;
    std::vector<uint8_t> status;
    std::vector<Connection> results;
    std::vector<int> tileStart;  // canonical index of the first sample of each tile
    std::vector<StrategyCounts> chunkCounts;   // accumulate: per (s, t) of one connection chunk
    std::vector<uint64_t> chunkShadowByDepth;  // accumulate: connection shadow rays per depth

    // PT with --depth-layers: the per-depth sums of each path (bytes).
    uint64_t ptDepthBytesPerPath() const {
        return settings.recordDepths ? (uint64_t(settings.maxDepth) + 1) * sizeof(Rgb) : 0;
    }
    Rgb* ptDepthOf(uint32_t i) {
        return ptDepthL.empty() ? nullptr : &ptDepthL[size_t(i) * (size_t(settings.maxDepth) + 1)];
    }
    uint64_t fixedBytesPerPath() const {
        const uint64_t index = 4 * sizeof(uint32_t) + sizeof(uint64_t);  // pixel, tile, x, y, offset
        if (kind == Kind::Path) return sizeof(PtPathState) + sizeof(HitRecord) + index + ptDepthBytesPerPath();
        return 2 * (sizeof(SubpathWalk) + sizeof(HitRecord)) + sizeof(Rgb) + index;
    }
    uint64_t staticBytesPerPath() const {
        if (kind == Kind::Path) return fixedBytesPerPath();
        return fixedBytesPerPath() + uint64_t(maxCam + maxLight) * (sizeof(PathVertex) + sizeof(Bsdf));
    }

    StageStats& stage(const char* name, int bounce) { return report.stages[{name, bounce}]; }
    void countRay(const char* type, int depth, uint64_t n = 1) {
        std::vector<uint64_t>& v = report.raysByDepth[type];
        if (v.size() <= size_t(depth)) v.resize(size_t(depth) + 1, 0);
        v[size_t(depth)] += n;
    }

    // One launch of a stage over n queue entries: statistics, then the parallel pass.
    template <class Body>
    void launch(const char* name, int bounce, uint32_t n, uint64_t capacity, bool early, double bytesPerItem, Body&& body) {
        if (n == 0) return;
        StageStats& st = stage(name, bounce);
        ++st.launches;
        st.items += n;
        st.maxAtLaunch = std::max<uint64_t>(st.maxAtLaunch, n);
        st.capacity = capacity;
        if (early) ++st.flushes;
        report.wavefrontActiveLanes += n;
        report.wavefrontIssuedLanes += roundUpToWarp(n);
        report.trafficBytes += double(n) * bytesPerItem;
        tbb::parallel_for(tbb::blocked_range<uint32_t>(0, n, 64), [&](const tbb::blocked_range<uint32_t>& r) {
            setFlushDenormals();
            for (uint32_t i = r.begin(); i != r.end(); ++i) body(i);
        });
    }

    // Megakernel SIMT model: a warp is 32 consecutive samples, it issues each phase as long as
    // its longest lane (docs/wavefront.md).
    void addMegakernelWarps(uint32_t n, const std::vector<const std::vector<uint32_t>*>& phases, uint32_t stride,
                            const std::vector<uint32_t>& phaseOffset) {
        for (uint32_t w0 = 0; w0 < n; w0 += uint32_t(kWarpSize)) {
            const uint32_t w1 = std::min<uint32_t>(n, w0 + uint32_t(kWarpSize));
            for (size_t p = 0; p < phases.size(); ++p) {
                uint64_t mx = 0;
                for (uint32_t i = w0; i < w1; ++i) {
                    const uint64_t v = (*phases[p])[size_t(i) * stride + phaseOffset[p]];
                    report.megakernelActiveLanes += v;
                    mx = std::max(mx, v);
                }
                report.megakernelIssuedLanes += mx * kWarpSize;
            }
        }
    }

    void allocate(uint32_t samples) {
        const uint32_t want = std::max<uint32_t>(1, std::min<uint32_t>(pool, samples));
        if (pixelOf.size() >= want) return;
        pixelOf.assign(want, 0);
        tileOf.assign(want, 0);
        xOf.assign(want, 0);
        yOf.assign(want, 0);
        pathL.assign(want, Rgb(0.f));
        if (kind == Kind::Path) {
            ptStates.assign(want, PtPathState{});
            ptDepthL.assign(settings.recordDepths ? size_t(want) * (size_t(settings.maxDepth) + 1) : 0, Rgb(0.f));
            hits.assign(want, HitRecord{});
            steps.assign(want, 0);
            rays.reset(want);
            nextRays.reset(want);
            ptShadow.reset(shadowCapacity);
        } else {
            cameraVertices.assign(size_t(want) * size_t(maxCam), PathVertex{});
            lightVertices.assign(size_t(want) * size_t(maxLight), PathVertex{});
            cameraBsdfs.assign(size_t(want) * size_t(maxCam), Bsdf{});
            lightBsdfs.assign(size_t(want) * size_t(maxLight), Bsdf{});
            walks.assign(2 * size_t(want), SubpathWalk{});
            hits.assign(2 * size_t(want), HitRecord{});
            steps.assign(3 * size_t(want), 0);  // camera rays, light rays, connections
            connectionOffset.assign(size_t(want) + 1, 0);
            rays.reset(2 * want);
            nextRays.reset(2 * want);
            shadow.reset(shadowCapacity);
            finish.reset(connectionCapacity);
            connections.assign(connectionCapacity, ConnectionRecord{});
            pending.assign(connectionCapacity, PendingConnection{});
            status.assign(connectionCapacity, kNoContribution);
            results.assign(connectionCapacity, Connection{});
        }
        report.rayQueuesPerPath = kind == Kind::Path ? 2 : 4;
    }

    PassLayout layout;  // of the pass being rendered (passL is indexed by layout.local)

    // Fills the per-slot pixel coordinates of canonical samples [k0, k0 + n).
    void mapSamples(const PassLayout& L, uint64_t k0, uint32_t n) {
        for (uint32_t i = 0; i < n; ++i) {
            const int k = int(k0 + i);
            const int t = int(std::upper_bound(tileStart.begin(), tileStart.end(), k) - tileStart.begin()) - 1;
            const int local = k - tileStart[size_t(t)];
            const int w = L.tileX1(t) - L.tileX0(t);
            xOf[i] = L.tileX0(t) + local % w;
            yOf[i] = L.tileY0(t) + local / w;
            pixelOf[i] = pixelIndex(xOf[i], yOf[i], L.width);
            tileOf[i] = uint32_t(t);
        }
    }

    bool poolPassPath(const Scene& scene, uint32_t seed, uint64_t sample, uint32_t n, std::vector<Rgb>& passL,
                      std::vector<TileOutput>& tiles, const std::atomic<bool>* cancel);
    bool poolPassBidirectional(const Scene& scene, uint32_t seed, uint64_t sample, uint32_t n, std::vector<Rgb>& passL,
                               std::vector<TileOutput>& tiles, const std::atomic<bool>* cancel);
    void flushPtShadow(const Scene& scene, int bounce, bool early);
    void flushConnectionShadow(const Scene& scene, bool early);
};

void WavefrontScheduler::Impl::flushPtShadow(const Scene& scene, int bounce, bool early) {
    const uint32_t n = ptShadow.size();
    if (n == 0) return;
    countRay("nee_shadow", bounce + 1, n);  // next-event estimation at vertex `bounce` makes a path of depth bounce + 1
    launch("shadow", bounce, n, ptShadow.capacity(), early, double(sizeof(PtShadowEntry) + sizeof(Rgb)), [&](uint32_t j) {
        const PtShadowEntry& e = ptShadow[j];
        ptAddShadowResult(ptStates[e.path], e.record, traceShadowRay(scene, e.record.ray), ptDepthOf(e.path));
    });
    ptShadow.clear();
}

bool WavefrontScheduler::Impl::poolPassPath(const Scene& scene, uint32_t seed, uint64_t sample, uint32_t n,
                                            std::vector<Rgb>& passL, std::vector<TileOutput>& tiles,
                                            const std::atomic<bool>* cancel) {
    rays.clear();
    launch("generate_camera", -1, n, rays.capacity(), false, double(sizeof(PtPathState) + 4), [&](uint32_t i) {
        ptStates[i] = ptBegin(scene, xOf[i], yOf[i], PixelSampler(seed, pixelOf[i], sample));
        if (Rgb* d = ptDepthOf(i)) std::fill(d, d + settings.maxDepth + 1, Rgb(0.f));
        steps[i] = 0;
        rays.push(i);
    });
    for (int bounce = 0; !rays.empty(); ++bounce) {
        if (cancel && cancel->load(std::memory_order_relaxed)) return false;
        const uint32_t m = rays.size();
        countRay("camera", bounce, m);
        launch("extend", bounce, m, rays.capacity(), false, double(4 + sizeof(Ray) + sizeof(HitRecord)), [&](uint32_t j) {
            const uint32_t i = rays[j];
            hits[i].found = scene.intersect(ptStates[i].ray, &hits[i].hit);
            ++steps[i];
        });
        // Shade in chunks that fit the shadow queue: when it is full it is flushed (traced) first.
        nextRays.clear();
        for (uint32_t c0 = 0; c0 < m;) {
            if (ptShadow.free() < std::min(m - c0, ptShadow.capacity())) flushPtShadow(scene, bounce, true);
            const uint32_t c = std::min(m - c0, ptShadow.free());
            launch("shade", bounce, c, rays.capacity(), false,
                   double(4 + sizeof(HitRecord) + 2 * sizeof(PtPathState) + 4), [&](uint32_t j) {
                       const uint32_t i = rays[c0 + j];
                       PtShadowRecord nee;
                       const PixelSampler sampler(seed, pixelOf[i], sample);
                       if (ptShade(scene, sampler, settings, ptStates[i], hits[i].found ? &hits[i].hit : nullptr, &nee,
                                   nullptr, ptDepthOf(i)))
                           ptShadow.push(PtShadowEntry{i, nee});
                       if (ptStates[i].active) nextRays.push(i);
                   });
            c0 += c;
        }
        // The regular shadow launch: before the next shade, so a path adds its next-event
        // estimate before the emission it finds at the next vertex (the megakernel's order).
        flushPtShadow(scene, bounce, false);
        rays.swap(nextRays);
    }
    launch("accumulate", -1, n, 0, false, double(2 * sizeof(Rgb)), [&](uint32_t i) { passL[layout.local(xOf[i], yOf[i])] = ptStates[i].L; });
    // Per-depth records appended to their tile in canonical order (the megakernel's).
    if (settings.recordDepths)
        for (uint32_t i = 0; i < n; ++i)
            ptForEachDepth(ptDepthOf(i), settings.maxDepth,
                           [&](const DepthContribution& c) { tiles[tileOf[i]].depths.emplace_back(pixelOf[i], c); });
    addMegakernelWarps(n, {&steps}, 1, {0});
    report.bytesPerPathPeak = fixedBytesPerPath();
    report.bytesPerPathUsedSum += double(n) * double(fixedBytesPerPath());
    return true;
}

void WavefrontScheduler::Impl::flushConnectionShadow(const Scene& scene, bool early) {
    const uint32_t n = shadow.size();
    if (n == 0) return;
    launch("shadow", -1, n, shadow.capacity(), early, double(4 + sizeof(ShadowRay) + 1 + 4), [&](uint32_t k) {
        const uint32_t j = shadow[k];
        if (traceShadowRay(scene, pending[j].shadow)) {
            status[j] = kContributes;
            finish.push(j);
        } else {
            status[j] = kOccluded;
        }
    });
    shadow.clear();
}

bool WavefrontScheduler::Impl::poolPassBidirectional(const Scene& scene, uint32_t seed, uint64_t sample, uint32_t n,
                                                     std::vector<Rgb>& passL, std::vector<TileOutput>& tiles,
                                                     const std::atomic<bool>* cancel) {
    const bool lightOnly = kind == Kind::Light;
    auto cameraPath = [&](uint32_t i) { return &cameraVertices[size_t(i) * size_t(maxCam)]; };
    auto lightPath = [&](uint32_t i) { return &lightVertices[size_t(i) * size_t(maxLight)]; };
    auto pathOf = [&](uint32_t w) { return (w & 1u) ? lightPath(w >> 1) : cameraPath(w >> 1); };
    auto cameraBsdf = [&](uint32_t i) { return &cameraBsdfs[size_t(i) * size_t(maxCam)]; };
    auto lightBsdf = [&](uint32_t i) { return &lightBsdfs[size_t(i) * size_t(maxLight)]; };
    auto bsdfsOf = [&](uint32_t w) { return (w & 1u) ? lightBsdf(w >> 1) : cameraBsdf(w >> 1); };
    auto subpathBsdfs = [&](uint32_t i) { return SubpathBsdfs{lightBsdf(i), cameraBsdf(i)}; };
    rays.clear();
    // Generate: the endpoints and first rays of both subpaths.
    launch("generate_camera", -1, n, rays.capacity(), false, double(sizeof(PathVertex) + sizeof(SubpathWalk) + 4),
           [&](uint32_t i) {
               walks[2 * i] = SubpathWalk{};
               steps[3 * i] = steps[3 * i + 1] = steps[3 * i + 2] = 0;
               pathL[i] = Rgb(0.f);
               if (lightOnly) return;
               const PixelSampler sampler(seed, pixelOf[i], sample);
               const Vec2 raster = Vec2(float(xOf[i]), float(yOf[i])) + sampler.get2D(RngStream::Camera, dim::kFilm);
               beginCameraSubpath(scene, raster, bdpt, cameraPath(i), &walks[2 * i]);
               if (walks[2 * i].active) rays.push(2 * i);
           });
    launch("generate_light", -1, n, rays.capacity(), false, double(sizeof(PathVertex) + sizeof(SubpathWalk) + 4),
           [&](uint32_t i) {
               beginLightSubpath(scene, PixelSampler(seed, pixelOf[i], sample), bdpt, lightPath(i), &walks[2 * i + 1]);
               if (walks[2 * i + 1].active) rays.push(2 * i + 1);
           });
    // Extend and shade both subpaths together, one bounce per iteration.
    for (int bounce = 0; !rays.empty(); ++bounce) {
        if (cancel && cancel->load(std::memory_order_relaxed)) return false;
        const uint32_t m = rays.size();
        uint64_t lightRays = 0;
        for (uint32_t j = 0; j < m; ++j) lightRays += rays[j] & 1u;
        if (m - lightRays) countRay("camera", bounce, m - lightRays);
        if (lightRays) countRay("light", bounce, lightRays);
        launch("extend", bounce, m, rays.capacity(), false, double(4 + sizeof(Ray) + sizeof(HitRecord)), [&](uint32_t j) {
            const uint32_t w = rays[j];
            hits[w].found = scene.intersect(walks[w].ray, &hits[w].hit);
            ++steps[3 * (w >> 1) + (w & 1u)];
        });
        nextRays.clear();  // holds at most one entry per walk: it cannot overflow
        launch("shade", bounce, m, nextRays.capacity(), false,
               double(4 + sizeof(HitRecord) + 2 * sizeof(SubpathWalk) + sizeof(PathVertex) + 4), [&](uint32_t j) {
                   const uint32_t w = rays[j];
                   SubpathWalk& walk = walks[w];
                   PathVertex* path = pathOf(w);
                   Bsdf* bsdfs = bsdfsOf(w);
                   if (walkAddVertex(scene, hits[w].found ? &hits[w].hit : nullptr, &walk, path, bsdfs) &&
                       walkScatter(scene, PixelSampler(seed, pixelOf[w >> 1], sample), &walk, path, bsdfs))
                       nextRays.push(w);
               });
        rays.swap(nextRays);
    }
    // Densities of the finished subpaths; the connection count of each path.
    auto forEachStrategy = [&](uint32_t i, auto&& f) {
        const int nCamera = walks[2 * i].vertices, nLight = walks[2 * i + 1].vertices;
        const int tEnd = lightOnly ? 1 : nCamera;  // the megakernel's loop bounds (bdpt_integrator.cpp)
        for (int t = 1; t <= tEnd; ++t)
            for (int s = lightOnly ? 1 : 0; s <= lastLightStrategy(nLight, t); ++s) {
                if (strategyStatus(s, t, bdpt.maxDepth, lightOnly) == StrategyStatus::Evaluated) f(s, t);
            }
    };
    launch("densities", -1, n, 0, false, double(2 * sizeof(PathVertex) * size_t(maxCam + maxLight) / 4), [&](uint32_t i) {
        // Light tracing is unweighted: its densities go unread, except by an observer (the trace
        // records them like the megakernel's trace does).
        if (!lightOnly || options.observer) {
            fillSubpathDensities(scene, cameraPath(i), walks[2 * i].vertices, bdpt.mis, cameraBsdf(i));
            fillSubpathDensities(scene, lightPath(i), walks[2 * i + 1].vertices, bdpt.mis, lightBsdf(i));
        }
        uint32_t count = 0;
        forEachStrategy(i, [&](int, int) { ++count; });
        steps[3 * i + 2] = count;
    });
    if (options.observer)
        for (uint32_t i = 0; i < n; ++i)
            options.observer->subpaths(pixelOf[i], cameraPath(i), walks[2 * i].vertices, lightPath(i), walks[2 * i + 1].vertices);
    // Exclusive prefix sum of the counts (a scan kernel on a GPU): connection slot ranges.
    connectionOffset[0] = 0;
    for (uint32_t i = 0; i < n; ++i) connectionOffset[i + 1] = connectionOffset[i] + steps[3 * i + 2];
    const uint64_t total = connectionOffset[n];

    // Connections in chunks of the connection queue's capacity: a full queue is flushed through
    // connect -> shadow -> finish -> accumulate before the expansion goes on.
    for (uint64_t c0 = 0; c0 < total; c0 += connectionCapacity) {
        if (cancel && cancel->load(std::memory_order_relaxed)) return false;
        const uint32_t cnt = uint32_t(std::min<uint64_t>(connectionCapacity, total - c0));
        const bool early = c0 + cnt < total;
        const uint32_t p0 = uint32_t(std::upper_bound(connectionOffset.begin(), connectionOffset.begin() + n + 1, c0) -
                                     connectionOffset.begin()) - 1;
        const uint32_t p1 = uint32_t(std::lower_bound(connectionOffset.begin(), connectionOffset.begin() + n + 1, c0 + cnt) -
                                     connectionOffset.begin());
        launch("expand", -1, p1 - p0, 0, false, double(sizeof(ConnectionRecord) * cnt) / double(p1 - p0), [&](uint32_t k) {
            const uint32_t i = p0 + k;
            uint64_t slot = connectionOffset[i];
            forEachStrategy(i, [&](int s, int t) {
                if (slot >= c0 && slot < c0 + cnt) connections[size_t(slot - c0)] = ConnectionRecord{i, s, t};
                ++slot;
            });
        });
        // Connect, in sub-launches that fit the shadow queue (flushed early when it is full).
        shadow.clear();
        finish.clear();
        for (uint32_t j0 = 0; j0 < cnt;) {
            if (shadow.free() < std::min(cnt - j0, shadow.capacity())) flushConnectionShadow(scene, true);
            const uint32_t c = std::min(cnt - j0, shadow.free());
            launch("connect", -1, c, connectionCapacity, early && j0 == 0,
                   double(sizeof(ConnectionRecord) + 2 * sizeof(PathVertex) + sizeof(PendingConnection) + 1 + 4),
                   [&](uint32_t k) {
                       const uint32_t j = j0 + k;
                       const ConnectionRecord& r = connections[j];
                       status[j] = kNoContribution;
                       if (!evaluateConnection(scene, lightPath(r.path), r.s, cameraPath(r.path), r.t,
                                               PixelSampler(seed, pixelOf[r.path], sample), &pending[j], subpathBsdfs(r.path)))
                           return;
                       if (pending[j].needsShadowRay) {
                           status[j] = kAwaitingShadow;
                           shadow.push(j);
                       } else {
                           status[j] = kContributes;
                           finish.push(j);
                       }
                   });
            j0 += c;
        }
        flushConnectionShadow(scene, false);
        // Finish: the MIS weight of every unoccluded connection (light tracing is unweighted).
        launch("finish", -1, finish.size(), finish.capacity(), false,
               double(4 + sizeof(PendingConnection) + 4 * sizeof(PathVertex) + sizeof(Connection)), [&](uint32_t k) {
                   const uint32_t j = finish[k];
                   const ConnectionRecord& r = connections[j];
                   if (lightOnly) {
                       results[j] = Connection{pending[j].unweighted, 1.0, pending[j].splat, pending[j].raster};
                   } else {
                       finishConnection(scene, lightPath(r.path), r.s, cameraPath(r.path), r.t, pending[j], bdpt, &results[j],
                                        subpathBsdfs(r.path));
                   }
               });
        // Accumulate in slot order = the megakernel's (path, t, s) order: camera estimates per
        // path, splats and strategy records appended to their tile in canonical order.
        StageStats& acc = stage("accumulate", -1);
        ++acc.launches;
        acc.items += cnt;
        acc.maxAtLaunch = std::max<uint64_t>(acc.maxAtLaunch, cnt);
        report.trafficBytes += double(cnt) * double(sizeof(ConnectionRecord) + 1);
        // Counters in dense per-(s, t) and per-depth arrays, merged into the report's maps after
        // the loop (a map lookup per connection was a measurable part of the wavefront's cost).
        const size_t tStride = size_t(maxCam) + 1;
        chunkCounts.assign((size_t(maxLight) + 1) * tStride, StrategyCounts{});
        chunkShadowByDepth.assign(size_t(bdpt.maxDepth) + 1, 0);
        for (uint32_t j = 0; j < cnt; ++j) {
            const ConnectionRecord& r = connections[j];
            StrategyCounts& sc = chunkCounts[size_t(r.s) * tStride + size_t(r.t)];
            ++sc.evaluated;
            if (options.observer)
                options.observer->connection(WavefrontConnectionEntry{c0 + j, pixelOf[r.path], r.s, r.t, status[j] != kNoContribution,
                                                                      status[j] == kContributes, &pending[j], &results[j]});
            if (status[j] == kNoContribution) continue;
            const bool shadowRay = pending[j].needsShadowRay;
            if (shadowRay) {
                ++sc.shadowRays;
                ++chunkShadowByDepth[size_t(r.s + r.t - 2)];
            }
            if (status[j] != kContributes) continue;
            ++sc.contributed;
            report.trafficBytes += double(sizeof(Connection) + sizeof(Rgb));
            const Connection& c = results[j];
            const double w = lightOnly ? 1.0 : c.weight;
            const Rgb weighted = c.unweighted * float(w);
            TileOutput& to = tiles[tileOf[r.path]];
            if (c.splat) to.splats.push_back(Splat{c.raster, weighted});
            else pathL[r.path] += weighted;
            if (settings.recordStrategies)
                to.strategies.emplace_back(pixelOf[r.path], StrategyContribution{r.s, r.t, weighted, c.unweighted, c.splat, c.raster});
            if (settings.recordDepths)
                to.depths.emplace_back(pixelOf[r.path], DepthContribution{r.s + r.t - 2, weighted, c.splat, c.raster});
        }
        for (size_t k = 0; k < chunkCounts.size(); ++k) {
            const StrategyCounts& sc = chunkCounts[k];
            if (sc.evaluated == 0) continue;
            StrategyCounts& sum = report.connections[{int(k / tStride), int(k % tStride)}];
            sum.evaluated += sc.evaluated;
            sum.shadowRays += sc.shadowRays;
            sum.contributed += sc.contributed;
        }
        for (size_t d = 0; d < chunkShadowByDepth.size(); ++d)
            if (chunkShadowByDepth[d]) countRay("connection_shadow", int(d), chunkShadowByDepth[d]);
    }
    for (uint32_t i = 0; i < n; ++i) {
        passL[layout.local(xOf[i], yOf[i])] = pathL[i];
        const uint64_t used = fixedBytesPerPath() + uint64_t(walks[2 * i].vertices + walks[2 * i + 1].vertices) *
                                                        (sizeof(PathVertex) + sizeof(Bsdf));
        report.bytesPerPathPeak = std::max(report.bytesPerPathPeak, used);
        report.bytesPerPathUsedSum += double(used);
    }
    addMegakernelWarps(n, {&steps, &steps, &steps}, 3, {0, 1, 2});
    return true;
}

WavefrontScheduler::WavefrontScheduler(const std::string& integrator, const IntegratorSettings& settings,
                                       const WavefrontOptions& options)
    : impl_(std::make_unique<Impl>()) {
    Impl& m = *impl_;
    if (settings.maxDepth < 0) throw InputError("--max-depth must be >= 0");
    if (options.poolSize < 0) throw InputError("--wavefront-pool must be >= 0 (0 = automatic)");
    if (options.shadowQueueCapacity < 0 || options.connectionQueueCapacity < 0)
        throw InputError("wavefront queue capacities must be >= 0 (0 = automatic)");
    m.kind = parseKind(integrator);
    m.settings = settings;
    m.bdpt.maxDepth = settings.maxDepth;
    m.bdpt.rouletteStartDepth = settings.rouletteStartDepth;
    m.bdpt.mis = settings.mis;
    m.options = options;
    m.maxCam = m.kind == Kind::Path ? 0 : m.bdpt.maxCameraVertices();
    m.maxLight = m.kind == Kind::Path ? 0 : m.bdpt.maxLightVertices();
    // Automatic pool: as many paths as fit in 512 KiB of per-path buffers, 256..65536, whole
    // warps. A CPU runs a stage over the pool out of its caches: with BDPT's vertex and BSDF
    // buffers, a pool that outgrows the L2 made the wavefront 1.3x slower than the megakernel
    // (docs/wavefront.md, "Pool size").
    const uint64_t perPath = m.staticBytesPerPath();
    uint64_t pool = options.poolSize > 0 ? uint64_t(options.poolSize)
                                         : std::clamp<uint64_t>((uint64_t(512) << 10) / perPath, 256, 65536) / kWarpSize * kWarpSize;
    m.pool = uint32_t(std::min<uint64_t>(pool, uint64_t(1) << 24));
    m.shadowCapacity = options.shadowQueueCapacity > 0 ? uint32_t(options.shadowQueueCapacity) : m.pool;
    m.connectionCapacity = options.connectionQueueCapacity > 0 ? uint32_t(options.connectionQueueCapacity) : 4 * m.pool;
    GpuReport& r = m.report;
    r.integrator = m.kind == Kind::Path ? "path" : m.kind == Kind::Light ? "lt" : "bdpt";
    r.maxDepth = settings.maxDepth;
    r.poolSize = int(m.pool);
    r.shadowQueueCapacity = int(m.shadowCapacity);
    r.connectionQueueCapacity = m.kind == Kind::Path ? 0 : int(m.connectionCapacity);
    r.bytesPerPathStatic = perPath;
    r.bytesPerConnection = m.kind == Kind::Path ? 0
                                                 : sizeof(ConnectionRecord) + sizeof(PendingConnection) + 1 + sizeof(Connection) + 4;
    r.bytesPerShadowEntry = m.kind == Kind::Path ? sizeof(PtShadowEntry) : 4;
    r.rayQueuesPerPath = m.kind == Kind::Path ? 2 : 4;
}

WavefrontScheduler::~WavefrontScheduler() = default;

const GpuReport& WavefrontScheduler::report() const { return impl_->report; }

bool WavefrontScheduler::renderPass(const Scene& scene, const Integrator& /*integrator*/, const PassLayout& layout,
                                    uint32_t seed, uint64_t sample, std::vector<Rgb>& passL, std::vector<TileOutput>& tiles,
                                    const std::atomic<bool>* cancel) {
    Impl& m = *impl_;
    FlushDenormalsScope fpMode;
    m.layout = layout;
    m.tileStart.assign(size_t(layout.tileCount()), 0);
    int total = 0;
    for (int t = 0; t < layout.tileCount(); ++t) {
        m.tileStart[size_t(t)] = total;
        total += layout.tilePixels(t);
    }
    for (TileOutput& to : tiles) to.clear();
    m.allocate(uint32_t(total));
    const uint32_t pool = uint32_t(m.pixelOf.size());
    for (uint64_t k0 = 0; k0 < uint64_t(total); k0 += pool) {
        if (cancel && cancel->load(std::memory_order_relaxed)) return false;
        const uint32_t n = uint32_t(std::min<uint64_t>(pool, uint64_t(total) - k0));
        m.mapSamples(layout, k0, n);
        const bool done = m.kind == Kind::Path ? m.poolPassPath(scene, seed, sample, n, passL, tiles, cancel)
                                               : m.poolPassBidirectional(scene, seed, sample, n, passL, tiles, cancel);
        if (!done) return false;
        ++m.report.poolPasses;
        m.report.pathSamples += n;
    }
    return true;
}

}  // namespace bdptref
