// One pool pass of the wavefront schedule (docs/wavefront.md, "Stage graph"): the path tracer's
// and the bidirectional estimators' stages over the pool's queues. The light transport is done by
// the same functions the megakernel calls (bdpt.h, path_tracer.h). Nothing depends on the slot an
// entry got in a queue: results are written at the path's (or the connection's) own index, and
// the accumulation walks paths and connections in canonical order.
#include "wavefront/wavefront_impl.h"

#include <algorithm>
#include <tuple>
#include <utility>

namespace bdptref {

namespace {

bool cancelled(const std::atomic<bool>* cancel) { return cancel && cancel->load(std::memory_order_relaxed); }

// Rays handed to Embree's stream API at once: a launch's chunk (64 entries) at most.
constexpr uint32_t kStreamChunk = 64;

// An extend launch's chunk body: the closest hits of the chunk's rays, traced together through
// Embree's stream API (as a GPU traces a launch's rays). entry(j) gives queue entry j's ray and
// the HitRecord it fills.
template <class Entry>
struct StreamExtend {
    const Scene& scene;
    Entry entry;
    void chunk(uint32_t begin, uint32_t end) {
        const Ray* rays[kStreamChunk];
        HitRecord* records[kStreamChunk];
        SurfaceHit* hits[kStreamChunk];
        bool found[kStreamChunk];
        for (uint32_t j0 = begin; j0 < end; j0 += kStreamChunk) {
            const uint32_t m = std::min(end - j0, kStreamChunk);
            for (uint32_t k = 0; k < m; ++k) {
                std::tie(rays[k], records[k]) = entry(j0 + k);
                hits[k] = &records[k]->hit;
            }
            scene.intersectStream(rays, m, hits, found);
            for (uint32_t k = 0; k < m; ++k) records[k]->found = found[k];
        }
    }
};
template <class Entry>
StreamExtend<Entry> streamExtend(const Scene& scene, Entry entry) {
    return StreamExtend<Entry>{scene, entry};
}

}  // namespace

void WavefrontScheduler::Impl::flushPtShadow(const Scene& scene, int bounce, bool early) {
    const uint32_t n = ptShadow.size();
    if (n == 0) return;
    countRay("nee_shadow", bounce + 1, n);  // next-event estimation at vertex `bounce` makes a path of depth bounce + 1
    struct Chunks {  // a chunk's shadow rays go to Embree together
        Impl& impl;
        const Scene& scene;
        void chunk(uint32_t begin, uint32_t end) {
            const ShadowRay* chunkRays[kStreamChunk];
            bool unoccluded[kStreamChunk];
            for (uint32_t j0 = begin; j0 < end; j0 += kStreamChunk) {
                const uint32_t m = std::min(end - j0, kStreamChunk);
                for (uint32_t k = 0; k < m; ++k) chunkRays[k] = &impl.ptShadow[j0 + k].record.ray;
                traceShadowRays(scene, chunkRays, m, unoccluded);
                for (uint32_t k = 0; k < m; ++k) {
                    const PtShadowEntry& e = impl.ptShadow[j0 + k];
                    ptAddShadowResult(impl.ptStates[e.path], e.record, unoccluded[k], impl.ptDepthOf(e.path));
                }
            }
        }
    } body{*this, scene};
    launchChunks("shadow", bounce, n, ptShadow.capacity(), early, double(sizeof(PtShadowEntry) + sizeof(Rgb)), body);
    ptShadow.clear();
}

bool WavefrontScheduler::Impl::poolPassPath(const Scene& scene, uint32_t seed, uint64_t sample, uint32_t n,
                                            std::vector<Rgb>& passL, std::vector<TileOutput>& tiles,
                                            const std::atomic<bool>* cancel) {
    rays.clear();
    launchAppending(
        "generate_camera", -1, n, rays.capacity(), false, double(sizeof(PtPathState) + 4),
        [&](uint32_t i, ChunkAppender<uint32_t>& toRays) {
            ptStates[i] = ptBegin(scene, xOf[i], yOf[i], PixelSampler(seed, pixelOf[i], sample));
            if (PtDepthSums* d = ptDepthOf(i)) std::fill(d, d + settings.maxDepth + 1, PtDepthSums{});
            steps[i] = 0;
            toRays.push(i);
        },
        rays);
    for (int bounce = 0; !rays.empty(); ++bounce) {
        if (cancelled(cancel)) return false;
        const uint32_t m = rays.size();
        countRay("camera", bounce, m);
        auto body = streamExtend(scene, [&](uint32_t j) {
            const uint32_t i = rays[j];
            ++steps[i];
            return std::pair<const Ray*, HitRecord*>(&ptStates[i].ray, &hits[i]);
        });
        launchChunks("extend", bounce, m, rays.capacity(), false, double(4 + sizeof(Ray) + sizeof(HitRecord)), body);
        // Shade in chunks that fit the shadow queue: when it is full it is flushed (traced) first.
        nextRays.clear();
        for (uint32_t c0 = 0; c0 < m;) {
            if (ptShadow.free() < std::min(m - c0, ptShadow.capacity())) flushPtShadow(scene, bounce, true);
            const uint32_t c = std::min(m - c0, ptShadow.free());
            launchAppending(
                "shade", bounce, c, rays.capacity(), false, double(4 + sizeof(HitRecord) + 2 * sizeof(PtPathState) + 4),
                [&](uint32_t j, ChunkAppender<PtShadowEntry>& toShadow, ChunkAppender<uint32_t>& toNext) {
                    const uint32_t i = rays[c0 + j];
                    PtShadowRecord nee;
                    const PixelSampler sampler(seed, pixelOf[i], sample);
                    if (ptShade(scene, sampler, settings, ptStates[i], hits[i].found ? &hits[i].hit : nullptr, &nee, nullptr,
                                ptDepthOf(i)))
                        toShadow.push(PtShadowEntry{i, nee});
                    if (ptStates[i].active) toNext.push(i);
                },
                ptShadow, nextRays);
            c0 += c;
        }
        // The regular shadow launch: before the next shade, so a path adds its next-event
        // estimate before the emission it finds at the next vertex (the megakernel's order).
        flushPtShadow(scene, bounce, false);
        rays.swap(nextRays);
    }
    launch("accumulate", -1, n, 0, false, double(2 * sizeof(Rgb)), [&](uint32_t i) { passL[layout.local(xOf[i], yOf[i])] = ptStates[i].L; });
    // Per-depth and per-strategy records appended to their tile in canonical order (the megakernel's).
    if (settings.recordDepths)
        for (uint32_t i = 0; i < n; ++i)
            ptForEachDepth(ptDepthOf(i), settings.maxDepth,
                           [&](const DepthContribution& c) { tiles[tileOf[i]].depths.emplace_back(pixelOf[i], c); });
    if (settings.recordStrategies)
        for (uint32_t i = 0; i < n; ++i)
            ptForEachStrategy(ptDepthOf(i), settings.maxDepth,
                              [&](const StrategyContribution& c) { tiles[tileOf[i]].strategies.emplace_back(pixelOf[i], c); });
    addMegakernelWarps(n, {&steps}, 1, {0});
    report.bytesPerPathPeak = fixedBytesPerPath();
    report.bytesPerPathUsedSum += double(n) * double(fixedBytesPerPath());
    return true;
}

void WavefrontScheduler::Impl::flushConnectionShadow(const Scene& scene, bool early) {
    const uint32_t n = shadow.size();
    if (n == 0) return;
    struct Chunks {  // a chunk's shadow rays go to Embree together; the survivors to the finish queue
        Impl& impl;
        const Scene& scene;
        void chunk(uint32_t begin, uint32_t end) {
            ChunkAppender<uint32_t> toFinish(impl.finish);
            const ShadowRay* chunkRays[kStreamChunk];
            bool unoccluded[kStreamChunk];
            for (uint32_t k0 = begin; k0 < end; k0 += kStreamChunk) {
                const uint32_t m = std::min(end - k0, kStreamChunk);
                for (uint32_t k = 0; k < m; ++k) chunkRays[k] = &impl.pending[impl.shadow[k0 + k]].shadow;
                traceShadowRays(scene, chunkRays, m, unoccluded);
                for (uint32_t k = 0; k < m; ++k) {
                    const uint32_t j = impl.shadow[k0 + k];
                    impl.status[j] = unoccluded[k] ? kContributes : kOccluded;
                    if (unoccluded[k]) toFinish.push(j);
                }
            }
            toFinish.flush();
        }
    } body{*this, scene};
    launchChunks("shadow", -1, n, shadow.capacity(), early, double(4 + sizeof(ShadowRay) + 1 + 4), body);
    shadow.clear();
}

// BDPT and light tracing: the two walks of every path to their ends, then the connections
// of every path, a connection queue's fill at a time. Each step is one stage (a launch).
bool WavefrontScheduler::Impl::poolPassBidirectional(const Scene& scene, uint32_t seed, uint64_t sample, uint32_t n,
                                                     std::vector<Rgb>& passL, std::vector<TileOutput>& tiles,
                                                     const std::atomic<bool>* cancel) {
    const PoolPassContext pass{scene, seed, sample, n};
    generateSubpaths(pass);
    for (int bounce = 0; !rays.empty(); ++bounce) {
        if (cancelled(cancel)) return false;
        extendWalks(pass, bounce);
        shadeWalks(pass, bounce);
        rays.swap(nextRays);
    }
    fillDensities(pass);
    if (options.observer) observeSubpaths(n);
    const uint64_t total = scanConnectionCounts(n);
    // A full connection queue is flushed through connect -> shadow -> finish -> accumulate
    // before the expansion goes on.
    for (uint64_t c0 = 0; c0 < total; c0 += connectionCapacity) {
        if (cancelled(cancel)) return false;
        const ConnectionChunk chunk = connectionChunk(c0, total, n);
        expandConnections(chunk);
        evaluateConnections(pass, chunk);
        flushConnectionShadow(scene, false);
        finishConnections(pass);
        accumulateConnections(chunk, tiles);
        mergeConnectionCounters();
    }
    storeSubpathEstimates(n, passL);
    addMegakernelWarps(n, {&steps, &steps, &steps}, 3, {0, 1, 2});
    return true;
}

// Generate: the endpoints and first rays of both subpaths.
// One launch for both walks of a path: their rays enter the queue side by side, so the
// thread that extends and shades one walk also has the other, whose per-walk state (walks,
// hits, steps) shares its cache lines. Separate camera and light launches left the two halves
// of those lines to different threads.
void WavefrontScheduler::Impl::generateSubpaths(const PoolPassContext& pass) {
    rays.clear();
    launchAppending(
        "generate", -1, pass.n, rays.capacity(), false, double(2 * (sizeof(PathVertex) + sizeof(SubpathWalk) + 4)),
        [&](uint32_t i, ChunkAppender<uint32_t>& toRays) {
            walks[2 * i] = SubpathWalk{};
            steps[3 * i] = steps[3 * i + 1] = steps[3 * i + 2] = 0;
            pathL[i] = Rgb(0.f);
            const PixelSampler sampler(pass.seed, pixelOf[i], pass.sample);
            if (!lightOnly()) {
                const Vec2 raster = Vec2(float(xOf[i]), float(yOf[i])) + sampler.get2D(RngStream::Camera, dim::kFilm);
                beginCameraSubpath(pass.scene, raster, bdpt, cameraPath(i), &walks[2 * i]);
                if (walks[2 * i].active) toRays.push(2 * i);
            }
            beginLightSubpath(pass.scene, sampler, bdpt, lightPath(i), &walks[2 * i + 1]);
            if (walks[2 * i + 1].active) toRays.push(2 * i + 1);
        },
        rays);
}

// Extend: the closest hit of every queued walk's ray (camera and light walks together).
void WavefrontScheduler::Impl::extendWalks(const PoolPassContext& pass, int bounce) {
    const uint32_t m = rays.size();
    uint64_t lightRays = 0;
    for (uint32_t j = 0; j < m; ++j) lightRays += rays[j] & 1u;
    if (m - lightRays) countRay("camera", bounce, m - lightRays);
    if (lightRays) countRay("light", bounce, lightRays);
    auto body = streamExtend(pass.scene, [&](uint32_t j) {
        const uint32_t w = rays[j];
        ++steps[3 * (w >> 1) + (w & 1u)];
        return std::pair<const Ray*, HitRecord*>(&walks[w].ray, &hits[w]);
    });
    launchChunks("extend", bounce, m, rays.capacity(), false, double(4 + sizeof(Ray) + sizeof(HitRecord)), body);
}

// Shade: the hit becomes the walk's next vertex (and its BSDF); a walk that scatters on is
// queued for the next bounce.
void WavefrontScheduler::Impl::shadeWalks(const PoolPassContext& pass, int bounce) {
    nextRays.clear();  // holds at most one entry per walk: it cannot overflow
    launchAppending(
        "shade", bounce, rays.size(), nextRays.capacity(), false,
        double(4 + sizeof(HitRecord) + 2 * sizeof(SubpathWalk) + sizeof(PathVertex) + 4),
        [&](uint32_t j, ChunkAppender<uint32_t>& toNext) {
            const uint32_t w = rays[j];
            SubpathWalk& walk = walks[w];
            PathVertex* path = walkPath(w);
            Bsdf* bsdfs = walkBsdfs(w);
            if (walkAddVertex(pass.scene, hits[w].found ? &hits[w].hit : nullptr, &walk, path, bsdfs) &&
                walkScatter(pass.scene, PixelSampler(pass.seed, pixelOf[w >> 1], pass.sample), &walk, path, bsdfs))
                toNext.push(w);
        },
        nextRays);
}

// Densities of the finished subpaths; the connection count of each path (steps[3 * i + 2]).
void WavefrontScheduler::Impl::fillDensities(const PoolPassContext& pass) {
    launch("densities", -1, pass.n, 0, false, double(2 * sizeof(PathVertex) * size_t(maxCam + maxLight) / 4), [&](uint32_t i) {
        // Light tracing is unweighted: its densities go unread, except by an observer (the trace
        // records them like the megakernel's trace does).
        if (!lightOnly() || options.observer) {
            fillSubpathDensities(pass.scene, cameraPath(i), walks[2 * i].vertices, bdpt.mis, cameraBsdf(i));
            fillSubpathDensities(pass.scene, lightPath(i), walks[2 * i + 1].vertices, bdpt.mis, lightBsdf(i));
        }
        uint32_t count = 0;
        forEachStrategy(i, [&](int, int) { ++count; });
        steps[3 * i + 2] = count;
    });
}

void WavefrontScheduler::Impl::observeSubpaths(uint32_t n) {
    for (uint32_t i = 0; i < n; ++i)
        options.observer->subpaths(pixelOf[i], cameraPath(i), walks[2 * i].vertices, lightPath(i), walks[2 * i + 1].vertices);
}

// Exclusive prefix sum of the counts (a scan kernel on a GPU): connection slot ranges. Returns
// the pool pass's number of connections.
uint64_t WavefrontScheduler::Impl::scanConnectionCounts(uint32_t n) {
    connectionOffset[0] = 0;
    for (uint32_t i = 0; i < n; ++i) connectionOffset[i + 1] = connectionOffset[i] + steps[3 * i + 2];
    return connectionOffset[n];
}

// The connection queue's fill that starts at slot c0, and the paths whose slots it holds.
ConnectionChunk WavefrontScheduler::Impl::connectionChunk(uint64_t c0, uint64_t total, uint32_t n) const {
    ConnectionChunk chunk;
    chunk.c0 = c0;
    chunk.count = uint32_t(std::min<uint64_t>(connectionCapacity, total - c0));
    chunk.early = c0 + chunk.count < total;
    chunk.p0 = uint32_t(std::upper_bound(connectionOffset.begin(), connectionOffset.begin() + n + 1, c0) -
                        connectionOffset.begin()) - 1;
    chunk.p1 = uint32_t(std::lower_bound(connectionOffset.begin(), connectionOffset.begin() + n + 1, c0 + chunk.count) -
                        connectionOffset.begin());
    return chunk;
}

// Expand: the ConnectionRecord (path, s, t) of every slot of the chunk.
void WavefrontScheduler::Impl::expandConnections(const ConnectionChunk& chunk) {
    const uint64_t c0 = chunk.c0;
    const uint32_t cnt = chunk.count;
    launch("expand", -1, chunk.p1 - chunk.p0, 0, false, double(sizeof(ConnectionRecord) * cnt) / double(chunk.p1 - chunk.p0),
           [&](uint32_t k) {
               const uint32_t i = chunk.p0 + k;
               uint64_t slot = connectionOffset[i];
               forEachStrategy(i, [&](int s, int t) {
                   if (slot >= c0 && slot < c0 + cnt) connections[size_t(slot - c0)] = ConnectionRecord{i, s, t};
                   ++slot;
               });
           });
}

// Connect: the unoccluded contribution of every connection, in sub-launches that fit the shadow
// queue (flushed early when it is full). A contribution that needs visibility goes to the shadow
// queue, the others straight to the finish queue.
void WavefrontScheduler::Impl::evaluateConnections(const PoolPassContext& pass, const ConnectionChunk& chunk) {
    const uint32_t cnt = chunk.count;
    shadow.clear();
    finish.clear();
    for (uint32_t j0 = 0; j0 < cnt;) {
        if (shadow.free() < std::min(cnt - j0, shadow.capacity())) flushConnectionShadow(pass.scene, true);
        const uint32_t c = std::min(cnt - j0, shadow.free());
        launchAppending(
            "connect", -1, c, connectionCapacity, chunk.early && j0 == 0,
            double(sizeof(ConnectionRecord) + 2 * sizeof(PathVertex) + sizeof(PendingConnection) + 1 + 4),
            [&](uint32_t k, ChunkAppender<uint32_t>& toShadow, ChunkAppender<uint32_t>& toFinish) {
                const uint32_t j = j0 + k;
                const ConnectionRecord& r = connections[j];
                status[j] = kNoContribution;
                const PixelSampler sampler(pass.seed, pixelOf[r.path], pass.sample);
                const bool contributes =
                    lightOnly() ? evaluateConnectionUnweighted(pass.scene, lightPath(r.path), r.s, cameraPath(r.path), r.t,
                                                               sampler, &pending[j], subpathBsdfs(r.path))
                                : evaluateConnection(pass.scene, lightPath(r.path), r.s, cameraPath(r.path), r.t, sampler,
                                                     &pending[j], bdpt.mis.lightSampler, subpathBsdfs(r.path));
                if (!contributes) return;
                if (pending[j].needsShadowRay) {
                    status[j] = kAwaitingShadow;
                    toShadow.push(j);
                } else {
                    status[j] = kContributes;
                    toFinish.push(j);
                }
            },
            shadow, finish);
        j0 += c;
    }
}

// Finish: the MIS weight of every unoccluded connection (light tracing is unweighted).
void WavefrontScheduler::Impl::finishConnections(const PoolPassContext& pass) {
    launch("finish", -1, finish.size(), finish.capacity(), false,
           double(4 + sizeof(PendingConnection) + 4 * sizeof(PathVertex) + sizeof(Connection)), [&](uint32_t k) {
               const uint32_t j = finish[k];
               const ConnectionRecord& r = connections[j];
               if (lightOnly()) {
                   results[j] = Connection{pending[j].unweighted, 1.0, pending[j].splat, pending[j].raster};
               } else {
                   finishConnection(pass.scene, lightPath(r.path), r.s, cameraPath(r.path), r.t, pending[j], bdpt, &results[j]);
               }
           });
}

// Accumulate in slot order = the megakernel's (path, t, s) order: camera estimates per
// path, splats and strategy records appended to their tile in canonical order. Counters go to
// dense per-(s, t) and per-depth arrays, merged into the report's maps by
// mergeConnectionCounters (a map lookup per connection was a measurable part of the
// wavefront's cost).
void WavefrontScheduler::Impl::accumulateConnections(const ConnectionChunk& chunk, std::vector<TileOutput>& tiles) {
    const uint32_t cnt = chunk.count;
    StageStats& acc = stage("accumulate", -1);
    ++acc.launches;
    acc.items += cnt;
    acc.maxAtLaunch = std::max<uint64_t>(acc.maxAtLaunch, cnt);
    report.trafficBytes += double(cnt) * double(sizeof(ConnectionRecord) + 1);
    const size_t tStride = size_t(maxCam) + 1;
    chunkCounts.assign((size_t(maxLight) + 1) * tStride, StrategyCounts{});
    chunkShadowByDepth.assign(size_t(bdpt.maxDepth) + 1, 0);
    for (uint32_t j = 0; j < cnt; ++j) {
        const ConnectionRecord& r = connections[j];
        StrategyCounts& sc = chunkCounts[size_t(r.s) * tStride + size_t(r.t)];
        ++sc.evaluated;
        if (options.observer)
            options.observer->connection(WavefrontConnectionEntry{chunk.c0 + j, pixelOf[r.path], r.s, r.t,
                                                                  status[j] != kNoContribution, status[j] == kContributes,
                                                                  &pending[j], &results[j]});
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
        const double w = lightOnly() ? 1.0 : c.weight;
        const Rgb weighted = c.unweighted * float(w);
        TileOutput& to = tiles[tileOf[r.path]];
        if (c.splat) to.splats.push_back(Splat{c.raster, weighted});
        else pathL[r.path] += weighted;
        if (settings.recordStrategies)
            to.strategies.emplace_back(pixelOf[r.path], StrategyContribution{r.s, r.t, weighted, c.unweighted, c.splat, c.raster});
        if (settings.recordDepths)
            to.depths.emplace_back(pixelOf[r.path], DepthContribution{r.s + r.t - 2, weighted, c.splat, c.raster});
    }
}

// The chunk's per-(s, t) counters into report.connections, its shadow rays per depth into the
// ray counts.
void WavefrontScheduler::Impl::mergeConnectionCounters() {
    const size_t tStride = size_t(maxCam) + 1;
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

// Every path's camera estimate into the pass image, and the pool memory its subpaths used.
void WavefrontScheduler::Impl::storeSubpathEstimates(uint32_t n, std::vector<Rgb>& passL) {
    for (uint32_t i = 0; i < n; ++i) {
        passL[layout.local(xOf[i], yOf[i])] = pathL[i];
        const uint64_t used = fixedBytesPerPath() + uint64_t(walks[2 * i].vertices + walks[2 * i + 1].vertices) *
                                                        (sizeof(PathVertex) + sizeof(Bsdf));
        report.bytesPerPathPeak = std::max(report.bytesPerPathPeak, used);
        report.bytesPerPathUsedSum += double(used);
    }
}

}  // namespace bdptref
