#include "cli/progress.h"

#include <cstdio>
#include <unistd.h>

namespace bdptref::cli {

std::string formatSeconds(double s) {
    char buf[64];
    if (s < 60) std::snprintf(buf, sizeof buf, "%.1fs", s);
    else if (s < 3600) std::snprintf(buf, sizeof buf, "%dm%02ds", int(s) / 60, int(s) % 60);
    else std::snprintf(buf, sizeof buf, "%dh%02dm", int(s) / 3600, (int(s) % 3600) / 60);
    return buf;
}

ProgressBar::ProgressBar(bool enabled) : enabled_(enabled), tty_(::isatty(STDERR_FILENO) != 0) {}

void ProgressBar::update(const RenderProgress& p) {
    if (!enabled_ || p.passesTotal <= 0) return;
    const double frac = double(p.passesDone) / double(p.passesTotal);
    const double rate = p.seconds > 0 ? p.passesDone / p.seconds : 0;
    const double eta = rate > 0 ? (p.passesTotal - p.passesDone) / rate : 0;
    if (tty_) {
        if (p.passesDone != p.passesTotal && p.seconds - lastDraw_ < 0.1) return;
        lastDraw_ = p.seconds;
        const int width = 30, filled = int(frac * width);
        std::fprintf(stderr, "\r[%s%s] %d/%d spp  %.2f spp/s  elapsed %s  ETA %s   ",
                     std::string(size_t(filled), '#').c_str(), std::string(size_t(width - filled), ' ').c_str(),
                     p.passesDone, p.passesTotal, rate, formatSeconds(p.seconds).c_str(), formatSeconds(eta).c_str());
        drawn_ = true;
    } else {
        const int decile = int(frac * 10);
        if (decile == lastDecile_) return;
        lastDecile_ = decile;
        std::fprintf(stderr, "progress: %d/%d spp (%d%%), %.2f spp/s, elapsed %s, ETA %s\n", p.passesDone,
                     p.passesTotal, int(frac * 100), rate, formatSeconds(p.seconds).c_str(), formatSeconds(eta).c_str());
    }
    std::fflush(stderr);
}

void ProgressBar::finish() {
    if (enabled_ && tty_ && drawn_) std::fprintf(stderr, "\n");
}

}  // namespace bdptref::cli
