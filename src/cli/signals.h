// SIGINT/SIGTERM request a graceful stop: the render finishes nothing more, writes what it has
// (complete passes only) and exits non-zero. A second SIGINT kills the process at once.
#pragma once

#include <atomic>

namespace bdptref::cli {

std::atomic<bool>& stopRequested();
void installStopHandlers();
int stopSignal();  // the signal that asked to stop (0 if none)

}  // namespace bdptref::cli
