// Sizing validate's renders to its budget (docs/validate.md, "Budget and samples"): the pilots'
// sample counts and the cost line through them, how many renders a scene's share affords, how many samples per render its reference says a verdict needs, and how
// the suite's budget is shared so that every scene gets what its verdict costs.
#include "verify/compare_internal.h"
#include "verify/validate.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace bdptref {

int rendersForBudget(double shareSeconds, double fixedSeconds, int maxRenders) {
    const int least = std::min(4, maxRenders);
    for (int n = maxRenders; n > least; --n)
        if (double(n) * fixedSeconds <= 0.5 * shareSeconds) return n;
    return least;
}

double referenceShapeMedian(const ExrImage& ref, const std::array<std::vector<float>, 3>& testShape) {
    static const char* kRgb[3] = {"R", "G", "B"};
    if (!ref.has("count")) return 0.0;
    for (const char* c : kRgb)
        if (!ref.has(c) || !ref.has(std::string("variance.") + c)) return 0.0;
    const int W = ref.width, H = ref.height;
    // compare's relative per-sample variance min((n - 1) v / m^2, n); NaN where the pixel says
    // nothing about the shape.
    const std::array<std::vector<float>, 3> shape = estimatorShape(ref, "reference");
    // As compare bounds the test by it: the larger of the pixel's own shape and its neighbours'
    // mean of ratios (compare_neighbourhood.cpp; compare_channel_test.cpp, rendersRefShape).
    CompareResult whole;
    whole.region = PixelRegion{0, 0, W, H};
    std::array<std::vector<double>, 3> neighbours;
    for (int c = 0; c < 3; ++c)
        neighbours[size_t(c)] = compare_detail::neighbourShape(whole, CompareOptions(), W, ref.channels.at(kRgb[c]),
                                                               ref.channels.at(std::string("variance.") + kRgb[c]),
                                                               ref.channels.at("count"))
                                    .meanOfRatios;
    std::vector<double> pixels;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            const size_t i = size_t(y) * size_t(W) + size_t(x);
            double best = INFINITY;
            for (int c = 0; c < 3; ++c) {
                const double m = ref.channels.at(kRgb[c])[i], v = ref.channels.at(std::string("variance.") + kRgb[c])[i];
                if (!(m > 0 && v > 0) || std::isnan(shape[c][i])) continue;  // no noise in this channel
                const double own = shape[c][i], nb = neighbours[size_t(c)][i];
                double pixelShape = std::isnan(nb) ? own : std::max(own, nb);
                // The port's estimator's shape where the suite has it (compare takes the larger).
                if (!testShape[size_t(c)].empty() && testShape[size_t(c)][i] > 0.f)
                    pixelShape = std::max(pixelShape, double(testShape[size_t(c)][i]));
                // The least noisy channel: compare tests a pixel when one channel has enough
                // effective samples.
                best = std::min(best, pixelShape);
            }
            if (std::isfinite(best)) pixels.push_back(best);
        }
    if (pixels.empty()) return 0.0;
    std::nth_element(pixels.begin(), pixels.begin() + long(pixels.size() / 2), pixels.end());
    return pixels[pixels.size() / 2];
}

int samplesNeededPerRender(double shapeMedian, int renders, double minEffectiveSamples, double safety) {
    const double n = safety * minEffectiveSamples * (1.0 + std::max(0.0, shapeMedian)) / double(std::max(1, renders));
    return int(std::clamp(std::ceil(n), 1.0, double(1 << 24)));
}

int nextPilotSpp(const std::vector<PilotTiming>& done) {
    if (done.empty()) return 1;
    if (done.size() == 1) return 16;
    // Blender's 2.6-6 s start-up against 0.02 s per spp: 1 and 4 spp differed by less than the
    // start-up's jitter, and read 0.18-0.44 s per spp. So the second pilot grows until the samples
    // clearly add time.
    const PilotTiming &first = done.front(), &last = done.back();
    const bool clear = last.seconds - first.seconds >= std::max(first.seconds, kPilotMinSampleSeconds);
    if (clear || last.spp >= kMaxPilotSpp) return 0;
    return std::min(kMaxPilotSpp, last.spp * 4);
}

PilotFit fitPilotCost(const std::vector<PilotTiming>& pilots) {
    PilotFit fit;
    if (pilots.empty()) return fit;
    const PilotTiming &first = pilots.front(), &last = pilots.back();
    if (last.spp <= first.spp) {  // one pilot: all of it per sample (the safe side)
        fit.secondsPerSample = first.seconds / double(std::max(1, first.spp));
        return fit;
    }
    const double added = std::max(last.seconds - first.seconds, 0.1 * first.seconds);
    fit.secondsPerSample = std::max(added, 1e-9) / double(last.spp - first.spp);
    fit.fixedSeconds = std::max(0.0, first.seconds - double(first.spp) * fit.secondsPerSample);
    return fit;
}

double SceneCost::neededSeconds() const {
    return double(processes()) * fixedSeconds + double(renders) * double(samplesNeeded) * secondsPerSample;
}

namespace {

// Not every verdict is affordable: each scene keeps the same fraction of its samples' cost, so no
// scene's chance is given up for another's. The processes' fixed cost is paid in full: shrinking
// it with the samples (the same fraction of the whole need, as before) cut a scene dominated by
// start-up to 1 spp of the 3 it needed (sun-courtyard, bidirectional, 2 of 17 clean runs without a
// verdict at the default budget).
std::vector<double> shrunkShares(const std::vector<SceneCost>& scenes, const std::vector<double>& need, double budgetSeconds) {
    double fixedTotal = 0, samplesTotal = 0;
    std::vector<double> fixed(scenes.size());
    for (size_t i = 0; i < scenes.size(); ++i) {
        fixed[i] = std::min(need[i], double(scenes[i].processes()) * scenes[i].fixedSeconds);
        fixedTotal += fixed[i], samplesTotal += need[i] - fixed[i];
    }
    std::vector<double> shares;
    if (!(samplesTotal > 0)) {  // start-up only: in proportion to it
        for (double n : need) shares.push_back(n * budgetSeconds / std::accumulate(need.begin(), need.end(), 0.0));
        return shares;
    }
    const double fraction = std::clamp((budgetSeconds - fixedTotal) / samplesTotal, 0.0, 1.0);
    for (size_t i = 0; i < scenes.size(); ++i) shares.push_back(fixed[i] + fraction * (need[i] - fixed[i]));
    return shares;
}

}  // namespace

BudgetShares allocateSceneBudgets(const std::vector<SceneCost>& scenes, double budgetSeconds) {
    BudgetShares out;
    const size_t K = scenes.size();
    if (K == 0) return out;
    std::vector<double> need(K);
    for (size_t i = 0; i < K; ++i) need[i] = std::max(0.0, scenes[i].neededSeconds());
    out.neededSeconds = std::accumulate(need.begin(), need.end(), 0.0);
    if (out.neededSeconds > budgetSeconds) {
        out.needsFit = false;
        out.seconds = shrunkShares(scenes, need, budgetSeconds);
        return out;
    }
    // Water-filling: share_i = max(need_i, L) with the shares summing to the budget. With the
    // needs sorted, the m smallest sit at the level L_m = (budget - the K - m largest) / m; the
    // largest m whose own largest need is at most L_m is the one (m = 1 always is: the needs fit).
    std::vector<double> sorted = need;
    std::sort(sorted.begin(), sorted.end());
    double level = budgetSeconds / double(K), above = out.neededSeconds;
    for (size_t m = 1; m <= K; ++m) {
        above -= sorted[m - 1];  // the K - m largest
        const double l = (budgetSeconds - above) / double(m);
        if (sorted[m - 1] <= l) level = l;
        else break;
    }
    for (size_t i = 0; i < K; ++i) out.seconds.push_back(std::max(need[i], level));
    return out;
}

int sppForShare(double shareSeconds, const SceneCost& cost) {
    // The tiny addend: a share equal to the need must not round below samplesNeeded.
    const double spp = (shareSeconds - double(cost.processes()) * cost.fixedSeconds) /
                       (double(cost.renders) * cost.secondsPerSample);
    return int(std::clamp(std::floor(spp + 1e-9), double(std::max(1, cost.samplesFloor)), double(1 << 24)));
}

}  // namespace bdptref
