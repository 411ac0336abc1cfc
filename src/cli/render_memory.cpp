#include "cli/render_memory.h"

#include "bdptref/errors.h"
#include "bdptref/film.h"
#include "bdptref/math.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>

namespace bdptref::cli {

std::string formatBytes(double bytes) {
    const char* units[] = {"B", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
    int u = 0;
    while (bytes >= 1024.0 && u < 6) {
        bytes /= 1024.0;
        ++u;
    }
    char buf[48];
    std::snprintf(buf, sizeof buf, "%.3g %s", bytes, units[u]);
    return buf;
}

std::string MemoryEstimate::text() const {
    std::string t = "about " + formatBytes(total()) + " (film " + formatBytes(film);
    if (layers > 0) t += ", strategy layers " + formatBytes(layers);
    if (depthLayers > 0) t += ", depth layers " + formatBytes(depthLayers);
    t += ", per-pass buffers " + formatBytes(passBuffers) + ", EXR output " + formatBytes(output);
    if (resume > 0) t += ", checkpoint read back " + formatBytes(resume);
    return t + ")";
}

MemoryEstimate estimateRenderMemory(double pixels, int strategyDepth, int depthLayersDepth, bool splats, bool resume) {
    const double layerCount = double(StrategyLayers::layerCountFor(strategyDepth));
    const double depthCount = depthLayersDepth < 0 ? 0.0 : double(depthLayersDepth) + 1.0;
    MemoryEstimate e;
    e.film = Film::bytesFor(pixels, -1);
    e.layers = Film::bytesFor(pixels, strategyDepth) - e.film;
    e.depthLayers = Film::bytesFor(pixels, -1, depthLayersDepth) - e.film;
    // passL and passLight, for the strategy layers a weighted and an unweighted value per layer,
    // for the depth layers one value per depth. The per-tile splat and contribution lists depend
    // on the path lengths and are not counted.
    e.passBuffers = pixels * (2.0 * sizeof(Rgb) + layerCount * 2.0 * sizeof(Rgb) + depthCount * sizeof(Rgb));
    // Float channels: beauty 3, variance 3, count 1, light 3, strategy layers 12 each, depth
    // layers 6 each; exact UINT channels: two per 64-bit value (sum 3, squares 3, count 1, light 3,
    // strategy layers 12 each, depth layers 6 each). The writer holds the layers and an
    // interleaved copy of all of them.
    const double floatChannels = 7.0 + (splats ? 3.0 : 0.0) + 12.0 * layerCount + 6.0 * depthCount;
    const double uintChannels = 2.0 * (7.0 + (splats ? 3.0 : 0.0) + 12.0 * layerCount + 6.0 * depthCount);
    e.output = pixels * 4.0 * (floatChannels + uintChannels) * 2.0;
    // A checkpoint is read as its raw pixels and then as a film.
    if (resume) e.resume = pixels * 4.0 * (floatChannels + uintChannels) + e.film + e.layers + e.depthLayers;
    return e;
}

double availableMemoryBytes(std::string* source) {
    const long pages = ::sysconf(_SC_PHYS_PAGES), pageSize = ::sysconf(_SC_PAGE_SIZE);
    double avail = pages > 0 && pageSize > 0 ? double(pages) * double(pageSize) : 1e300;
    std::string what = "physical memory";
    struct rlimit rl;
    if (::getrlimit(RLIMIT_AS, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY && double(rl.rlim_cur) < avail) {
        avail = double(rl.rlim_cur);
        what = "address-space limit (ulimit -v)";
    }
    if (::getrlimit(RLIMIT_DATA, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY && double(rl.rlim_cur) < avail) {
        avail = double(rl.rlim_cur);
        what = "data-segment limit (ulimit -d)";
    }
    if (source) *source = what;
    return avail;
}

void checkRenderFits(const MemoryEstimate& estimate, const std::string& request) {
    std::string source;
    const double avail = availableMemoryBytes(&source);
    if (estimate.total() > avail)
        throw InputError(request + " needs " + estimate.text() + ", more than this machine's " + source + " of " +
                         formatBytes(avail) + ": render a --crop window (only the window is held in memory), a smaller "
                         "image, or fewer strategy or depth layers (--max-depth with --strategies or --depth-layers)");
}

}  // namespace bdptref::cli
