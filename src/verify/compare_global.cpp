// The image-level tests of the comparison: the local (Sidak) and bias (tiles, Stouffer) tests, the
// global p-value and verdict, the flagged pixels (Benjamini-Hochberg) and the worst region; and
// compareImages, which runs the stages (include/bdptref/image_compare.h, docs/compare.md).
#include "verify/compare_internal.h"

#include <algorithm>
#include <cmath>

namespace bdptref {

namespace compare_detail {

namespace {

// How many times the samples of both images would let a quarter of the pixels with noise be tested:
// n_eff grows in proportion to the samples, so a pixel needs its own factor (testPixels), and the
// (ceil(noisy / 4) - tested)-th smallest of them suffices. 0 when unknown.
double samplesFactor(const CompareResult& r, const CompareWork& wk, uint64_t noisy) {
    std::vector<double> f;
    for (size_t i = 0; i < wk.N; ++i)
        if ((r.status[i] == PixelStatus::LowEffective || r.status[i] == PixelStatus::FewSamples) &&
            wk.neededFactor[i] > 0)
            f.push_back(wk.neededFactor[i]);
    const uint64_t quarter = (noisy + 3) / 4;
    const uint64_t need = quarter - std::min<uint64_t>(r.tested, quarter);
    if (need == 0 || need > f.size()) return 0.0;
    std::nth_element(f.begin(), f.begin() + long(need - 1), f.end());
    const double k = f[size_t(need - 1)];
    return k < kNoFactor ? std::max(1.0, k) : 0.0;
}

// The median of a count layer over the compared pixels (0 when there is none).
double medianCount(const CompareResult& r, const std::vector<float>* count) {
    if (!count) return 0.0;
    std::vector<double> v;
    for (size_t i = 0; i < count->size(); ++i)
        if (r.status[i] != PixelStatus::Outside) v.push_back(double((*count)[i]));
    if (v.empty()) return 0.0;
    std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
    return v[v.size() / 2];
}

std::string insufficientReason(const CompareResult& r, const CompareWork& wk, uint64_t noisy) {
    std::string s = "insufficient samples: only " + std::to_string(r.tested) + " of the " + std::to_string(noisy) +
                    " pixels with noise could be tested (" + std::to_string(r.fewSamples) + " with count < 2, " +
                    std::to_string(r.lowEffective) + " with fewer than " + fmtG(r.options.minEffectiveSamples) +
                    " effective samples), and a verdict needs at least a quarter of them";
    const double k = r.samplesFactorNeeded;
    if (k <= 0) return s + "; render more samples in both images";
    const double kr = std::ceil(k * 10.0) / 10.0;  // rounded up: "about" must not promise too little
    // n_eff estimated from few samples is too high (they miss the rare large ones): a lower bound.
    s += "; at least about " + fmtG(kr, 3) + " times the samples in both images are needed";
    std::vector<std::string> eg;
    const double nT = medianCount(r, wk.tn), nR = medianCount(r, wk.rn);
    if (r.testRenders >= 2)
        eg.push_back("test: " + std::to_string(int(std::ceil(kr * r.testRenders))) + " renders instead of " +
                     std::to_string(r.testRenders) + ", or each render with " + fmtG(kr, 3) + " times its samples");
    else if (nT > 0)
        eg.push_back("test: " + fmtG(std::ceil(kr * nT), 6) + " samples per pixel instead of " + fmtG(nT, 6));
    if (nR > 0) eg.push_back("reference: " + fmtG(std::ceil(kr * nR), 6) + " instead of " + fmtG(nR, 6));
    for (size_t j = 0; j < eg.size(); ++j) s += (j ? "; " : " (") + eg[j] + (j + 1 == eg.size() ? ")" : "");
    return s;
}

// docs/compare.md "Layers of a test image with variances": no verdict when neither image has
// variances.
void verdictNeedsVariances(CompareResult& r) {
    if (r.kind == TestKind::None) {
        r.hasVerdict = false;
        r.noVerdictReason = "neither image has variance layers (variance.R, variance.G, variance.B)";
    } else {
        r.hasVerdict = true;
    }
}

// docs/compare.md "Global test: one p-value", local test: Sidak on the smallest pixel p-value.
void localTest(CompareResult& r) { r.pLocal = stats::sidak(r.pMin, double(r.tested)); }

// One channel's bias-test sums per tile: D_T, V_T, F_T (t - r, its variance, the precision
// floors), R_T (the reference) and M_T (tested pixels), over the tile's t-tested pixels.
struct BiasTiles {
    int side = 0, tilesX = 0, tilesY = 0;
    std::vector<double> D, V, F, R, M;
    size_t at(int gx, int gy) const { return size_t(gy) * size_t(tilesX) + size_t(gx); }
};

// The weighted sums of Z = num / sqrt(noise + floorSum^2) over the tiles with variance.
struct BiasSums {
    double num = 0, noise = 0, floorSum = 0, sumWr = 0;
    int tiles = 0;
};

// docs/compare.md "Global test: one p-value", bias test: the tiles' sums of channel c.
void tileSums(const CompareResult& r, const CompareWork& wk, int c, BiasTiles& t) {
    const int bt = t.side, W = wk.W;
    const std::vector<double>& d = wk.diff[size_t(c)];
    const std::vector<double>& V = wk.diffVar[size_t(c)];
    const std::vector<double>& F = wk.diffFloor[size_t(c)];
    for (int gy = 0; gy < t.tilesY; ++gy)
        for (int gx = 0; gx < t.tilesX; ++gx) {
            const int tx = r.region.x + gx * bt, ty = r.region.y + gy * bt;
            double D = 0, VT = 0, FT = 0, R = 0, M = 0;
            for (int y = ty; y < std::min(ty + bt, r.region.y + r.region.height); ++y)
                for (int x = tx; x < std::min(tx + bt, r.region.x + r.region.width); ++x) {
                    const size_t i = size_t(y) * size_t(W) + size_t(x);
                    if (std::isnan(d[i])) continue;
                    D += d[i];
                    VT += V[i];
                    FT += F[i];
                    R += double((*wk.rm[c])[i]);
                    M += 1;
                }
            const size_t u = t.at(gx, gy);
            t.D[u] = D;
            t.V[u] = VT;
            t.F[u] = FT;
            t.R[u] = R;
            t.M[u] = M;
        }
}

// docs/compare.md "Global test: one p-value", bias test: the tile weights w_T = 1 / sqrt(m_T V~_T)
// from the 3 x 3 tiles around each tile, and the weighted sums.
BiasSums weightedTileSums(const BiasTiles& t) {
    BiasSums s;
    for (int gy = 0; gy < t.tilesY; ++gy)
        for (int gx = 0; gx < t.tilesX; ++gx) {
            const size_t u0 = t.at(gx, gy);
            const double total = t.V[u0] + t.F[u0] * t.F[u0];
            if (!(total > 0)) continue;
            // The weight from the variance per tested pixel of the 3 x 3 tiles around this
            // one (itself included), times its tested pixels. A weight from the tile's own
            // variance alone favours the tiles whose skewed samples came out low (low mean,
            // low variance) and biases Z: with a 16-spp path-traced test against a 64-spp
            // BDPT reference, mean Z was -1.9; the tile's share in its weight is now 1/9.
            // (Leaving the tile out entirely gives a noisy tile, e.g. on a light's edge,
            // the weight of its quiet neighbours, and its noise then drowns the test.)
            double wv = total;
            {
                double sv = 0, sm = 0;
                for (int dy = -1; dy <= 1; ++dy)
                    for (int dx = -1; dx <= 1; ++dx) {
                        const int ux = gx + dx, uy = gy + dy;
                        if (ux < 0 || uy < 0 || ux >= t.tilesX || uy >= t.tilesY) continue;
                        const size_t u = t.at(ux, uy);
                        if (!(t.M[u] > 0)) continue;
                        sv += t.V[u] + t.F[u] * t.F[u];
                        sm += t.M[u];
                    }
                if (sm > 0 && sv > 0) wv = sv / sm * t.M[u0];
            }
            const double w = 1.0 / std::sqrt(wv);
            s.num += w * t.D[u0];
            s.noise += w * w * t.V[u0];
            s.floorSum += w * t.F[u0];
            s.sumWr += w * t.R[u0];
            ++s.tiles;
        }
    return s;
}

// docs/compare.md "Global test: one p-value", bias test (tiles + Stouffer): each channel's Z and
// the tiles' relative bias, the channels' p-values Cauchy-combined into p_bias.
void biasTest(CompareResult& r, const CompareWork& wk) {
    // Bias test, per channel: the region is cut into about 64 square tiles (side >= 4); tile T
    // has D_T = sum(t - r), V_T = sum V (the variance of t - r) and F_T = sum of the precision
    // floors over its t-tested pixels, and
    //     Z = sum_T w_T D_T / sqrt(sum_T w_T^2 V_T + (sum_T w_T F_T)^2),  w_T = 1 / sqrt(V_T + F_T^2):
    // Stouffer's combination of the tiles' z-scores D_T / sqrt(V_T) when the floors are
    // negligible, while a systematic difference at the precision floor stays below |Z| = 1.
    // Within a tile the sum runs over many pixels x samples, so D_T is close to normal and its
    // studentisation bias (for skewed pixel estimators) is small; across tiles, every tile has
    // about the same weight, so a few very noisy pixels (fireflies, light edges) only silence
    // their own tile instead of the whole test. docs/compare.md discusses the choice.
    r.biasTile = biasTileSize(r.region.width, r.region.height);
    BiasTiles t;
    t.side = r.biasTile;
    t.tilesX = (r.region.width + t.side - 1) / t.side;
    t.tilesY = (r.region.height + t.side - 1) / t.side;
    const size_t nTiles = size_t(t.tilesX) * size_t(t.tilesY);
    t.D.resize(nTiles);
    t.V.resize(nTiles);
    t.F.resize(nTiles);
    t.R.resize(nTiles);
    t.M.resize(nTiles);
    double pc[3];
    int k = 0;
    for (int c = 0; c < 3; ++c) {
        tileSums(r, wk, c, t);
        const BiasSums s = weightedTileSums(t);
        const double den = std::sqrt(s.noise + s.floorSum * s.floorSum);
        if (s.tiles > 0 && den > 0) {
            r.biasZ[size_t(c)] = s.num / den;
            r.weightedRelativeBias[size_t(c)] = s.sumWr != 0 ? s.num / s.sumWr : 0.0;
            r.weightedRelativeBiasSigma[size_t(c)] = s.sumWr != 0 ? den / std::abs(s.sumWr) : 0.0;
            r.biasTiles = std::max(r.biasTiles, s.tiles);
            pc[k++] = stats::normalTwoSidedP(r.biasZ[size_t(c)]);
        }
    }
    r.pBias = stats::cauchyCombination(pc, k);
}

// docs/compare.md "Global test: one p-value": Sidak over the local and the bias test, the |z| at
// which one pixel alone makes it reject, and 0 on a hard failure.
void sidakCombination(double alpha, CompareResult& r) {
    if (r.tested > 0) {
        r.pGlobal = stats::sidak(std::min(r.pLocal, r.pBias), 2.0);
        // The |z| at which one pixel alone makes the global test reject.
        const double twoTestLevel = -std::expm1(0.5 * std::log1p(-alpha));  // 1 - (1 - alpha)^(1/2)
        const double pixelLevel = -std::expm1(std::log1p(-twoTestLevel) / double(r.tested));
        r.zThreshold = stats::zFromTwoSidedP(pixelLevel);
    }
    if (r.unequal > 0 || r.nonFinite > 0) r.pGlobal = 0.0;
}

// docs/compare.md "Insufficient samples" and "Global test: one p-value": consistent, or no
// verdict when fewer than a quarter of the pixels with noise were tested.
void verdict(double alpha, CompareResult& r, const CompareWork& wk) {
    // Coverage: "consistent" needs at least a quarter of the pixels with noise tested, else a test
    // of a few pixels (or of none) would pass for a verdict on the image. (A quarter, not more: in
    // a scene lit mostly through rare paths, e.g. narrow-gap at 128 spp, 30% of the pixels are
    // testable and the verdict on them is sound; tests/scenes/test_references.cpp.) A rejection stands whatever
    // the coverage: the p-values of the pixels that were tested are valid.
    const uint64_t noisy = r.tested + r.fewSamples + r.lowEffective;
    const bool rejected = r.pGlobal < alpha || r.unequal > 0 || r.nonFinite > 0;
    if (r.kind != TestKind::None && !rejected && noisy > 0 && 4 * r.tested < noisy) {
        r.hasVerdict = false;
        r.insufficientSamples = true;
        r.samplesFactorNeeded = samplesFactor(r, wk, noisy);
        r.noVerdictReason = insufficientReason(r, wk, noisy);
    }
    r.consistent = r.hasVerdict && r.pGlobal >= alpha && r.unequal == 0 && r.nonFinite == 0;
}

// docs/compare.md "Flagged pixels and the worst region": Benjamini-Hochberg at FDR alpha over the
// tested pixels, plus every hard failure; returns the tested pixels' (p, index), smallest first.
std::vector<std::pair<double, size_t>> flagPixels(double alpha, CompareResult& r, const CompareWork& wk) {
    const size_t N = wk.N;
    std::vector<std::pair<double, size_t>> tp;
    tp.reserve(size_t(r.tested));
    for (size_t i = 0; i < N; ++i)
        if (r.status[i] == PixelStatus::Tested) tp.emplace_back(wk.pixelPd[i], i);
    std::sort(tp.begin(), tp.end());
    const double m = double(tp.size());
    size_t k = 0;
    for (size_t j = tp.size(); j > 0; --j)
        if (tp[j - 1].first <= double(j) * alpha / m) {
            k = j;
            break;
        }
    for (size_t j = 0; j < k; ++j) r.isFlagged[tp[j].second] = 1;
    r.bhThreshold = k > 0 ? tp[k - 1].first : 0.0;
    for (size_t i = 0; i < N; ++i)
        if (r.status[i] == PixelStatus::Unequal || r.status[i] == PixelStatus::NonFinite) r.isFlagged[i] = 1;
    return tp;
}

// docs/compare.md "Reading a failure": the most significant pixels, hard failures first, then the
// smallest p-values (tested: flagPixels' list).
void listWorstPixels(const std::vector<std::pair<double, size_t>>& tested, CompareResult& r, const CompareWork& wk) {
    const size_t N = wk.N;
    std::vector<size_t> order;
    for (size_t i = 0; i < N && order.size() < 10; ++i)
        if (r.status[i] == PixelStatus::Unequal || r.status[i] == PixelStatus::NonFinite) order.push_back(i);
    for (size_t j = 0; j < tested.size() && order.size() < 10; ++j) order.push_back(tested[j].second);
    for (size_t i : order) {
        FlaggedPixel f;
        f.x = int(i % size_t(wk.W));
        f.y = int(i / size_t(wk.W));
        f.status = r.status[i];
        f.p = r.status[i] == PixelStatus::Tested ? wk.pixelPd[i] : 0.0;
        f.z = double(r.pixelZ[i]);
        for (int c = 0; c < 3; ++c) {
            f.test[size_t(c)] = (*wk.tm[c])[i];
            f.ref[size_t(c)] = (*wk.rm[c])[i];
            f.testSigma[size_t(c)] = wk.useTestVar ? std::sqrt(std::max(0.f, (*wk.tv[c])[i])) : 0.0;
            f.refSigma[size_t(c)] = wk.useRefVar ? std::sqrt(std::max(0.f, (*wk.rv[c])[i])) : 0.0;
        }
        r.worst.push_back(f);
    }
}

// The flagged pixels per --tile tile of the region.
struct FlaggedTiles {
    int side = 0, tilesX = 0;
    std::vector<uint64_t> count;
};

// docs/compare.md "Flagged pixels and the worst region": the flagged pixels' count and bounding
// box, and their count per --tile tile.
FlaggedTiles flaggedBox(int tileSize, CompareResult& r, const CompareWork& wk) {
    const int W = wk.W, H = wk.H;
    FlaggedTiles t;
    const int ts = t.side = tileSize;
    const int tilesX = t.tilesX = (r.region.width + ts - 1) / ts, tilesY = (r.region.height + ts - 1) / ts;
    t.count.assign(size_t(tilesX) * size_t(tilesY), 0);
    r.boxX0 = W;
    r.boxY0 = H;
    for (int y = r.region.y; y < r.region.y + r.region.height; ++y)
        for (int x = r.region.x; x < r.region.x + r.region.width; ++x) {
            const size_t i = size_t(y) * size_t(W) + size_t(x);
            if (!r.isFlagged[i]) continue;
            ++r.flagged;
            r.boxX0 = std::min(r.boxX0, x);
            r.boxY0 = std::min(r.boxY0, y);
            r.boxX1 = std::max(r.boxX1, x);
            r.boxY1 = std::max(r.boxY1, y);
            ++t.count[size_t((y - r.region.y) / ts) * size_t(tilesX) + size_t((x - r.region.x) / ts)];
        }
    if (r.flagged == 0) r.boxX0 = r.boxY0 = 0;
    return t;
}

// docs/compare.md "Flagged pixels and the worst region": the bounding box of all flagged pixels
// when it is compact (at most two tiles across each way and a quarter of the region), else the
// tile holding the most flagged pixels; and its relative bias.
void worstRegion(const FlaggedTiles& t, CompareResult& r, const CompareWork& wk) {
    if (r.flagged == 0) return;
    const int ts = t.side, tilesX = t.tilesX;
    const double boxArea = double(r.boxX1 - r.boxX0 + 1) * double(r.boxY1 - r.boxY0 + 1);
    if (r.boxX1 - r.boxX0 < 2 * ts && r.boxY1 - r.boxY0 < 2 * ts &&
        boxArea <= 0.25 * double(r.region.width) * double(r.region.height)) {
        r.worstX0 = r.boxX0;
        r.worstY0 = r.boxY0;
        r.worstX1 = r.boxX1;
        r.worstY1 = r.boxY1;
        r.worstFlagged = r.flagged;
        r.worstIsBoundingBox = true;
    } else {
        size_t best = 0;
        for (size_t u = 1; u < t.count.size(); ++u)
            if (t.count[u] > t.count[best]) best = u;
        r.worstFlagged = t.count[best];
        r.worstX0 = r.region.x + int(best % size_t(tilesX)) * ts;
        r.worstY0 = r.region.y + int(best / size_t(tilesX)) * ts;
        r.worstX1 = std::min(r.worstX0 + ts, r.region.x + r.region.width) - 1;
        r.worstY1 = std::min(r.worstY0 + ts, r.region.y + r.region.height) - 1;
    }
    // Its relative bias: the median over its compared pixels of sum_c(t - r) / sum_c r, the
    // relative error of a typical pixel (a sum over the region would be ruled by its
    // brightest or noisiest pixels).
    std::vector<double> rel;
    for (int y = r.worstY0; y <= r.worstY1; ++y)
        for (int x = r.worstX0; x <= r.worstX1; ++x) {
            const size_t i = size_t(y) * size_t(wk.W) + size_t(x);
            if (r.status[i] == PixelStatus::Outside || r.status[i] == PixelStatus::NonFinite) continue;
            double sd = 0, sr = 0;
            for (int c = 0; c < 3; ++c) {
                sd += double((*wk.tm[c])[i]) - double((*wk.rm[c])[i]);
                sr += double((*wk.rm[c])[i]);
            }
            if (sr > 0) rel.push_back(sd / sr);
        }
    if (!rel.empty()) {
        std::nth_element(rel.begin(), rel.begin() + long(rel.size() / 2), rel.end());
        r.worstRelativeBias = rel[rel.size() / 2];
    }
}

}  // namespace

void globalTests(const CompareOptions& options, CompareResult& r, const CompareWork& wk) {
    verdictNeedsVariances(r);
    if (r.tested > 0) {
        localTest(r);
        biasTest(r, wk);
    }
    sidakCombination(options.alpha, r);
    verdict(options.alpha, r, wk);
    const std::vector<std::pair<double, size_t>> tested = flagPixels(options.alpha, r, wk);
    listWorstPixels(tested, r, wk);
    const FlaggedTiles tiles = flaggedBox(options.tileSize, r, wk);
    worstRegion(tiles, r, wk);
}

}  // namespace compare_detail

using namespace compare_detail;

int biasTileSize(int regionWidth, int regionHeight) {
    const double m = double(regionWidth) * double(regionHeight);
    return std::max(4, int(std::ceil(std::sqrt(m / 64.0))));
}

CompareResult compareImages(const ExrImage& test, const ExrImage& ref, const CompareOptions& options) {
    CompareResult r;
    CompareWork w;
    testPixels(test, ref, options, r, w);
    globalTests(options, r, w);
    addWarnings(test, ref, r);
    writeSentence(r);
    return r;
}

}  // namespace bdptref
