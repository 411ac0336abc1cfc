#include "support/chi2.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <numeric>
#include <sstream>

namespace bdptref {
namespace test {

namespace {

constexpr double kPiD = 3.14159265358979323846;
constexpr double kMinExpected = 5.0;

// Series for P(a, x), good for x < a + 1 (Numerical Recipes 3rd ed., 6.2.5).
double gammaPSeries(double a, double x) {
    double ap = a, del = 1.0 / a, sum = del;
    for (int i = 0; i < 100000; ++i) {
        ap += 1.0;
        del *= x / ap;
        sum += del;
        if (std::abs(del) < std::abs(sum) * 1e-16) break;
    }
    return sum * std::exp(-x + a * std::log(x) - std::lgamma(a));
}

// Continued fraction for Q(a, x), good for x >= a + 1 (modified Lentz; NR 6.2.7).
double gammaQContinuedFraction(double a, double x) {
    const double tiny = 1e-300;
    double b = x + 1.0 - a, c = 1.0 / tiny, d = 1.0 / b, h = d;
    for (int i = 1; i < 100000; ++i) {
        const double an = -i * (i - a);
        b += 2.0;
        d = an * d + b;
        if (std::abs(d) < tiny) d = tiny;
        c = b + an / c;
        if (std::abs(c) < tiny) c = tiny;
        d = 1.0 / d;
        const double del = d * c;
        h *= del;
        if (std::abs(del - 1.0) < 1e-16) break;
    }
    return std::exp(-x + a * std::log(x) - std::lgamma(a)) * h;
}

// Cell integrals: error-controlled adaptive midpoint quadrature. A cell's integral is estimated
// on a kGrid x kGrid midpoint grid and again as the sum of its four quarters (each on the same
// grid); where the two differ by more than the tolerance the quarters are refined recursively
// (tolerance halved per level, depth-limited). This resolves narrow lobes, ridges and support
// boundaries (horizons) that a fixed grid gets wrong by several percent.
constexpr int kGrid = 8;
constexpr int kMaxDepth = 10;

template <class G>
double midpointRule(const G& g, double a0, double a1, double b0, double b1) {
    const double da = (a1 - a0) / kGrid, db = (b1 - b0) / kGrid;
    double sum = 0.0;
    for (int i = 0; i < kGrid; ++i) {
        const double a = a0 + (i + 0.5) * da;
        for (int j = 0; j < kGrid; ++j) {
            const double v = g(a, b0 + (j + 0.5) * db);
            if (std::isfinite(v) && v > 0.0) sum += v;
        }
    }
    return sum * da * db;
}

template <class G>
double adaptiveRule(const G& g, double a0, double a1, double b0, double b1, double whole, double tol, int depth) {
    const double am = 0.5 * (a0 + a1), bm = 0.5 * (b0 + b1);
    const double q[4] = {midpointRule(g, a0, am, b0, bm), midpointRule(g, am, a1, b0, bm),
                         midpointRule(g, a0, am, bm, b1), midpointRule(g, am, a1, bm, b1)};
    const double fine = q[0] + q[1] + q[2] + q[3];
    if (depth <= 0 || std::abs(fine - whole) <= tol) return fine;
    return adaptiveRule(g, a0, am, b0, bm, q[0], 0.5 * tol, depth - 1) +
           adaptiveRule(g, am, a1, b0, bm, q[1], 0.5 * tol, depth - 1) +
           adaptiveRule(g, a0, am, bm, b1, q[2], 0.5 * tol, depth - 1) +
           adaptiveRule(g, am, a1, bm, b1, q[3], 0.5 * tol, depth - 1);
}

// Integral of g over [a0,a1] x [b0,b1] (a probability, for n samples) to an absolute accuracy of
// 0.02 standard errors of the cell's count: an error that adds at most 0.02^2 per cell to the
// expected chi-square statistic (negligible against its dof).
template <class G>
double integrateCell(const G& g, double a0, double a1, double b0, double b1, uint64_t n) {
    const double whole = midpointRule(g, a0, a1, b0, b1);
    const double nd = double(n);
    const double tol = 0.02 * std::sqrt(std::max(whole, 1.0 / nd) / nd);
    return adaptiveRule(g, a0, a1, b0, b1, whole, tol, kMaxDepth);
}

std::string fmt(double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return buf;
}

Chi2Result hardFailure(const std::string& why) {
    Chi2Result r;
    r.pValue = 0.0;
    r.statistic = std::numeric_limits<double>::infinity();
    r.dof = 0;
    r.report = "chi2 hard failure: " + why;
    return r;
}

// Pearson's test with Cochran pooling. labels[i] names cell i in the report. With strictZero, a
// cell with expected <= 0 and observed > 0 is a hard failure; otherwise such a cell (which the
// caller has shown to be legitimate, e.g. a lobe sliver the integration grid missed) is pooled.
Chi2Result pearson(const std::vector<double>& observed, const std::vector<double>& expected,
                   const std::vector<std::string>& labels, double minExpected, bool strictZero,
                   const std::string& preamble) {
    const size_t n = observed.size();
    if (expected.size() != n) return hardFailure("observed and expected have different sizes");
    std::ostringstream rep;
    rep << preamble;
    if (strictZero) {
        for (size_t i = 0; i < n; ++i) {
            if (!(expected[i] > 0.0) && observed[i] > 0.0) {
                return hardFailure(preamble + "; " + fmt(observed[i]) + " samples in cell " + labels[i] +
                                   " whose expected count is " + fmt(expected[i]));
            }
        }
    }
    std::vector<size_t> order(n);
    std::iota(order.begin(), order.end(), size_t(0));
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return expected[a] < expected[b]; });
    struct Cell {
        double o, e;
        std::string label;
    };
    std::vector<Cell> cells;
    double poolO = 0.0, poolE = 0.0;
    int pooledCells = 0;
    for (size_t k = 0; k < n; ++k) {
        const size_t i = order[k];
        const double e = std::max(0.0, expected[i]);
        if (e < minExpected) {
            poolO += observed[i];
            poolE += e;
            ++pooledCells;
        } else {
            cells.push_back({observed[i], e, labels[i]});
        }
    }
    if (pooledCells > 0 && (poolO > 0.0 || poolE > 0.0)) {
        const std::string poolLabel = "pool of " + std::to_string(pooledCells) + " cells";
        if (poolE >= minExpected || cells.empty()) {
            cells.push_back({poolO, poolE, poolLabel});
        } else {
            // `cells` is in ascending order of expected count: merge into the smallest.
            cells.front().o += poolO;
            cells.front().e += poolE;
            cells.front().label += " + " + poolLabel;
        }
    }
    Chi2Result r;
    double stat = 0.0;
    std::vector<std::pair<double, size_t>> contributions;
    for (size_t k = 0; k < cells.size(); ++k) {
        if (!(cells[k].e > 0.0)) {
            return hardFailure(preamble + "; " + fmt(cells[k].o) + " samples where nothing is expected (" +
                               cells[k].label + ")");
        }
        const double c = (cells[k].o - cells[k].e) * (cells[k].o - cells[k].e) / cells[k].e;
        stat += c;
        contributions.push_back({c, k});
    }
    r.statistic = stat;
    r.dof = int(cells.size()) - 1;
    r.pValue = chi2Survival(stat, r.dof);
    rep << "; chi2 = " << fmt(stat) << ", dof = " << r.dof << ", p = " << fmt(r.pValue);
    if (r.dof <= 0) rep << " (too few cells for a test)";
    std::sort(contributions.begin(), contributions.end(),
              [](const std::pair<double, size_t>& a, const std::pair<double, size_t>& b) { return a.first > b.first; });
    rep << "; largest contributions:";
    for (size_t k = 0; k < std::min<size_t>(5, contributions.size()); ++k) {
        const Cell& c = cells[contributions[k].second];
        rep << " [" << c.label << ": observed " << fmt(c.o) << ", expected " << fmt(c.e) << "]";
    }
    // BDPTREF_CHI2_VERBOSE=1 in the environment lists every cell (for debugging a failure).
    const char* verbose = std::getenv("BDPTREF_CHI2_VERBOSE");
    if (verbose && verbose[0] == '1') {
        rep << "\nall cells (before pooling):";
        for (size_t i = 0; i < n; ++i) {
            rep << "\n  " << labels[i] << ": observed " << fmt(observed[i]) << ", expected " << fmt(expected[i]);
        }
    }
    r.report = rep.str();
    return r;
}

}  // namespace

double sidakAlpha(double familyAlpha, int numTests) {
    if (numTests <= 1) return familyAlpha;
    // 1 - (1 - a)^(1/m), written with log1p/expm1 to keep its precision for small a.
    return -std::expm1(std::log1p(-familyAlpha) / double(numTests));
}

double regularizedGammaP(double a, double x) {
    if (!(a > 0.0) || !(x > 0.0)) return 0.0;
    if (std::isinf(x)) return 1.0;
    return x < a + 1.0 ? gammaPSeries(a, x) : 1.0 - gammaQContinuedFraction(a, x);
}

double regularizedGammaQ(double a, double x) {
    if (!(a > 0.0) || !(x > 0.0)) return 1.0;
    if (std::isinf(x)) return 0.0;
    return x < a + 1.0 ? 1.0 - gammaPSeries(a, x) : gammaQContinuedFraction(a, x);
}

double chi2Survival(double statistic, int dof) {
    if (dof <= 0) return 1.0;
    if (std::isnan(statistic)) return 0.0;
    return regularizedGammaQ(0.5 * dof, 0.5 * statistic);
}

Chi2Result chi2FromCounts(const std::vector<double>& observed, const std::vector<double>& expected,
                          double minExpected) {
    std::vector<std::string> labels(observed.size());
    for (size_t i = 0; i < labels.size(); ++i) labels[i] = "cell " + std::to_string(i);
    return pearson(observed, expected, labels, minExpected, true, "counts");
}

Chi2Result chi2DirectionTest(const DirectionSampler& sample, const DirectionPdf& pdf, uint64_t n, int thetaBins,
                             int phiBins) {
    DirectionBinning b;
    b.thetaBins = thetaBins;
    b.phiBins = phiBins;
    return chi2DirectionTest(sample, pdf, n, b);
}

Chi2Result chi2DirectionTest(const DirectionSampler& sample, const DirectionPdf& pdf, uint64_t n,
                             const DirectionBinning& binning) {
    const int T = binning.thetaBins, P = binning.phiBins;
    const bool logBins = binning.theta == ThetaBinning::LogOneMinusCos;
    if (T < (logBins ? 2 : 1) || P < 1 || n == 0) return hardFailure("invalid binning or sample count");
    if (logBins && !(binning.minOneMinusCos > 0.0 && binning.minOneMinusCos < 2.0)) {
        return hardFailure("minOneMinusCos must be in (0, 2)");
    }
    const glm::dvec3 fs(binning.frame.s), ft(binning.frame.t), fn(binning.frame.n);
    const double logMin = logBins ? std::log(binning.minOneMinusCos) : 0.0;
    const double logMax = std::log(2.0);
    const double dPhi = 2.0 * kPiD / P;

    // theta-bin boundaries in the binning variable: cos(theta) for UniformCos; for
    // LogOneMinusCos bin 0 is 1 - cos in [0, minOneMinusCos], bin i >= 1 is log(1 - cos) in
    // [logMin + (i-1) d, logMin + i d].
    auto thetaBinOf = [&](double z, double oneMinusCos) {
        if (!logBins) return std::min(T - 1, std::max(0, int((z + 1.0) * 0.5 * T)));
        if (oneMinusCos < binning.minOneMinusCos) return 0;
        const int i = 1 + int((std::log(oneMinusCos) - logMin) / (logMax - logMin) * (T - 1));
        return std::min(T - 1, std::max(1, i));
    };

    // Histogram.
    const size_t cellsN = size_t(T) * size_t(P);
    std::vector<double> observed(cellsN + 1, 0.0);  // last cell: lost samples
    uint64_t zeroPdf = 0, badDir = 0;
    std::string firstProblem;
    for (uint64_t i = 0; i < n; ++i) {
        Vec3 d;
        if (!sample(i, &d)) {
            observed[cellsN] += 1.0;
            continue;
        }
        const glm::dvec3 dd(d);
        const double len = glm::length(dd);
        if (!isFinite(d) || std::abs(len - 1.0) > 1e-3) {
            if (badDir++ == 0) firstProblem = "sample " + std::to_string(i) + " is not a unit vector";
            continue;
        }
        const double p = pdf(d);
        if (!(p > 0.0) || !std::isfinite(p)) {
            if (zeroPdf++ == 0) {
                firstProblem = "sample " + std::to_string(i) + " (" + fmt(d.x) + ", " + fmt(d.y) + ", " + fmt(d.z) +
                               ") has pdf " + fmt(p);
            }
            continue;
        }
        const double x = glm::dot(dd, fs) / len, y = glm::dot(dd, ft) / len, z = glm::dot(dd, fn) / len;
        const double oneMinusCos = z > 0.0 ? (x * x + y * y) / (1.0 + z) : 1.0 - z;
        double phi = std::atan2(y, x);
        if (phi < 0.0) phi += 2.0 * kPiD;
        const int ti = thetaBinOf(z, oneMinusCos);
        const int pi = std::min(P - 1, std::max(0, int(phi / dPhi)));
        observed[size_t(ti) * size_t(P) + size_t(pi)] += 1.0;
    }
    if (badDir > 0 || zeroPdf > 0) {
        return hardFailure(std::to_string(badDir) + " non-unit directions and " + std::to_string(zeroPdf) +
                           " samples with pdf <= 0 or not finite; first: " + firstProblem);
    }

    // Expected counts: adaptive quadrature in (binning variable, phi) per cell.
    std::vector<double> expected(cellsN + 1, 0.0);
    std::vector<std::string> labels(cellsN + 1);
    double integral = 0.0;
    for (int ti = 0; ti < T; ++ti) {
        // The cell's range in the binning variable v, and z(v) with d(omega) = jac(v) dv dphi.
        double v0, v1;
        if (!logBins) {
            v0 = -1.0 + 2.0 * ti / T;
            v1 = -1.0 + 2.0 * (ti + 1) / T;
        } else if (ti == 0) {
            v0 = 0.0;  // v = 1 - cos
            v1 = binning.minOneMinusCos;
        } else {
            const double d = (logMax - logMin) / (T - 1);  // v = log(1 - cos)
            v0 = logMin + (ti - 1) * d;
            v1 = logMin + ti * d;
        }
        auto density = [&](double v, double phi) {
            double z, jac;
            if (!logBins) {
                z = v;
                jac = 1.0;
            } else if (ti == 0) {
                z = 1.0 - v;
                jac = 1.0;
            } else {
                const double u = std::exp(v);
                z = 1.0 - u;
                jac = u;
            }
            z = std::min(1.0, std::max(-1.0, z));
            const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
            const glm::dvec3 w = fs * (r * std::cos(phi)) + ft * (r * std::sin(phi)) + fn * z;
            return pdf(Vec3(glm::normalize(w))) * jac;
        };
        for (int pi = 0; pi < P; ++pi) {
            const double sum = integrateCell(density, v0, v1, pi * dPhi, (pi + 1) * dPhi, n);
            const size_t c = size_t(ti) * size_t(P) + size_t(pi);
            expected[c] = double(n) * sum;
            integral += sum;
            labels[c] = "theta bin " + std::to_string(ti) + ", phi bin " + std::to_string(pi);
        }
    }
    labels[cellsN] = "lost (failed or delta samples)";
    std::ostringstream pre;
    pre << "n = " << n << ", pdf integral = " << fmt(integral) << ", lost samples " << fmt(observed[cellsN])
        << " vs expected " << fmt(double(n) * std::max(0.0, 1.0 - integral));
    if (integral > 1.0 + 1e-3) return hardFailure(pre.str() + "; the pdf integrates to more than 1");
    expected[cellsN] = double(n) * std::max(0.0, 1.0 - integral);
    // Every binned sample had pdf > 0 (checked above), so a cell whose grid integral is 0 holds
    // samples from a sliver of support the grid missed: pool it rather than fail.
    return pearson(observed, expected, labels, kMinExpected, false, pre.str());
}

Chi2Result chi2Test2D(const PointSampler& sample, const PointPdf& pdf, uint64_t n, int xBins, int yBins, Vec2 lo,
                      Vec2 hi) {
    if (xBins < 1 || yBins < 1 || n == 0 || !(hi.x > lo.x) || !(hi.y > lo.y)) {
        return hardFailure("invalid binning, domain or sample count");
    }
    const double x0 = lo.x, y0 = lo.y, dx = (double(hi.x) - x0) / xBins, dy = (double(hi.y) - y0) / yBins;
    const size_t cellsN = size_t(xBins) * size_t(yBins);
    std::vector<double> observed(cellsN + 1, 0.0);
    uint64_t problems = 0;
    std::string firstProblem;
    for (uint64_t i = 0; i < n; ++i) {
        Vec2 p;
        if (!sample(i, &p)) {
            observed[cellsN] += 1.0;
            continue;
        }
        const double density = pdf(p);
        const bool inside = p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y;
        if (!inside || !(density > 0.0) || !std::isfinite(density)) {
            if (problems++ == 0) {
                firstProblem = "sample " + std::to_string(i) + " (" + fmt(p.x) + ", " + fmt(p.y) + ") " +
                               (inside ? "has pdf " + fmt(density) : "is outside the domain");
            }
            continue;
        }
        const int xi = std::min(xBins - 1, std::max(0, int((p.x - x0) / dx)));
        const int yi = std::min(yBins - 1, std::max(0, int((p.y - y0) / dy)));
        observed[size_t(yi) * size_t(xBins) + size_t(xi)] += 1.0;
    }
    if (problems > 0) {
        return hardFailure(std::to_string(problems) + " samples outside the domain or with pdf <= 0; first: " +
                           firstProblem);
    }
    std::vector<double> expected(cellsN + 1, 0.0);
    std::vector<std::string> labels(cellsN + 1);
    double integral = 0.0;
    for (int yi = 0; yi < yBins; ++yi) {
        for (int xi = 0; xi < xBins; ++xi) {
            auto density = [&](double x, double y) { return pdf(Vec2(float(x), float(y))); };
            const double sum = integrateCell(density, x0 + xi * dx, x0 + (xi + 1) * dx, y0 + yi * dy,
                                             y0 + (yi + 1) * dy, n);
            const size_t c = size_t(yi) * size_t(xBins) + size_t(xi);
            expected[c] = double(n) * sum;
            integral += sum;
            labels[c] = "x bin " + std::to_string(xi) + ", y bin " + std::to_string(yi);
        }
    }
    labels[cellsN] = "lost (failed samples)";
    std::ostringstream pre;
    pre << "n = " << n << ", pdf integral = " << fmt(integral) << ", lost samples " << fmt(observed[cellsN])
        << " vs expected " << fmt(double(n) * std::max(0.0, 1.0 - integral));
    if (integral > 1.0 + 1e-3) return hardFailure(pre.str() + "; the pdf integrates to more than 1");
    expected[cellsN] = double(n) * std::max(0.0, 1.0 - integral);
    return pearson(observed, expected, labels, kMinExpected, false, pre.str());
}

Chi2Result chi2DiscreteTest(const std::function<bool(uint64_t sampleIndex, size_t* index)>& sample,
                            const std::vector<double>& pmf, uint64_t n) {
    const size_t k = pmf.size();
    std::vector<double> observed(k + 1, 0.0), expected(k + 1, 0.0);
    std::vector<std::string> labels(k + 1);
    double total = 0.0;
    for (size_t i = 0; i < k; ++i) {
        expected[i] = double(n) * pmf[i];
        total += pmf[i];
        labels[i] = "index " + std::to_string(i);
    }
    if (total > 1.0 + 1e-6) return hardFailure("the pmf sums to " + fmt(total) + " > 1");
    expected[k] = double(n) * std::max(0.0, 1.0 - total);
    labels[k] = "lost (failed samples)";
    for (uint64_t i = 0; i < n; ++i) {
        size_t idx = 0;
        if (!sample(i, &idx)) {
            observed[k] += 1.0;
        } else if (idx >= k) {
            return hardFailure("sample " + std::to_string(i) + " returned index " + std::to_string(idx) +
                               " >= " + std::to_string(k));
        } else {
            observed[idx] += 1.0;
        }
    }
    return pearson(observed, expected, labels, kMinExpected, true, "n = " + std::to_string(n));
}

}  // namespace test
}  // namespace bdptref
