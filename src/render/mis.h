// Small MIS helpers shared by the unidirectional estimators.
#pragma once

#include <cmath>

namespace bdptref {

// Power heuristic with beta = 2 for one sample from each of two strategies (Veach 1997, 9.2.4).
// Written in double so huge or tiny densities neither overflow nor produce NaN.
inline float powerHeuristic(float pdfThis, float pdfOther) {
    const double a = double(pdfThis), b = double(pdfOther);
    if (!(a > 0.0)) return 0.f;
    if (std::isinf(a)) return std::isinf(b) ? 0.5f : 1.f;
    const double aa = a * a, bb = b * b;
    return float(aa / (aa + bb));
}

}  // namespace bdptref
