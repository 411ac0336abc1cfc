// Kolmogorov-Smirnov checks of p-values against Uniform(0, 1), for the calibration tests of
// compare (tests/unit/test_compare.cpp, test_compare_calibration.cpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace bdptref::test {

// D = sup |F_n(x) - x| over the sample.
inline double ksStatistic(std::vector<double> u) {
    std::sort(u.begin(), u.end());
    const double n = double(u.size());
    double d = 0;
    for (size_t i = 0; i < u.size(); ++i) d = std::max({d, double(i + 1) / n - u[i], u[i] - double(i) / n});
    return d;
}

// Asymptotic p-value Q_KS(lambda) = 2 sum_{k>=1} (-1)^(k-1) exp(-2 k^2 lambda^2) with Stephens'
// small-sample correction lambda = (sqrt(n) + 0.12 + 0.11 / sqrt(n)) D (Numerical Recipes 14.3).
inline double ksPValue(double d, size_t n) {
    const double sn = std::sqrt(double(n));
    const double lambda = (sn + 0.12 + 0.11 / sn) * d;
    if (lambda < 0.2) return 1.0;
    double q = 0, sign = 1;
    for (int k = 1; k <= 200; ++k) {
        const double term = sign * std::exp(-2.0 * k * k * lambda * lambda);
        q += term;
        if (std::abs(term) < 1e-16) break;
        sign = -sign;
    }
    return std::clamp(2.0 * q, 0.0, 1.0);
}

// One-sided D+ = max(F_n(x) - x): how far the p-values lean towards 0, i.e. towards false alarms.
// (A conservative test, p-values leaning towards 1, is a loss of power, not a false alarm.)
inline double ksPlus(std::vector<double> u) {
    std::sort(u.begin(), u.end());
    const double n = double(u.size());
    double d = 0;
    for (size_t i = 0; i < u.size(); ++i) d = std::max(d, double(i + 1) / n - u[i]);
    return d;
}

// D+'s critical value at level 0.01: sqrt(-ln(0.01) / 2) = 1.5174 over sqrt(n) (asymptotic, with
// Stephens' small-sample correction; 0.27 for 30 values, 0.19 for 60).
inline double ksPlusCritical01(size_t n) {
    const double sn = std::sqrt(double(n));
    return 1.5174 / (sn + 0.12 + 0.11 / sn);
}

}  // namespace bdptref::test
