// The shape of each image's pixel estimator judged from the pixel's 8 neighbours in that image (at
// the region's border, its 3 x 3 window shifted inside; docs/compare.md, "Too few samples"): the
// relative per-sample variance C = sigma^2 / mu^2, so that n_eff = n / (1 + C). Neither the
// pixel's own noise (a rule that used it would keep the pixels whose skewed samples missed their
// rare large values, low mean and low variance, and drop those that caught them) nor the other
// image (a path tracer's test image is not shaped like a BDPT reference) enters.
#include "verify/compare_internal.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace bdptref::compare_detail {

NeighbourShape neighbourShape(const CompareResult& r, const CompareOptions& options, int W,
                              const std::vector<float>& mean, const std::vector<float>& var,
                              const std::vector<float>& count) {
    const PixelRegion& g = r.region;
    const size_t N = mean.size();
    std::vector<double> s2(N, 0.0), m2(N, 0.0), rel(N, 0.0);
    std::vector<uint8_t> ok(N, 0);
    for (int y = g.y; y < g.y + g.height; ++y)
        for (int x = g.x; x < g.x + g.width; ++x) {
            const size_t i = size_t(y) * size_t(W) + size_t(x);
            if (!options.mask.empty() && !options.mask[i]) continue;
            const double m = mean[i], v = var[i], n = count[i];
            if (!std::isfinite(m) || !std::isfinite(v) || !(n >= 2.0) || !std::isfinite(n)) continue;
            // (n - 1) v = sum x^2 / n - m^2; relative to m^2 at most n (one sample carries the pixel).
            // A pixel whose samples were all 0 tells nothing about the shape (it may have missed
            // every rare contribution): left out.
            s2[i] = (n - 1.0) * std::max(0.0, v);
            m2[i] = m * m;
            if (m2[i] == 0 && s2[i] == 0) continue;
            rel[i] = m2[i] > 0 ? std::min(s2[i] / m2[i], n) : n;
            ok[i] = 1;
        }
    NeighbourShape out;
    out.meanOfRatios.assign(N, std::numeric_limits<double>::quiet_NaN());
    out.ratioOfSums.assign(N, std::numeric_limits<double>::quiet_NaN());
    // The pixel's 3 x 3 window, shifted to lie inside the region: a pixel at its border or corner
    // is judged by 8 neighbours as one inside it is, not by 5 or 3 (a corner whose 3 neighbours
    // had all missed the rare values read -12% with no variance: a clean path tracer flagged).
    const auto windowStart = [](int v, int lo, int size) { return size < 3 ? lo : std::clamp(v - 1, lo, lo + size - 3); };
    for (int y = g.y; y < g.y + g.height; ++y)
        for (int x = g.x; x < g.x + g.width; ++x) {
            double sumRel = 0, sumS2 = 0, sumM2 = 0;
            int k = 0;
            const int x0 = windowStart(x, g.x, g.width), y0 = windowStart(y, g.y, g.height);
            for (int yy = y0; yy < y0 + 3; ++yy)
                for (int xx = x0; xx < x0 + 3; ++xx) {
                    if ((xx == x && yy == y) || xx < g.x || yy < g.y || xx >= g.x + g.width || yy >= g.y + g.height)
                        continue;
                    const size_t j = size_t(yy) * size_t(W) + size_t(xx);
                    if (!ok[j]) continue;
                    sumRel += rel[j];
                    sumS2 += s2[j];
                    sumM2 += m2[j];
                    ++k;
                }
            if (k == 0) continue;  // NaN: no neighbour to judge by
            const size_t i = size_t(y) * size_t(W) + size_t(x);
            out.meanOfRatios[i] = sumRel / k;
            out.ratioOfSums[i] = sumM2 > 0 ? sumS2 / sumM2 : 0.0;
        }
    return out;
}

}  // namespace bdptref::compare_detail
