#include "support/image_stats.h"

#include "bdptref/image_compare.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace bdptref::test {

namespace {

std::string fmt(double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return buf;
}

}  // namespace

// The statistics are the shipped ones (src/verify/image_compare.cpp): one implementation.
double regularizedBeta(double a, double b, double x) {
    return stats::regularizedIncompleteBeta(a, b, std::clamp(x, 0.0, 1.0));
}

double studentTTwoSidedP(double t, double dof) { return stats::studentTTwoSidedP(t, dof); }

double binomialCdf(uint64_t k, uint64_t m, double p) {
    if (k >= m || p <= 0.0) return 1.0;
    if (p >= 1.0) return 0.0;
    const double md = double(m), lp = std::log(p), lq = std::log1p(-p);
    double cdf = 0.0;
    for (uint64_t i = 0; i <= k; ++i) {
        const double id = double(i);
        cdf += std::exp(std::lgamma(md + 1.0) - std::lgamma(id + 1.0) - std::lgamma(md - id + 1.0) + id * lp +
                        (md - id) * lq);
    }
    return std::min(cdf, 1.0);
}

uint64_t binomialQuantile(uint64_t m, double p, double level) {
    if (p <= 0.0) return 0;
    if (p >= 1.0) return m;
    const double md = double(m), lp = std::log(p), lq = std::log1p(-p);
    double cdf = 0.0;
    for (uint64_t q = 0; q < m; ++q) {
        const double qd = double(q);
        cdf += std::exp(std::lgamma(md + 1.0) - std::lgamma(qd + 1.0) - std::lgamma(md - qd + 1.0) + qd * lp +
                        (md - qd) * lq);
        if (cdf >= level) return q;
    }
    return m;
}

double effectiveSamples(double mean, double varianceOfMean, uint64_t count) {
    const double n = double(count), m2 = mean * mean;
    const double denom = (n - 1.0) * varianceOfMean + m2;
    return denom > 0.0 ? n * m2 / denom : 0.0;
}

MomentImage momentsFrom(int width, int height, const std::function<PixelMoments(int, int)>& f) {
    MomentImage img;
    img.width = width;
    img.height = height;
    img.pixels.reserve(size_t(width) * size_t(height));
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) img.pixels.push_back(f(x, y));
    return img;
}

MomentImage momentsOf(const Film& film, const PixelRect& r) {
    if (r.x0 < 0 || r.y0 < 0 || r.x1 > film.width() || r.y1 > film.height() || r.width() <= 0 || r.height() <= 0)
        throw std::invalid_argument("momentsOf: region outside the film");
    return momentsFrom(r.width(), r.height(), [&](int x, int y) {
        PixelMoments m;
        m.mean = film.mean(r.x0 + x, r.y0 + y);
        m.varianceOfMean = film.varianceOfMean(r.x0 + x, r.y0 + y);
        m.count = film.count(r.x0 + x, r.y0 + y);
        return m;
    });
}

MomentImage momentsOf(const Film& film) { return momentsOf(film, PixelRect{0, 0, film.width(), film.height()}); }

MomentImage mergeBlocks(const MomentImage& img, int block) {
    if (block < 1 || img.width % block || img.height % block)
        throw std::invalid_argument("mergeBlocks: the image size must be a multiple of the block size");
    const double k = double(block) * double(block);
    return momentsFrom(img.width / block, img.height / block, [&](int bx, int by) {
        PixelMoments m;
        m.count = img.at(bx * block, by * block).count;
        for (int y = by * block; y < (by + 1) * block; ++y)
            for (int x = bx * block; x < (bx + 1) * block; ++x) {
                const PixelMoments& p = img.at(x, y);
                m.mean += p.mean / k;
                m.varianceOfMean += p.varianceOfMean / (k * k);
                m.count = std::min(m.count, p.count);
            }
        return m;
    });
}

ImageComparison compareImages(const MomentImage& a, const MomentImage& b, double alpha, const std::string& labelA,
                              const std::string& labelB, double minEffectiveSamples) {
    if (a.width != b.width || a.height != b.height)
        throw std::invalid_argument("compareImages: images of different sizes");
    ImageComparison r;
    r.alpha = alpha;
    struct Worst {
        double p;
        int x, y, c;
    };
    std::vector<Worst> worst;
    std::ostringstream mismatches;
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x) {
            const PixelMoments& pa = a.at(x, y);
            const PixelMoments& pb = b.at(x, y);
            ++r.pixels;
            if (pa.count < 2 || pb.count < 2) {
                ++r.skipped;
                continue;
            }
            double p[3];
            int k = 0, lowHere = 0;
            for (int c = 0; c < 3; ++c) {
                const double va = pa.varianceOfMean[c], vb = pb.varianceOfMean[c];
                p[c] = -1.0;
                if (va == 0.0 && vb == 0.0) {
                    if (pa.mean[c] != pb.mean[c]) {
                        if (r.exactMismatches < 5)
                            mismatches << " [(" << x << "," << y << ") channel " << c << ": " << labelA << " "
                                       << fmt(pa.mean[c]) << " vs " << labelB << " " << fmt(pb.mean[c])
                                       << ", both with zero variance]";
                        ++r.exactMismatches;
                    }
                    continue;
                }
                if (effectiveSamples(pa.mean[c], va, pa.count) < minEffectiveSamples ||
                    effectiveSamples(pb.mean[c], vb, pb.count) < minEffectiveSamples) {
                    ++r.lowEffectiveChannels;
                    ++lowHere;
                    continue;
                }
                const double na = double(pa.count), nb = double(pb.count);
                const double t = (pa.mean[c] - pb.mean[c]) / std::sqrt(va + vb);
                const double nu = (va + vb) * (va + vb) / (va * va / (na - 1.0) + vb * vb / (nb - 1.0));
                p[c] = studentTTwoSidedP(t, nu);
                r.minP = std::min(r.minP, p[c]);
                ++k;
            }
            if (k == 0) {
                if (lowHere > 0)
                    ++r.lowEffective;
                else
                    ++r.exactOnly;
                continue;
            }
            ++r.tested;
            double pMin = 1.0;
            int cMin = 0;
            for (int c = 0; c < 3; ++c)
                if (p[c] >= 0.0 && p[c] < pMin) {
                    pMin = p[c];
                    cMin = c;
                }
            if (pMin < alpha / double(k)) ++r.rejected;
            worst.push_back({pMin, x, y, cMin});
        }
    r.bound = binomialQuantile(r.tested, alpha, kBinomialLevel);

    std::ostringstream rep;
    rep << labelA << " vs " << labelB << ": " << r.pixels << " pixels, " << r.tested << " t-tested, " << r.exactOnly
        << " zero-variance (equality only), " << r.lowEffective << " with fewer than " << minEffectiveSamples
        << " effective samples (" << r.lowEffectiveChannels << " channels), " << r.skipped
        << " skipped; rejected at alpha " << alpha << ": "
        << r.rejected << " (binomial bound " << r.bound << ", expected " << fmt(alpha * double(r.tested))
        << "); exact mismatches: " << r.exactMismatches << (r.passed() ? " -> PASS" : " -> FAIL");
    if (r.exactMismatches) rep << "\n  zero-variance mismatches:" << mismatches.str();
    std::sort(worst.begin(), worst.end(), [](const Worst& u, const Worst& v) { return u.p < v.p; });
    if (!worst.empty()) rep << "\n  worst pixels:";
    for (size_t i = 0; i < std::min<size_t>(6, worst.size()); ++i) {
        const Worst& w = worst[i];
        const PixelMoments& pa = a.at(w.x, w.y);
        const PixelMoments& pb = b.at(w.x, w.y);
        rep << "\n    (" << w.x << "," << w.y << ") channel " << w.c << ": " << labelA << " " << fmt(pa.mean[w.c])
            << " +- " << fmt(std::sqrt(pa.varianceOfMean[w.c])) << ", " << labelB << " " << fmt(pb.mean[w.c]) << " +- "
            << fmt(std::sqrt(pb.varianceOfMean[w.c])) << ", p = " << fmt(w.p);
    }
    r.report = rep.str();
    return r;
}

ImageComparison compareFilms(const Film& a, const Film& b, double alpha, const std::string& labelA,
                             const std::string& labelB) {
    return compareImages(momentsOf(a), momentsOf(b), alpha, labelA, labelB);
}

ImageComparison compareFilmRegions(const Film& a, const PixelRect& ra, const Film& b, const PixelRect& rb,
                                   double alpha, const std::string& labelA, const std::string& labelB) {
    if (ra.width() != rb.width() || ra.height() != rb.height())
        throw std::invalid_argument("compareFilmRegions: regions of different sizes");
    return compareImages(momentsOf(a, ra), momentsOf(b, rb), alpha, labelA, labelB);
}

}  // namespace bdptref::test
