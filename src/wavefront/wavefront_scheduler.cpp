// The wavefront schedule of one pass (docs/wavefront.md). Samples of the pass are taken in the
// canonical order (tiles, then pixels row by row in a tile) and processed in pool passes of at
// most `pool` paths: with several threads, whole pool passes side by side (one per thread, its
// stages plain loops), else one pool pass at a time with every stage a tbb::parallel_for over the
// entries of its input queue (wavefront_pool_pass.cpp).
#include "bdptref/wavefront.h"

#include "bdptref/errors.h"
#include "wavefront/wavefront_impl.h"

#include <tbb/global_control.h>
#include <tbb/task_arena.h>
#include <xmmintrin.h>

#include <algorithm>
#include <atomic>

namespace bdptref {

namespace {

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

}  // namespace

WavefrontScheduler::WavefrontScheduler(const std::string& integrator, const IntegratorSettings& settings,
                                       const WavefrontOptions& options)
    : impl_(std::make_unique<Impl>()) {
    Impl& m = *impl_;
    if (settings.maxDepth < 0) throw InputError("--max-depth must be >= 0");
    if (options.poolSize < 0) throw InputError("--wavefront-pool must be >= 0 (0 = automatic)");
    if (options.shadowQueueCapacity < 0 || options.connectionQueueCapacity < 0)
        throw InputError("wavefront queue capacities must be >= 0 (0 = automatic)");
    m.kind = parseKind(integrator);
    checkLightSamplerSupported(integrator, settings);
    m.settings = settings;
    m.bdpt.maxDepth = settings.maxDepth;
    m.bdpt.rouletteStartDepth = settings.rouletteStartDepth;
    m.bdpt.mis = settings.mis;
    m.bdpt.mis.lightSampler = settings.lightSampler;  // as the megakernel's toBdptSettings
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

namespace {

// Adds the figures of one pool pass (GpuReport counters only) to the report.
void addCounters(GpuReport& into, const GpuReport& d) {
    into.pathSamples += d.pathSamples;
    into.poolPasses += d.poolPasses;
    for (const auto& [key, st] : d.stages) {
        StageStats& t = into.stages[key];
        t.launches += st.launches;
        t.items += st.items;
        t.maxAtLaunch = std::max(t.maxAtLaunch, st.maxAtLaunch);
        t.capacity = st.capacity;
        t.flushes += st.flushes;
    }
    for (const auto& [type, rays] : d.raysByDepth) {
        std::vector<uint64_t>& t = into.raysByDepth[type];
        if (t.size() < rays.size()) t.resize(rays.size(), 0);
        for (size_t i = 0; i < rays.size(); ++i) t[i] += rays[i];
    }
    for (const auto& [key, c] : d.connections) {
        StrategyCounts& t = into.connections[key];
        t.evaluated += c.evaluated;
        t.shadowRays += c.shadowRays;
        t.contributed += c.contributed;
    }
    into.megakernelActiveLanes += d.megakernelActiveLanes;
    into.megakernelIssuedLanes += d.megakernelIssuedLanes;
    into.wavefrontActiveLanes += d.wavefrontActiveLanes;
    into.wavefrontIssuedLanes += d.wavefrontIssuedLanes;
    into.bytesPerPathPeak = std::max(into.bytesPerPathPeak, d.bytesPerPathPeak);
    into.bytesPerPathUsedSum += d.bytesPerPathUsedSum;
    into.trafficBytes += d.trafficBytes;
}

template <class T>
void appendTo(std::vector<T>& into, const std::vector<T>& more) {
    into.insert(into.end(), more.begin(), more.end());
}

}  // namespace

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
    if (total == 0) return true;
    const uint64_t poolPaths = std::max<uint64_t>(1, std::min<uint64_t>(m.pool, uint64_t(total)));
    const uint64_t passes = (uint64_t(total) + poolPaths - 1) / poolPaths;
    const size_t threads = tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism);

    if (m.options.observer || threads <= 1 || passes <= 1) {
        // On the calling thread, each stage launch spread over the threads.
        m.allocate(uint32_t(total));
        for (uint64_t p = 0; p < passes; ++p) {
            if (cancel && cancel->load(std::memory_order_relaxed)) return false;
            const uint64_t k0 = p * poolPaths;
            const uint32_t n = uint32_t(std::min<uint64_t>(poolPaths, uint64_t(total) - k0));
            GpuReport counters;
            const bool done = m.runPoolPass(scene, seed, sample, k0, n, passL, tiles, cancel, &counters);
            addCounters(m.report, counters);
            if (!done) return false;
        }
        return true;
    }

    // Pool passes side by side, one per thread at a time (Impl::workers). Their tile outputs and
    // figures are kept per pass and added in pass order: the same film and report as one thread.
    const size_t slots = size_t(std::max(1, tbb::this_task_arena::max_concurrency()));
    while (m.workers.size() < slots) m.workers.push_back(m.makeWorker());
    for (auto& w : m.workers) {
        w->layout = layout;
        w->tileStart = m.tileStart;
    }
    std::vector<GpuReport> passCounters(passes);
    std::vector<std::vector<TileOutput>> passTiles(passes);
    std::atomic<bool> stopped{false};
    tbb::parallel_for(tbb::blocked_range<uint64_t>(0, passes, 1), [&](const tbb::blocked_range<uint64_t>& r) {
        setFlushDenormals();
        const int slot = tbb::this_task_arena::current_thread_index();
        Impl& w = *m.workers[size_t(slot >= 0 ? slot : 0) % m.workers.size()];
        for (uint64_t p = r.begin(); p != r.end(); ++p) {
            if (stopped.load(std::memory_order_relaxed) || (cancel && cancel->load(std::memory_order_relaxed))) {
                stopped = true;
                return;
            }
            w.allocate(uint32_t(poolPaths));
            const uint64_t k0 = p * poolPaths;
            const uint32_t n = uint32_t(std::min<uint64_t>(poolPaths, uint64_t(total) - k0));
            passTiles[p].resize(tiles.size());
            if (!w.runPoolPass(scene, seed, sample, k0, n, passL, passTiles[p], cancel, &passCounters[p])) stopped = true;
        }
    });
    if (stopped) return false;
    for (uint64_t p = 0; p < passes; ++p) {
        addCounters(m.report, passCounters[p]);
        for (size_t t = 0; t < tiles.size(); ++t) {
            appendTo(tiles[t].splats, passTiles[p][t].splats);
            appendTo(tiles[t].strategies, passTiles[p][t].strategies);
            appendTo(tiles[t].depths, passTiles[p][t].depths);
        }
    }
    return true;
}

}  // namespace bdptref
