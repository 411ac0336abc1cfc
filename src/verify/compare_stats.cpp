// The distributions of the comparison (include/bdptref/image_compare.h, namespace stats): Student's t
// through the regularised incomplete beta function (continued fraction), the normal distribution and
// its quantile, Sidak's correction and the Cauchy combination test. docs/compare.md says why these are
// hand-written rather than taken from Boost.Math.
#include "bdptref/image_compare.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace bdptref {

namespace stats {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kPiD = 3.14159265358979323846;

// log B(a, b) = lgamma(a) + lgamma(b) - lgamma(a + b). std::lgamma may write the global signgam;
// the comparison calls it from one thread only.
double logBeta(double a, double b) { return std::lgamma(a) + std::lgamma(b) - std::lgamma(a + b); }

// Continued fraction of I_x(a, b) (modified Lentz; Numerical Recipes 3rd ed., section 6.4); it
// converges quickly for x < (a + 1) / (a + b + 2).
double betaContinuedFraction(double a, double b, double x) {
    const double tiny = 1e-300;
    const double qab = a + b, qap = a + 1.0, qam = a - 1.0;
    double c = 1.0, d = 1.0 - qab * x / qap;
    if (std::abs(d) < tiny) d = tiny;
    d = 1.0 / d;
    double h = d;
    for (int m = 1; m < 200000; ++m) {
        const double m2 = 2.0 * m;
        double aa = m * (b - m) * x / ((qam + m2) * (a + m2));
        d = 1.0 + aa * d;
        if (std::abs(d) < tiny) d = tiny;
        c = 1.0 + aa / c;
        if (std::abs(c) < tiny) c = tiny;
        d = 1.0 / d;
        h *= d * c;
        aa = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2));
        d = 1.0 + aa * d;
        if (std::abs(d) < tiny) d = tiny;
        c = 1.0 + aa / c;
        if (std::abs(c) < tiny) c = tiny;
        d = 1.0 / d;
        const double del = d * c;
        h *= del;
        if (std::abs(del - 1.0) < 1e-15) break;
    }
    return h;
}

// I_x(a, b) with y = 1 - x passed separately (exact when x is close to 1).
double betaI(double a, double b, double x, double y) {
    if (!(a > 0.0) || !(b > 0.0) || std::isnan(x) || std::isnan(y)) return std::numeric_limits<double>::quiet_NaN();
    if (x <= 0.0) return 0.0;
    if (y <= 0.0) return 1.0;
    const double logFront = a * std::log(x) + b * std::log(y) - logBeta(a, b);
    if (x < (a + 1.0) / (a + b + 2.0)) return std::exp(logFront) * betaContinuedFraction(a, b, x) / a;
    return 1.0 - std::exp(logFront) * betaContinuedFraction(b, a, y) / b;
}

}  // namespace

double regularizedIncompleteBeta(double a, double b, double x) {
    x = std::clamp(x, 0.0, 1.0);
    return std::clamp(betaI(a, b, x, 1.0 - x), 0.0, 1.0);
}

double normalTwoSidedP(double z) {
    if (std::isnan(z)) return std::numeric_limits<double>::quiet_NaN();
    return std::erfc(std::abs(z) / std::sqrt(2.0));
}

double studentTTwoSidedP(double t, double dof) {
    if (std::isnan(t) || !(dof > 0.0)) return std::numeric_limits<double>::quiet_NaN();
    if (std::isinf(t)) return 0.0;
    // Beyond 1e5 degrees of freedom Student's t and the normal differ by < 1e-3 relative in the
    // two-sided tail up to |t| = 6, and the continued fraction would need ~sqrt(dof) terms.
    if (dof > 1e5) return normalTwoSidedP(t);
    const double t2 = t * t;
    // P(|T| >= |t|) = I_{nu / (nu + t^2)}(nu / 2, 1 / 2), both arguments without cancellation.
    return std::clamp(betaI(0.5 * dof, 0.5, dof / (dof + t2), t2 / (dof + t2)), 0.0, 1.0);
}

double normalQuantile(double p) {
    if (std::isnan(p) || p < 0.0 || p > 1.0) return std::numeric_limits<double>::quiet_NaN();
    if (p == 0.0) return -kInf;
    if (p == 1.0) return kInf;
    // Acklam's rational approximation (relative error < 1.2e-9) and one Halley step on erfc.
    static const double a[6] = {-3.969683028665376e+01, 2.209460984245205e+02, -2.759285104469687e+02,
                                1.383577518672690e+02,  -3.066479806614716e+01, 2.506628277459239e+00};
    static const double b[5] = {-5.447609879822406e+01, 1.615858368580409e+02, -1.556989798598866e+02,
                                6.680131188771972e+01,  -1.328068155288572e+01};
    static const double c[6] = {-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e+00,
                                -2.549732539343734e+00, 4.374664141464968e+00,  2.938163982698783e+00};
    static const double d[4] = {7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e+00,
                                3.754408661907416e+00};
    const double pLow = 0.02425;
    double x;
    if (p < pLow) {
        const double q = std::sqrt(-2.0 * std::log(p));
        x = (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
            ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1.0);
    } else if (p <= 1.0 - pLow) {
        const double q = p - 0.5, r = q * q;
        x = (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
            (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1.0);
    } else {
        const double q = std::sqrt(-2.0 * std::log1p(-p));
        x = -(((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
            ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1.0);
    }
    // Halley refinement: e = Phi(x) - p, computed on the side where it does not cancel.
    const double e = x < 0 ? 0.5 * std::erfc(-x / std::sqrt(2.0)) - p : (1.0 - p) - 0.5 * std::erfc(x / std::sqrt(2.0));
    const double u = e * std::sqrt(2.0 * kPiD) * std::exp(0.5 * x * x);
    const double refined = x - u / (1.0 + 0.5 * x * u);
    return std::isfinite(refined) ? refined : x;
}

double zFromTwoSidedP(double p) {
    if (std::isnan(p)) return std::numeric_limits<double>::quiet_NaN();
    if (p <= 0.0) return 40.0;  // beyond any double-precision p-value (p(40) ~ 1e-350)
    if (p >= 1.0) return 0.0;
    return -normalQuantile(0.5 * p);
}

double sidak(double p, double m) {
    if (std::isnan(p)) return p;
    if (p <= 0.0) return 0.0;
    if (p >= 1.0 || m <= 0.0) return std::min(1.0, std::max(0.0, p));
    return std::min(1.0, -std::expm1(m * std::log1p(-p)));
}

double cauchyCombination(const double* p, int k) {
    if (k <= 0) return 1.0;
    if (k == 1) return p[0];
    for (int i = 0; i < k; ++i)
        if (p[i] <= 0.0) return 0.0;  // a p-value of exactly 0 (underflow) decides
    // T = sum w_i tan((1/2 - p_i) pi), w_i = 1/k; p = 1/2 - atan(T) / pi. For small p_i,
    // tan((1/2 - p) pi) = 1 / tan(p pi); for large T, 1/2 - atan(T)/pi = atan(1/T)/pi.
    double T = 0.0;
    for (int i = 0; i < k; ++i) {
        const double pi = std::clamp(p[i], 1e-300, 1.0 - 1e-16);
        T += (pi < 1e-15 ? 1.0 / (pi * kPiD) : 1.0 / std::tan(pi * kPiD)) / double(k);
    }
    if (T > 1e15) return std::min(1.0, 1.0 / (T * kPiD));
    if (T > 0) return std::atan(1.0 / T) / kPiD;
    return std::clamp(0.5 - std::atan(T) / kPiD, 0.0, 1.0);
}

}  // namespace stats

}  // namespace bdptref
