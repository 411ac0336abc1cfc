#include "cli/signals.h"

#include <csignal>

namespace bdptref::cli {

namespace {
std::atomic<bool> gStop{false};
volatile std::sig_atomic_t gSignal = 0;

extern "C" void onStopSignal(int sig) {
    if (gStop.load()) {  // second request: stop now
        std::signal(sig, SIG_DFL);
        std::raise(sig);
        return;
    }
    gSignal = sig;
    gStop.store(true);
}
}  // namespace

std::atomic<bool>& stopRequested() { return gStop; }
int stopSignal() { return int(gSignal); }

void installStopHandlers() {
    struct sigaction sa {};
    sa.sa_handler = onStopSignal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESTART;
    sigaction(SIGINT, &sa, nullptr);
    sigaction(SIGTERM, &sa, nullptr);
}

}  // namespace bdptref::cli
