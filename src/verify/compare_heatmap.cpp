// The heatmap PNG of a comparison: signed per-pixel z-scores (or relative errors) in a diverging
// colour map, with a legend bar and its labels drawn in a tiny bitmap font.
#include "verify/compare_internal.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace bdptref {

using namespace compare_detail;

namespace {

// A 3x5 bitmap font: each glyph is 5 rows of 3 bits (bit 2 = left column).
struct Glyph {
    char c;
    uint8_t rows[5];
};
const Glyph kFont[] = {
    {'0', {7, 5, 5, 5, 7}}, {'1', {2, 6, 2, 2, 7}}, {'2', {7, 1, 7, 4, 7}}, {'3', {7, 1, 7, 1, 7}},
    {'4', {5, 5, 7, 1, 1}}, {'5', {7, 4, 7, 1, 7}}, {'6', {7, 4, 7, 5, 7}}, {'7', {7, 1, 1, 1, 1}},
    {'8', {7, 5, 7, 5, 7}}, {'9', {7, 5, 7, 1, 7}}, {'+', {0, 2, 7, 2, 0}}, {'-', {0, 0, 7, 0, 0}},
    {'.', {0, 0, 0, 0, 2}}, {'%', {5, 1, 2, 4, 5}}, {'e', {0, 7, 7, 4, 7}}, {'z', {0, 7, 2, 4, 7}},
    {'|', {2, 2, 2, 2, 2}},
};
constexpr int kFontScale = 2;
constexpr int kGlyphW = 3 * kFontScale, kGlyphH = 5 * kFontScale, kGlyphGap = kFontScale;

struct Canvas {
    int w, h;
    std::vector<uint8_t> px;  // RGB
    Canvas(int width, int height) : w(width), h(height), px(size_t(width) * size_t(height) * 3, 0) {}
    void set(int x, int y, const std::array<uint8_t, 3>& c) {
        if (x < 0 || y < 0 || x >= w || y >= h) return;
        uint8_t* p = &px[(size_t(y) * size_t(w) + size_t(x)) * 3];
        p[0] = c[0];
        p[1] = c[1];
        p[2] = c[2];
    }
    void fill(int x0, int y0, int x1, int y1, const std::array<uint8_t, 3>& c) {
        for (int y = y0; y < y1; ++y)
            for (int x = x0; x < x1; ++x) set(x, y, c);
    }
};

int textWidth(const std::string& s) { return s.empty() ? 0 : int(s.size()) * (kGlyphW + kGlyphGap) - kGlyphGap; }

void drawText(Canvas& cv, int x, int y, const std::string& s, const std::array<uint8_t, 3>& col) {
    for (char ch : s) {
        for (const Glyph& g : kFont)
            if (g.c == ch) {
                for (int ry = 0; ry < 5; ++ry)
                    for (int rx = 0; rx < 3; ++rx)
                        if (g.rows[ry] & (4 >> rx)) cv.fill(x + rx * kFontScale, y + ry * kFontScale,
                                                            x + (rx + 1) * kFontScale, y + (ry + 1) * kFontScale, col);
                break;
            }
        x += kGlyphW + kGlyphGap;
    }
}

// Diverging blue - grey - red ("cool to warm") for u in [-1, 1].
std::array<uint8_t, 3> diverging(double u) {
    u = std::clamp(u, -1.0, 1.0);
    const double lo[3] = {59, 76, 192}, mid[3] = {221, 221, 221}, hi[3] = {180, 4, 38};
    std::array<uint8_t, 3> c{};
    for (int k = 0; k < 3; ++k) {
        const double v = u < 0 ? mid[k] + (lo[k] - mid[k]) * (-u) : mid[k] + (hi[k] - mid[k]) * u;
        c[size_t(k)] = uint8_t(std::lround(v));
    }
    return c;
}

std::string shortNumber(double v, bool percent) {
    char buf[32];
    if (percent) {
        const double pv = v * 100.0;
        std::snprintf(buf, sizeof buf, std::abs(pv) >= 10 || pv == std::round(pv) ? "%+.0f%%" : "%+.1f%%", pv);
        if (std::abs(pv) < 0.1 && pv != 0) std::snprintf(buf, sizeof buf, "%+.2f%%", pv);
    } else {
        std::snprintf(buf, sizeof buf, v == std::round(v) ? "%+.0f" : "%+.1f", v);
    }
    std::string s = buf;
    if (s == "+0" || s == "-0") s = "0";
    if (s == "+0%" || s == "-0%") s = "0%";
    return s;
}

// 1, 2, 5 x 10^k, the smallest >= v.
double niceCeil(double v) {
    if (!(v > 0)) return 1.0;
    const double e = std::pow(10.0, std::floor(std::log10(v)));
    for (double m : {1.0, 2.0, 5.0, 10.0})
        if (m * e >= v * (1 - 1e-12)) return m * e;
    return 10 * e;
}

}  // namespace

HeatmapLayout heatmapLayout(int regionWidth, int regionHeight) {
    HeatmapLayout l;
    const int longest = std::max(1, std::max(regionWidth, regionHeight));
    l.scale = std::clamp((256 + longest - 1) / longest, 1, 32);
    l.imageHeight = regionHeight * l.scale;
    l.width = std::max(regionWidth * l.scale, 256);
    const int margin = 24;
    l.barX0 = margin;
    l.barX1 = l.width - margin;
    l.barY0 = l.imageHeight + 8;
    l.barY1 = l.barY0 + 14;
    l.height = l.barY1 + 6 + kGlyphH + 6;
    return l;
}

void writeHeatmapPng(const std::string& path, const CompareResult& r) {
    const HeatmapLayout L = heatmapLayout(r.region.width, r.region.height);
    Canvas cv(L.width, L.height);
    cv.fill(0, 0, L.width, L.height, {32, 32, 32});
    const bool zMode = r.kind != TestKind::None;
    double range;
    if (zMode) {
        range = std::max(5.0, std::ceil(r.zThreshold + 1.0));
    } else {
        std::vector<float> a;
        for (size_t i = 0; i < r.relError.size(); ++i)
            if (r.status[i] == PixelStatus::NoVariance && std::isfinite(r.relError[i])) a.push_back(std::abs(r.relError[i]));
        double q = 0.01;
        if (!a.empty()) {
            const size_t k = std::min(a.size() - 1, size_t(0.99 * double(a.size())));
            std::nth_element(a.begin(), a.begin() + long(k), a.end());
            q = std::max(1e-3, double(a[k]));
        }
        range = niceCeil(q);
    }
    const std::array<uint8_t, 3> grey{96, 96, 96}, black{0, 0, 0}, magenta{255, 0, 255}, white{235, 235, 235},
        yellow{255, 220, 0};
    for (int ry = 0; ry < r.region.height; ++ry)
        for (int rx = 0; rx < r.region.width; ++rx) {
            const size_t i = size_t(r.region.y + ry) * size_t(r.width) + size_t(r.region.x + rx);
            std::array<uint8_t, 3> c;
            switch (r.status[i]) {
            case PixelStatus::Outside: c = black; break;
            case PixelStatus::NonFinite:
            case PixelStatus::Unequal: c = magenta; break;
            case PixelStatus::FewSamples:
            case PixelStatus::LowEffective: c = grey; break;
            case PixelStatus::Equal: c = diverging(0.0); break;
            case PixelStatus::Tested: c = diverging(double(r.pixelZ[i]) / range); break;
            case PixelStatus::NoVariance: c = diverging(double(r.relError[i]) / range); break;
            default: c = grey;
            }
            cv.fill(rx * L.scale, ry * L.scale, (rx + 1) * L.scale, (ry + 1) * L.scale, c);
        }
    // Outline the worst region.
    if (r.flagged > 0 && r.worstX1 >= r.worstX0) {
        const int x0 = (r.worstX0 - r.region.x) * L.scale, x1 = (r.worstX1 + 1 - r.region.x) * L.scale - 1;
        const int y0 = (r.worstY0 - r.region.y) * L.scale, y1 = (r.worstY1 + 1 - r.region.y) * L.scale - 1;
        for (int x = x0; x <= x1; ++x) {
            cv.set(x, y0, yellow);
            cv.set(x, y1, yellow);
        }
        for (int y = y0; y <= y1; ++y) {
            cv.set(x0, y, yellow);
            cv.set(x1, y, yellow);
        }
    }
    // Legend: the colour bar from -range to +range, its unit at the left, labels below.
    const int barW = L.barX1 - L.barX0;
    for (int x = L.barX0; x < L.barX1; ++x) {
        const double u = (double(x - L.barX0) + 0.5) / double(barW) * 2.0 - 1.0;
        cv.fill(x, L.barY0, x + 1, L.barY1, diverging(u));
    }
    drawText(cv, 6, L.barY0 + (L.barY1 - L.barY0 - kGlyphH) / 2, zMode ? "z" : "%", white);
    const int labelY = L.barY1 + 4;
    auto xOf = [&](double v) { return L.barX0 + int(std::lround((v / range + 1.0) * 0.5 * double(barW))); };
    struct Label {
        double v;
        std::string s;
    };
    std::vector<Label> labels = {{-range, shortNumber(-range, !zMode)}, {0.0, zMode ? "0" : "0%"},
                                 {range, shortNumber(range, !zMode)}};
    if (zMode && r.zThreshold > 0 && r.zThreshold < range) {
        labels.push_back({-r.zThreshold, shortNumber(-r.zThreshold, false)});
        labels.push_back({r.zThreshold, shortNumber(r.zThreshold, false)});
    }
    std::vector<std::pair<int, int>> used;  // occupied label spans
    for (const Label& lb : labels) {
        const int tw = textWidth(lb.s);
        const int cx = xOf(lb.v);
        const int x0 = std::clamp(cx - tw / 2, 0, L.width - tw);
        bool overlaps = false;
        for (const auto& u : used) overlaps = overlaps || !(x0 + tw + 4 <= u.first || x0 >= u.second + 4);
        cv.fill(std::clamp(cx, L.barX0, L.barX1 - 1), L.barY1, std::clamp(cx, L.barX0, L.barX1 - 1) + 1, L.barY1 + 3,
                white);  // tick
        if (overlaps) continue;
        drawText(cv, x0, labelY, lb.s, white);
        used.emplace_back(x0, x0 + tw);
    }

    writeRgb8Png(path, L.width, L.height, cv.px);
}

}  // namespace bdptref
