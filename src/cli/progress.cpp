#include "cli/progress.h"

#include <algorithm>
#include <climits>
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
    double frac = double(p.passesDone) / double(p.passesTotal);
    const double rate = p.seconds > 0 ? p.passesDone / p.seconds : 0;
    double eta = rate > 0 ? (p.passesTotal - p.passesDone) / rate : 0;
    if (p.secondsBudget > 0 && p.seconds / p.secondsBudget > frac) {  // --time ends it first
        frac = std::min(1.0, p.seconds / p.secondsBudget);
        eta = std::max(0.0, p.secondsBudget - p.seconds);
    }
    // With only --time there is no spp limit (passesTotal is INT_MAX): show the passes done.
    const std::string total = p.passesTotal == INT_MAX ? std::string("") : "/" + std::to_string(p.passesTotal);
    if (tty_) {
        if (p.passesDone != p.passesTotal && p.seconds - lastDraw_ < 0.1) return;
        lastDraw_ = p.seconds;
        const int width = 30, filled = int(frac * width);
        std::fprintf(stderr, "\r[%s%s] %d%s spp  %.2f spp/s  elapsed %s  ETA %s   ",
                     std::string(size_t(filled), '#').c_str(), std::string(size_t(width - filled), ' ').c_str(),
                     p.passesDone, total.c_str(), rate, formatSeconds(p.seconds).c_str(), formatSeconds(eta).c_str());
        drawn_ = true;
    } else {
        const int decile = int(frac * 10);
        if (decile == lastDecile_) return;
        lastDecile_ = decile;
        std::fprintf(stderr, "progress: %d%s spp (%d%%), %.2f spp/s, elapsed %s, ETA %s\n", p.passesDone,
                     total.c_str(), int(frac * 100), rate, formatSeconds(p.seconds).c_str(), formatSeconds(eta).c_str());
    }
    std::fflush(stderr);
}

void ProgressBar::finish() {
    if (enabled_ && tty_ && drawn_) std::fprintf(stderr, "\n");
}

}  // namespace bdptref::cli
