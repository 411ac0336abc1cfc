// How much memory a render needs, estimated before anything is allocated, so that a request that
// cannot fit is refused with its size (exit 2) instead of failing with std::bad_alloc half-way.
// What is counted: docs/ground-truth.md, "Memory".
#pragma once

#include <cstddef>
#include <string>

namespace bdptref::cli {

struct MemoryEstimate {
    double film = 0;         // the film's accumulators (sums, squares, light sums, counts)
    double layers = 0;       // per-(s,t) strategy layers' accumulators (--strategies)
    double depthLayers = 0;  // per-depth layers' accumulators (--depth-layers)
    double passBuffers = 0;  // one pass's buffers (camera estimates, splats, strategy and depth values)
    double output = 0;       // the EXR being written (float layers, exact channels, interleaved copy)
    double resume = 0;       // the checkpoint read back (--resume)
    double total() const { return film + layers + depthLayers + passBuffers + output + resume; }
    std::string text() const;  // "about 3.2 GiB (film ..., ...)"
};

// `pixels`: of the crop window (the whole image without --crop); strategyDepth, depthLayersDepth
// -1: no strategy layers, no depth layers.
MemoryEstimate estimateRenderMemory(double pixels, int strategyDepth, int depthLayersDepth, bool splats, bool resume);

// The memory this process may use: the smaller of the physical memory and the address-space and
// data-segment limits (ulimit -v / -d). `source` says which one it is.
double availableMemoryBytes(std::string* source);

// Throws InputError when the estimate exceeds the available memory.
void checkRenderFits(const MemoryEstimate& estimate, const std::string& request);

// "1.5 GiB", "12 MiB", "800 KiB".
std::string formatBytes(double bytes);

}  // namespace bdptref::cli
