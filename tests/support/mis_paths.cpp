#include "support/mis_paths.h"

#include "support/mis_tolerance.h"

#include "bdptref/bdpt.h"
#include "bdptref/rng.h"

#include <cmath>
#include <sstream>

namespace bdptref::test {

std::string MisPathCheck::summary() const {
    std::ostringstream o;
    o << firstFailures << paths << " paths (s = 0: " << s0 << ", s = 1: " << s1 << ", t = 1: " << t1 << "); failures: sum "
      << sumFailures << ", invalid but used " << invalidButUsed << ", weight " << weightFailures << ", connection " << connectionFailures
      << "; worst |sum - 1| " << worstSumError << ", worst |prod - def| / tolerance " << worstRatio;
    return o.str();
}

MisPathCheck checkSampledPathWeights(const Scene& scene, int cameraSamples, uint32_t seed, int maxDepth,
                                     const std::function<void(const std::vector<PathVertex>&, int)>& visit) {
    BdptSettings settings;
    settings.maxDepth = maxDepth;
    std::vector<PathVertex> camera(size_t(settings.maxCameraVertices())), light(size_t(settings.maxLightVertices()));
    const uint32_t width = uint32_t(scene.camera.width()), pixels = width * uint32_t(scene.camera.height());
    MisPathCheck r;
    std::ostringstream first;
    int reported = 0;
    for (int k = 0; k < cameraSamples; ++k) {
        const uint32_t pixel = uint32_t(k) * 7919u % pixels;
        const PixelSampler sampler(seed, pixel, uint64_t(k));
        const Vec2 raster = Vec2(float(pixel % width), float(pixel / width)) + sampler.get2D(RngStream::Camera, dim::kFilm);
        const int nc = generateCameraSubpath(scene, sampler, raster, settings, camera.data());
        const int nl = generateLightSubpath(scene, sampler, settings, light.data());
        for (int t = 1; t <= nc; ++t)
            for (int s = 0; s <= nl; ++s) {
                if (strategyStatus(s, t, settings.maxDepth, false) != StrategyStatus::Evaluated) continue;
                // connectStrategy weighs with the subpaths' dVCM/dVC: those of its own heuristic
                // (the loop below refills them for every heuristic it checks).
                fillRecursiveMis(scene, camera.data(), nc, settings.mis);
                fillRecursiveMis(scene, light.data(), nl, settings.mis);
                Connection c;
                PathVertex sampled;
                if (!connectStrategy(scene, light.data(), s, camera.data(), t, sampler, settings, &c, &sampled)) continue;
                // The full path, camera first; the connection's endpoints are not delta.
                std::vector<PathVertex> x;
                for (int i = 0; i < t; ++i) x.push_back(t == 1 && i == 0 ? sampled : camera[size_t(i)]);
                for (int j = s - 1; j >= 0; --j) x.push_back(s == 1 && j == 0 ? sampled : light[size_t(j)]);
                x[size_t(t - 1)].delta = false;
                if (s > 0) x[size_t(t)].delta = false;
                ++r.paths;
                r.s0 += s == 0;
                r.s1 += s == 1;
                r.t1 += t == 1;
                if (visit) visit(x, s);
                const ConnectionDensities d = connectionDensities(scene, light.data(), s, camera.data(), t, sampled, settings.mis);
                for (MisHeuristic h : {MisHeuristic::Balance, MisHeuristic::Power, MisHeuristic::Uniform}) {
                    MisSettings mis;
                    mis.heuristic = h;
                    mis.beta = 2.0;
                    // The subpaths' recursive quantities for this heuristic (generated with balance).
                    fillRecursiveMis(scene, camera.data(), nc, mis);
                    fillRecursiveMis(scene, light.data(), nl, mis);
                    const std::vector<double> w = misWeightsDefinition(scene, x, mis);
                    double sum = 0.0;
                    for (double v : w) sum += v;
                    r.worstSumError = std::max(r.worstSumError, std::abs(sum - 1.0));
                    const bool sumOk = std::abs(sum - 1.0) <= 1e-9;
                    r.sumFailures += !sumOk;
                    if (!(w.size() == x.size() && w[size_t(s)] > 0.0)) {
                        ++r.invalidButUsed;
                        if (reported++ < 5) first << "s=" << s << " t=" << t << ": strategy used but invalid by the definition\n";
                        continue;
                    }
                    // Both production forms: the recursive one the renderer uses and the ratio walk.
                    const double recursive = misWeightRecursive(scene, light.data(), s, camera.data(), t, sampled, d, mis);
                    const double walk = misWeight(scene, light.data(), s, camera.data(), t, sampled, mis);
                    const double tol = w[size_t(s)] * misRelativeTolerance(x, mis.exponent());
                    for (double prod : {recursive, walk}) {
                        const double err = std::abs(prod - w[size_t(s)]);
                        r.worstRatio = std::max(r.worstRatio, err / tol);
                        if (!(err <= tol)) {
                            ++r.weightFailures;
                            if (reported++ < 5)
                                first << "s=" << s << " t=" << t << " heuristic " << int(h) << ": recursive " << recursive << ", walk "
                                      << walk << ", definition " << w[size_t(s)] << "\n";
                        }
                    }
                    if (h == MisHeuristic::Balance && c.weight != recursive) ++r.connectionFailures;
                }
            }
    }
    r.firstFailures = first.str();
    return r;
}

}  // namespace bdptref::test
