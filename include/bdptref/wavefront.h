// The GPU-style wavefront emulation mode (docs/wavefront.md): a pass is computed by stages, each a
// parallel launch over a fixed-capacity queue filled through atomic-append counters, on a pool of
// paths in flight. The stages store the same PathVertex and call the same light-transport
// functions as the megakernel (bdpt.h, src/render/path_tracer.h), so the image is bit-identical.
#pragma once

#include "bdptref/integrator.h"
#include "bdptref/pass_scheduler.h"

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace bdptref {

class WavefrontObserver;

struct WavefrontOptions {
    int poolSize = 0;                 // paths in flight per pool pass; 0 = automatic (docs/wavefront.md)
    int shadowQueueCapacity = 0;      // shadow-ray queue entries; 0 = the pool size
    int connectionQueueCapacity = 0;  // connection records per connect launch; 0 = 4 x the pool size
    WavefrontObserver* observer = nullptr;  // BDPT/LT: shown what the stages stored (the wavefront trace)
};

// One connection-queue entry after the shadow and finish stages, as the accumulate stage reads it.
struct WavefrontConnectionEntry {
    uint64_t slot = 0;      // connection slot of the pool pass (connectionOffset order: path, t, s)
    uint32_t pixel = 0;     // pixel index of the path
    int s = 0, t = 0;
    bool connected = false;   // connect: evaluateConnection found an unoccluded contribution
    bool unoccluded = false;  // shadow (or no shadow ray needed): the entry went on to finish
    const PendingConnection* pending = nullptr;  // connect's output (meaningful when `connected`)
    const Connection* result = nullptr;          // finish's output (meaningful when `unoccluded`)
};

// Called by the scheduler from its sequential points, in canonical order (tests and the trace
// tool read the stages' buffers through it; it must not change anything).
class WavefrontObserver {
public:
    virtual ~WavefrontObserver() = default;
    // After the densities stage: both subpaths of one path, as stored in the pool's vertex buffers.
    virtual void subpaths(uint32_t pixel, const PathVertex* camera, int nCamera, const PathVertex* light, int nLight) = 0;
    // Accumulate: every connection-queue entry, in slot order.
    virtual void connection(const WavefrontConnectionEntry& entry) = 0;
};

// One stage at one bounce (bounce -1: stages that are not per bounce).
struct StageStats {
    uint64_t launches = 0;     // launches of the stage (one per drain of its input queue)
    uint64_t items = 0;        // queue entries processed, over all launches
    uint64_t maxAtLaunch = 0;  // the longest queue at a launch (= peak occupancy of the queue)
    uint64_t capacity = 0;     // entries the queue can hold
    uint64_t flushes = 0;      // launches forced early because the producer would have overflowed it
};

struct StrategyCounts {
    uint64_t evaluated = 0;   // connection records processed by the connect stage
    uint64_t shadowRays = 0;  // of these, those with a non-zero unoccluded contribution (a shadow ray)
    uint64_t contributed = 0;  // unoccluded (or needing no shadow ray): they reach the image
};

struct GpuReport {
    std::string integrator;
    int maxDepth = 0;
    int poolSize = 0, shadowQueueCapacity = 0, connectionQueueCapacity = 0;
    uint64_t pathSamples = 0;  // pixel samples computed
    uint64_t poolPasses = 0;
    std::map<std::pair<std::string, int>, StageStats> stages;  // (stage, bounce)
    std::map<std::string, std::vector<uint64_t>> raysByDepth;  // ray type -> rays per depth
    std::map<std::pair<int, int>, StrategyCounts> connections;  // (s, t) -> counts
    // Simulated SIMT: lanes that did work and lanes issued, warps of 32 (docs/wavefront.md).
    uint64_t megakernelActiveLanes = 0, megakernelIssuedLanes = 0;
    uint64_t wavefrontActiveLanes = 0, wavefrontIssuedLanes = 0;
    uint64_t bytesPerPathStatic = 0;  // per-path buffers allocated for the max depth
    uint64_t bytesPerPathPeak = 0;    // the most any path actually used
    double bytesPerPathUsedSum = 0;   // over all paths (mean = / pathSamples)
    uint64_t bytesPerConnection = 0;  // one connection-queue entry (record + pending + result)
    uint64_t bytesPerShadowEntry = 0;
    uint64_t rayQueuesPerPath = 0;    // ray-queue entries per path (2 queues x subpaths)
    double trafficBytes = 0;          // record bytes read + written by all stage launches

    double simtEfficiencyMegakernel() const;
    double simtEfficiencyWavefront() const;
    double trafficBytesPerSample() const { return pathSamples ? trafficBytes / double(pathSamples) : 0.0; }
    // Buffer memory of this layout with one path in flight per pixel of a width x height image.
    uint64_t bufferBytesFor(int width, int height) const;
    uint64_t bufferBytesForPool() const;
};

std::string gpuReportJson(const GpuReport& report);
std::string gpuReportSummary(const GpuReport& report);  // a few lines for stderr

class WavefrontScheduler final : public PassScheduler {
public:
    // integrator: "path"/"pt", "lt"/"light", "bdpt" (as makeIntegrator); InputError otherwise.
    WavefrontScheduler(const std::string& integrator, const IntegratorSettings& settings, const WavefrontOptions& options);
    ~WavefrontScheduler() override;
    bool renderPass(const Scene& scene, const Integrator& integrator, const PassLayout& layout, uint32_t seed,
                    uint64_t sample, std::vector<Rgb>& passL, std::vector<TileOutput>& tiles,
                    const std::atomic<bool>* cancel) override;
    const GpuReport& report() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace bdptref
