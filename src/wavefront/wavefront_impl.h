// The wavefront scheduler's state (WavefrontScheduler::Impl): configuration, pool buffers,
// queues, the stage launch helpers and the report being filled. wavefront_scheduler.cpp
// distributes pool passes (renderPass), wavefront_pool_pass.cpp runs one (docs/wavefront.md).
#pragma once

#include "bdptref/bdpt.h"
#include "bdptref/renderer.h"
#include "bdptref/scene.h"
#include "bdptref/wavefront.h"
#include "render/path_tracer.h"
#include "scene/accel.h"  // setFlushDenormals
#include "wavefront/work_queue.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <memory>
#include <tuple>
#include <vector>

namespace bdptref {

namespace wavefront_detail {

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

inline uint64_t roundUpToWarp(uint64_t n) { return (n + kWarpSize - 1) / kWarpSize * kWarpSize; }

// What every stage of one pool pass reads: the scene, the sample's RNG key and the pool's fill.
struct PoolPassContext {
    const Scene& scene;
    uint32_t seed = 0;
    uint64_t sample = 0;
    uint32_t n = 0;  // paths in this pool pass (pool slots [0, n))
};

// One fill of the connection queue: slots [c0, c0 + count) of the pool pass, which belong to the
// paths [p0, p1).
struct ConnectionChunk {
    uint64_t c0 = 0;
    uint32_t count = 0;
    bool early = false;  // more connections follow: this chunk's connect launch is a flush
    uint32_t p0 = 0, p1 = 0;
};

}  // namespace wavefront_detail

using namespace wavefront_detail;

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
    std::vector<PtDepthSums> ptDepthL;                      // PT with depth or strategy layers: maxDepth + 1 per path
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

    // With more than one thread, whole pool passes run side by side, each on one thread with its
    // own buffers (a worker: a copy of this configuration whose stage launches are serial loops).
    // A stage launch spread over threads ends in a barrier; on a shared machine each barrier
    // waited for a descheduled thread, and the threads' caches traded each path's state between
    // stages: 2 threads took 2.6x the CPU time of the megakernel. Pool passes are independent
    // (other samples), so a GPU's view of one pool pass is unchanged (docs/wavefront.md).
    bool serial = false;
    std::vector<std::unique_ptr<Impl>> workers;
    std::unique_ptr<Impl> makeWorker() const {
        auto w = std::make_unique<Impl>();
        w->kind = kind;
        w->settings = settings;
        w->bdpt = bdpt;
        w->options = options;
        w->options.observer = nullptr;  // observed renders stay on the calling thread (renderPass)
        w->maxCam = maxCam;
        w->maxLight = maxLight;
        w->pool = pool;
        w->shadowCapacity = shadowCapacity;
        w->connectionCapacity = connectionCapacity;
        w->serial = true;
        return w;
    }

    // PT with --depth-layers or --strategies: the per-depth sums of each path (bytes).
    bool ptRecordsDepthSums() const { return settings.recordDepths || settings.recordStrategies; }
    uint64_t ptDepthBytesPerPath() const {
        return ptRecordsDepthSums() ? (uint64_t(settings.maxDepth) + 1) * sizeof(PtDepthSums) : 0;
    }
    PtDepthSums* ptDepthOf(uint32_t i) {
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

    // One launch of a stage over n queue entries: statistics, then the parallel pass, in chunks
    // (body.chunk(begin, end)); launch() and launchAppending() below give the per-entry forms.
    template <class Chunks>
    void launchChunks(const char* name, int bounce, uint32_t n, uint64_t capacity, bool early, double bytesPerItem, Chunks& body) {
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
        if (serial) {
            body.chunk(0, n);
            return;
        }
        tbb::parallel_for(tbb::blocked_range<uint32_t>(0, n, 64), [&](const tbb::blocked_range<uint32_t>& r) {
            setFlushDenormals();
            body.chunk(r.begin(), r.end());
        });
    }
    template <class Body>
    struct PerItem {
        Body& body;
        void chunk(uint32_t begin, uint32_t end) {
            for (uint32_t i = begin; i != end; ++i) body(i);
        }
    };
    // The same for a stage that appends to queues: body(i, appender...), one ChunkAppender per queue
    // and chunk of the parallel pass (work_queue.h: one fetch_add per block of appends).
    template <class Body, class... T>
    struct PerItemAppending {
        Body& body;
        std::tuple<WorkQueue<T>&...> queues;
        void chunk(uint32_t begin, uint32_t end) {
            std::apply(
                [&](WorkQueue<T>&... q) {
                    std::tuple<ChunkAppender<T>...> out{ChunkAppender<T>(q)...};
                    std::apply(
                        [&](ChunkAppender<T>&... a) {
                            for (uint32_t i = begin; i != end; ++i) body(i, a...);
                            (a.flush(), ...);
                        },
                        out);
                },
                queues);
        }
    };
    template <class Body>
    void launch(const char* name, int bounce, uint32_t n, uint64_t capacity, bool early, double bytesPerItem, Body&& body) {
        PerItem<Body> items{body};
        launchChunks(name, bounce, n, capacity, early, bytesPerItem, items);
    }
    template <class Body, class... T>
    void launchAppending(const char* name, int bounce, uint32_t n, uint64_t capacity, bool early, double bytesPerItem,
                         Body&& body, WorkQueue<T>&... queues) {
        PerItemAppending<Body, T...> items{body, std::tuple<WorkQueue<T>&...>(queues...)};
        launchChunks(name, bounce, n, capacity, early, bytesPerItem, items);
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
            ptDepthL.assign(ptRecordsDepthSums() ? size_t(want) * (size_t(settings.maxDepth) + 1) : 0, PtDepthSums{});
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

    // Pool pass `k0 / pool` of the pass: samples [k0, k0 + n) into passL and `tiles`, its figures
    // into a fresh `report` (returned in *counters): the caller adds them up in pass order, so
    // the sums (doubles among them) do not depend on which thread ran which pass.
    bool runPoolPass(const Scene& scene, uint32_t seed, uint64_t sample, uint64_t k0, uint32_t n, std::vector<Rgb>& passL,
                     std::vector<TileOutput>& tiles, const std::atomic<bool>* cancel, GpuReport* counters) {
        GpuReport kept = std::move(report);
        report = GpuReport{};
        mapSamples(layout, k0, n);
        const bool done = kind == Kind::Path ? poolPassPath(scene, seed, sample, n, passL, tiles, cancel)
                                             : poolPassBidirectional(scene, seed, sample, n, passL, tiles, cancel);
        ++report.poolPasses;
        report.pathSamples += n;
        *counters = std::move(report);
        report = std::move(kept);
        return done;
    }

    bool poolPassPath(const Scene& scene, uint32_t seed, uint64_t sample, uint32_t n, std::vector<Rgb>& passL,
                      std::vector<TileOutput>& tiles, const std::atomic<bool>* cancel);
    bool poolPassBidirectional(const Scene& scene, uint32_t seed, uint64_t sample, uint32_t n, std::vector<Rgb>& passL,
                               std::vector<TileOutput>& tiles, const std::atomic<bool>* cancel);
    void flushPtShadow(const Scene& scene, int bounce, bool early);
    void flushConnectionShadow(const Scene& scene, bool early);

    // The bidirectional pool pass (BDPT and light tracing), one function per stage in the order
    // poolPassBidirectional runs them (docs/wavefront.md, "Stage graph").
    void generateSubpaths(const PoolPassContext& pass);
    void extendWalks(const PoolPassContext& pass, int bounce);
    void shadeWalks(const PoolPassContext& pass, int bounce);
    void fillDensities(const PoolPassContext& pass);
    void observeSubpaths(uint32_t n);
    uint64_t scanConnectionCounts(uint32_t n);
    ConnectionChunk connectionChunk(uint64_t c0, uint64_t total, uint32_t n) const;
    void expandConnections(const ConnectionChunk& chunk);
    void evaluateConnections(const PoolPassContext& pass, const ConnectionChunk& chunk);
    void finishConnections(const PoolPassContext& pass);
    void accumulateConnections(const ConnectionChunk& chunk, std::vector<TileOutput>& tiles);
    void mergeConnectionCounters();
    void storeSubpathEstimates(uint32_t n, std::vector<Rgb>& passL);

    // Light tracing: no camera walk, t = 1 only, unweighted.
    bool lightOnly() const { return kind == Kind::Light; }
    // The pool's per-path vertex and BSDF buffers; a walk index w is 2 * path + {0 camera, 1 light}.
    PathVertex* cameraPath(uint32_t i) { return &cameraVertices[size_t(i) * size_t(maxCam)]; }
    PathVertex* lightPath(uint32_t i) { return &lightVertices[size_t(i) * size_t(maxLight)]; }
    PathVertex* walkPath(uint32_t w) { return (w & 1u) ? lightPath(w >> 1) : cameraPath(w >> 1); }
    Bsdf* cameraBsdf(uint32_t i) { return &cameraBsdfs[size_t(i) * size_t(maxCam)]; }
    Bsdf* lightBsdf(uint32_t i) { return &lightBsdfs[size_t(i) * size_t(maxLight)]; }
    Bsdf* walkBsdfs(uint32_t w) { return (w & 1u) ? lightBsdf(w >> 1) : cameraBsdf(w >> 1); }
    SubpathBsdfs subpathBsdfs(uint32_t i) { return SubpathBsdfs{lightBsdf(i), cameraBsdf(i)}; }
    // f(s, t) for every strategy of path i that is evaluated, in the megakernel's loop order
    // (t, then s; bdpt_integrator.cpp): the connection slots of the path.
    template <class F>
    void forEachStrategy(uint32_t i, F&& f) const {
        const int nCamera = walks[2 * i].vertices, nLight = walks[2 * i + 1].vertices;
        const int tEnd = lightOnly() ? 1 : nCamera;  // the megakernel's loop bounds (bdpt_integrator.cpp)
        for (int t = 1; t <= tEnd; ++t)
            for (int s = lightOnly() ? 1 : 0; s <= lastLightStrategy(nLight, t); ++s) {
                if (strategyStatus(s, t, bdpt.maxDepth, lightOnly()) == StrategyStatus::Evaluated) f(s, t);
            }
    }
};

}  // namespace bdptref
