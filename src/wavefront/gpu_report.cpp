// The figures of the wavefront mode for a GPU port (docs/wavefront.md, "Reported figures"):
// JSON for tools, a few lines for people.
#include "bdptref/wavefront.h"

#include <nlohmann/json.hpp>

#include <cstdio>

namespace bdptref {

double GpuReport::simtEfficiencyMegakernel() const {
    return megakernelIssuedLanes ? double(megakernelActiveLanes) / double(megakernelIssuedLanes) : 0.0;
}
double GpuReport::simtEfficiencyWavefront() const {
    return wavefrontIssuedLanes ? double(wavefrontActiveLanes) / double(wavefrontIssuedLanes) : 0.0;
}

// Per-path buffers for every path in flight, the ray queues (current and next: one entry per
// subpath each), the shadow queue (one entry per path) and, for BDPT/LT, the connection queue
// (4 entries per path, the default capacity ratio) with its finish queue.
uint64_t GpuReport::bufferBytesFor(int width, int height) const {
    const uint64_t paths = uint64_t(width) * uint64_t(height);
    uint64_t bytes = paths * bytesPerPathStatic + paths * rayQueuesPerPath * 4 + paths * bytesPerShadowEntry;
    if (bytesPerConnection) bytes += 4 * paths * bytesPerConnection;
    return bytes;
}
uint64_t GpuReport::bufferBytesForPool() const {
    const uint64_t paths = uint64_t(poolSize);
    return paths * bytesPerPathStatic + paths * rayQueuesPerPath * 4 + uint64_t(shadowQueueCapacity) * bytesPerShadowEntry +
           uint64_t(connectionQueueCapacity) * bytesPerConnection;
}

std::string gpuReportJson(const GpuReport& r) {
    nlohmann::ordered_json j;
    j["integrator"] = r.integrator;
    j["maxDepth"] = r.maxDepth;
    j["poolSize"] = r.poolSize;
    j["shadowQueueCapacity"] = r.shadowQueueCapacity;
    j["connectionQueueCapacity"] = r.connectionQueueCapacity;
    j["pathSamples"] = r.pathSamples;
    j["poolPasses"] = r.poolPasses;
    nlohmann::ordered_json stages = nlohmann::ordered_json::array();
    for (const auto& [key, st] : r.stages) {
        nlohmann::ordered_json e;
        e["stage"] = key.first;
        e["bounce"] = key.second;  // -1: not a per-bounce stage
        e["launches"] = st.launches;
        e["items"] = st.items;
        e["meanQueueLengthAtLaunch"] = st.launches ? double(st.items) / double(st.launches) : 0.0;
        e["peakQueueLength"] = st.maxAtLaunch;
        e["capacity"] = st.capacity;
        e["flushes"] = st.flushes;
        stages.push_back(e);
    }
    j["stages"] = stages;
    nlohmann::ordered_json rays;
    for (const auto& [type, perDepth] : r.raysByDepth) rays[type] = perDepth;
    j["raysByDepth"] = rays;
    nlohmann::ordered_json conns = nlohmann::ordered_json::array();
    for (const auto& [st, c] : r.connections)
        conns.push_back({{"s", st.first}, {"t", st.second}, {"evaluated", c.evaluated}, {"shadowRays", c.shadowRays},
                         {"unoccluded", c.contributed}});
    j["connections"] = conns;
    j["simt"] = {{"warpSize", 32},
                 {"megakernel", {{"activeLanes", r.megakernelActiveLanes}, {"issuedLanes", r.megakernelIssuedLanes},
                                 {"efficiency", r.simtEfficiencyMegakernel()}}},
                 {"wavefront", {{"activeLanes", r.wavefrontActiveLanes}, {"issuedLanes", r.wavefrontIssuedLanes},
                                {"efficiency", r.simtEfficiencyWavefront()}}}};
    j["memory"] = {{"bytesPerPathStatic", r.bytesPerPathStatic},
                   {"bytesPerPathPeak", r.bytesPerPathPeak},
                   {"bytesPerPathMeanUsed", r.pathSamples ? r.bytesPerPathUsedSum / double(r.pathSamples) : 0.0},
                   {"bytesPerConnectionEntry", r.bytesPerConnection},
                   {"bytesPerShadowEntry", r.bytesPerShadowEntry},
                   {"bufferBytesForPool", r.bufferBytesForPool()},
                   {"bufferBytes1920x1080", r.bufferBytesFor(1920, 1080)},
                   {"bufferBytes1920x1080PathBuffers", uint64_t(1920 * 1080) * r.bytesPerPathStatic},
                   {"bufferBytes1920x1080Queues", r.bufferBytesFor(1920, 1080) - uint64_t(1920 * 1080) * r.bytesPerPathStatic}};
    j["traffic"] = {{"bytesTotal", r.trafficBytes}, {"bytesPerSample", r.trafficBytesPerSample()}};
    return j.dump(2) + "\n";
}

std::string gpuReportSummary(const GpuReport& r) {
    char buf[512];
    std::string out;
    auto mib = [](uint64_t b) { return double(b) / double(1 << 20); };
    uint64_t launches = 0, flushes = 0;
    for (const auto& [key, st] : r.stages) {
        launches += st.launches;
        flushes += st.flushes;
    }
    std::snprintf(buf, sizeof(buf),
                  "bdptref: wavefront (%s, max depth %d): pool %d paths, %llu pool passes, %llu stage launches, %llu "
                  "early flushes\n",
                  r.integrator.c_str(), r.maxDepth, r.poolSize, static_cast<unsigned long long>(r.poolPasses),
                  static_cast<unsigned long long>(launches), static_cast<unsigned long long>(flushes));
    out += buf;
    std::snprintf(buf, sizeof(buf), "bdptref: simulated SIMT efficiency (warps of 32): megakernel %.1f%%, wavefront %.1f%%\n",
                  100.0 * r.simtEfficiencyMegakernel(), 100.0 * r.simtEfficiencyWavefront());
    out += buf;
    std::snprintf(buf, sizeof(buf),
                  "bdptref: bytes per path %llu static, %llu peak; buffer traffic %.0f bytes per sample; buffers %.1f MiB "
                  "for this pool, %.1f MiB at 1920x1080 (one path per pixel)\n",
                  static_cast<unsigned long long>(r.bytesPerPathStatic), static_cast<unsigned long long>(r.bytesPerPathPeak),
                  r.trafficBytesPerSample(), mib(r.bufferBytesForPool()), mib(r.bufferBytesFor(1920, 1080)));
    out += buf;
    return out;
}

}  // namespace bdptref
