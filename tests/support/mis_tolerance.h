// The float32 error bound for comparing two evaluations of the same MIS weights (derivation in
// tests/unit/test_mis.cpp's header): a density factor of edge (a, b) carries a relative error of
// at most 2^-24 (32 + 4/|cos_a| + 4/|cos_b|), each edge enters a density ratio at most twice, and a
// weight's relative error is at most max(b, 1) times the sum.
#pragma once

#include "bdptref/path_vertex.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace bdptref::test {

// |cos| of direction w at vertex v (the smaller of the geometric and shading cosines; 1 where v
// has no surface), floored so a grazing edge gives a large but finite error budget.
inline double cosForBudget(const PathVertex& v, const DVec3& w) {
    if (!v.isOnSurface()) return 1.0;
    const double cg = std::abs(glm::dot(DVec3(v.ng), w)), cs = std::abs(glm::dot(DVec3(v.ns), w));
    return std::max(std::min(cg, cs), 1e-6);
}

// Relative tolerance for one weight of the camera-first path x under heuristic exponent b.
inline double misRelativeTolerance(const std::vector<PathVertex>& x, double exponent) {
    double sum = 0.0;
    for (size_t k = 0; k + 1 < x.size(); ++k) {
        const PathVertex &a = x[k], &b = x[k + 1];
        DVec3 w = b.infinite ? DVec3(b.ng) : DVec3(b.p) - DVec3(a.p);
        if (glm::dot(w, w) > 0.0) w = glm::normalize(w);
        sum += 2.0 * 0x1p-24 * (32.0 + 4.0 / cosForBudget(a, w) + 4.0 / cosForBudget(b, w));
    }
    return std::max(exponent, 1.0) * sum;
}

}  // namespace bdptref::test
