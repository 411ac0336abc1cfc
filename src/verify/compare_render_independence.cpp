// Are N plain renders independent? (docs/compare.md, "Renders that share noise"). The spread of N
// renders measures the noise of their mean only when their noise is independent. A renderer that
// seeds each thread's stream with seed + thread index makes the renders of seeds s and s + 1 share
// streams (SmallVCM does: with 2 threads, consecutive seeds share half their samples), and the
// spread then underestimates the noise: correct renders fail the per-pixel test.
#include "verify/compare_internal.h"

#include "bdptref/errors.h"

#include <cmath>
#include <vector>

namespace bdptref::compare_detail {

RenderCorrelation strongestRenderCorrelation(const std::vector<const std::vector<float>*>& sums) {
    // Per pixel, each render's standardised deviation from the renders' mean, z_k = (x_k - m) / s,
    // over the pixels whose renders differ. With independent exchangeable renders E[z_k z_l] =
    // -1 / N for every pair k != l (sum_k z_k = 0 and sum_k z_k^2 = N - 1 give
    // sum_{k != l} z_k z_l = -(N - 1) in every pixel). A pair whose product is higher shares noise.
    RenderCorrelation out;
    const size_t n = sums.size();
    if (n < 3) return out;  // two renders: z_1 = -z_2 in every pixel, nothing to learn
    const size_t pixels = sums[0]->size();
    const double N = double(n);
    std::vector<std::vector<double>> z(n);
    for (size_t i = 0; i < pixels; ++i) {
        double m = 0.0, ss = 0.0;
        for (size_t k = 0; k < n; ++k) m += double((*sums[k])[i]);
        m /= N;
        for (size_t k = 0; k < n; ++k) ss += (double((*sums[k])[i]) - m) * (double((*sums[k])[i]) - m);
        const double s = std::sqrt(ss / (N - 1.0));
        if (!(s > 1e-6 * std::abs(m)) || !std::isfinite(s)) continue;  // deterministic or rounding only
        for (size_t k = 0; k < n; ++k) z[k].push_back((double((*sums[k])[i]) - m) / s);
    }
    out.pixels = z[0].size();
    if (out.pixels < 30) return out;
    const double mPix = double(out.pixels);
    for (size_t k = 0; k < n; ++k)
        for (size_t l = k + 1; l < n; ++l) {
            // The mean product and its standard error from the products' own spread (|z| is at
            // most (N - 1) / sqrt(N), so the products are bounded and their mean is close to normal).
            double sum = 0.0, sum2 = 0.0;
            for (size_t i = 0; i < out.pixels; ++i) {
                const double p = z[k][i] * z[l][i];
                sum += p;
                sum2 += p * p;
            }
            const double mean = sum / mPix;
            const double se = std::sqrt(std::max(0.0, sum2 / mPix - mean * mean) / mPix);
            const double excess = mean + 1.0 / N;
            const double zScore = se > 0 ? excess / se : 0.0;
            if (zScore > out.zScore || out.first < 0) {
                out.first = int(k);
                out.second = int(l);
                out.correlation = mean;
                out.expected = -1.0 / N;
                out.standardError = se;
                out.zScore = zScore;
            }
        }
    return out;
}

void requireIndependentRenders(const std::vector<ExrImage>& renders, const std::vector<std::string>& names) {
    // One value per pixel, R + G + B: the channels share their paths, so one statistic per pixel.
    std::vector<std::vector<float>> sum(renders.size());
    std::vector<const std::vector<float>*> sums;
    for (size_t k = 0; k < renders.size(); ++k) {
        const std::vector<float>&r = renders[k].channels.at("R"), &g = renders[k].channels.at("G"),
                                 &b = renders[k].channels.at("B");
        sum[k].resize(r.size());
        for (size_t i = 0; i < r.size(); ++i) sum[k][i] = r[i] + g[i] + b[i];
        sums.push_back(&sum[k]);
    }
    const RenderCorrelation c = strongestRenderCorrelation(sums);
    // Refused when the excess is both certain (z > 6: with at most a few hundred pairs, independent
    // renders reach it with a chance below 1e-6) and material (> 0.05: the shared noise of such a
    // pair already moves the extreme tail of the per-pixel test).
    if (c.first < 0 || !(c.zScore > kSharedNoiseZ && c.correlation - c.expected > kSharedNoiseExcess)) return;
    auto name = [&](int k) {
        return size_t(k) < names.size() ? names[size_t(k)] : "render " + std::to_string(k + 1);
    };
    throw InputError(
        "test renders " + name(c.first) + " and " + name(c.second) + " share noise: over " +
        std::to_string(c.pixels) + " pixels the product of their standardised deviations from the renders' mean is " +
        fmtG(c.correlation, 3) + ", where independent renders give " + fmtG(c.expected, 3) + " +- " +
        fmtG(c.standardError, 2) + " (z = " + fmtG(c.zScore, 3) +
        "). The spread of renders that share noise underestimates the noise of their mean, so correct renders "
        "would fail. A common cause: a renderer that seeds thread i with seed + i, so that seeds s and s + 1 share "
        "streams; space the seeds by more than the thread count (e.g. 1000, 2000, ...) or render with one thread "
        "(docs/compare.md, 'Renders that share noise')");
}

}  // namespace bdptref::compare_detail
