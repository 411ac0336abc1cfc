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

// A density raised to the heuristic's exponent b (docs/mis.md, "The recursive form"): p^b, with
// the uniform heuristic's b = 0 read as "is this strategy possible": 1 for p > 0, 0 for p = 0.
// p = 0 (or NaN) gives 0 for every b. The common exponents skip the libm call (p * p is the
// correctly rounded square, as pow(p, 2)).
inline double misPower(double p, double b) {
    if (!(p > 0.0)) return 0.0;
    return b == 1.0 ? p : b == 2.0 ? p * p : b == 0.0 ? 1.0 : std::pow(p, b);
}

}  // namespace bdptref
