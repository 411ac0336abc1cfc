// Environment maps generated in code for the env-map tests (no binary assets): texel values are
// pure functions of (col, row), so a test can integrate the map itself without EnvironmentMap.
#pragma once

#include "bdptref/env_map.h"

#include <cmath>
#include <functional>
#include <vector>

namespace bdptref::test {

using TexelFunction = std::function<Rgb(int col, int row)>;

inline std::vector<Rgb> texelsOf(int w, int h, const TexelFunction& f) {
    std::vector<Rgb> t(size_t(w) * size_t(h));
    for (int r = 0; r < h; ++r)
        for (int c = 0; c < w; ++c) t[size_t(r) * size_t(w) + size_t(c)] = f(c, r);
    return t;
}

// A smooth sky: brighter and bluer towards the zenith, a dim brownish ground, a gentle variation
// in azimuth (so the conditional distributions differ from row to row).
inline Rgb smoothSky(int col, int row, int w, int h) {
    const double theta = 3.14159265358979323846 * (row + 0.5) / h, phi = 2.0 * 3.14159265358979323846 * (col + 0.5) / w;
    const double up = std::cos(theta);
    if (up < 0.0) return Rgb(0.12f, 0.09f, 0.06f) * float(1.0 + 0.3 * std::cos(phi));
    const double s = 0.4 + 0.6 * up + 0.2 * std::sin(phi) * (1.0 - up);
    return Rgb(float(0.35 * s), float(0.5 * s), float(0.9 * s));
}

// The same sky with a "sun": one texel at (sunCol, sunRow) of the given radiance.
constexpr int kSunCol = 41, kSunRow = 7;  // above the horizon (row < h / 2 for h = 32)
inline Rgb sunAndSky(int col, int row, int w, int h, float sun = 20000.f) {
    if (col == kSunCol && row == kSunRow) return Rgb(sun, 0.9f * sun, 0.75f * sun);
    return smoothSky(col, row, w, h);
}

inline EnvironmentMap smoothSkyMap(int w = 64, int h = 32, float rotation = 0.f) {
    return EnvironmentMap(w, h, texelsOf(w, h, [&](int c, int r) { return smoothSky(c, r, w, h); }), rotation);
}
inline EnvironmentMap sunAndSkyMap(int w = 64, int h = 32, float rotation = 0.f, float sun = 20000.f) {
    return EnvironmentMap(w, h, texelsOf(w, h, [&](int c, int r) { return sunAndSky(c, r, w, h, sun); }), rotation);
}

}  // namespace bdptref::test
