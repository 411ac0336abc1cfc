// Progress on stderr: a redrawn bar on a terminal, a line every 10% otherwise (logs, CI).
#pragma once

#include "bdptref/renderer.h"

#include <string>

namespace bdptref::cli {

class ProgressBar {
public:
    explicit ProgressBar(bool enabled);
    void update(const RenderProgress& p);
    void finish();

private:
    bool enabled_, tty_;
    double lastDraw_ = -1;
    int lastDecile_ = -1;
    bool drawn_ = false;
};

std::string formatSeconds(double s);

}  // namespace bdptref::cli
