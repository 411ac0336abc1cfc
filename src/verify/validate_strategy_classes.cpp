// Strategy classes (docs/validate.md, "Strategy classes"): a bidirectional or path-tracing port that
// writes its unweighted strategy layers (bdptref render --strategies: s<S>t<T>.unweighted) gets them
// compared, averaged per class of strategy and depth, with the reference's depth layer. Unweighted,
// each strategy (s,t) that can sample every path of depth s + t - 2 estimates that whole layer on
// its own, whatever the MIS weights; so a class that fails names the terms its strategies read
// (next-event estimation the light's sampling density, light tracing the camera's importance, the
// connections both subpaths' ends), and every class agreeing while the beauty fails leaves only
// the weights. Which classes sample every path of a scene (no delta light for emitter hits, no
// specular vertex next to the light for next events, ...) the suite says (`strategyClasses`).
#include "verify/validate.h"

#include "bdptref/errors.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

namespace bdptref {

namespace {

constexpr std::array<const char*, kStrategyClassCount> kClassNames = {"emitterHit", "nextEvent", "lightTracing",
                                                                       "connections"};

std::string unweightedChannel(int s, int t, const char* channel) {
    return "s" + std::to_string(s) + "t" + std::to_string(t) + ".unweighted." + channel;
}

}  // namespace

const char* strategyClassName(StrategyClass c) { return kClassNames[size_t(c)]; }

std::optional<StrategyClass> parseStrategyClass(const std::string& name) {
    for (int c = 0; c < kStrategyClassCount; ++c)
        if (name == kClassNames[size_t(c)]) return StrategyClass(c);
    return std::nullopt;
}

StrategyClass strategyClassOf(int s, int t) {
    if (t == 1) return StrategyClass::LightTracing;
    if (s == 0) return StrategyClass::EmitterHit;
    return s == 1 ? StrategyClass::NextEvent : StrategyClass::Connections;
}

bool estimatorHasClass(PortEstimator e, StrategyClass c) {
    switch (e) {
        case PortEstimator::Path: return c == StrategyClass::EmitterHit || c == StrategyClass::NextEvent;
        case PortEstimator::Light: return c == StrategyClass::LightTracing;
        case PortEstimator::Bidirectional: return true;
    }
    return true;
}

bool strategyClassImage(const ExrImage& render, StrategyClass c, int depth, ExrImage* out) {
    std::vector<int> lightVertices;  // s of the class's strategies at this depth that the render holds
    // s = 1, t = 1 (a point of a light seen through the lens, depth 0) is left out: light tracing
    // of emitters seen directly is a strategy bdptref does not sample (its layer is zero).
    for (int s = 0; s <= depth + 1; ++s)
        if (strategyClassOf(s, depth + 2 - s) == c && !(s == 1 && depth == 0) &&
            render.has(unweightedChannel(s, depth + 2 - s, "R")))
            lightVertices.push_back(s);
    if (lightVertices.empty()) return false;
    out->width = render.width, out->height = render.height, out->window = render.window;
    out->channels.clear();
    const size_t pixels = size_t(render.width) * size_t(render.height);
    for (const char* ch : {"R", "G", "B"}) {
        std::vector<double> sum(pixels, 0.0);
        for (int s : lightVertices) {
            const std::string name = unweightedChannel(s, depth + 2 - s, ch);
            if (!render.has(name)) throw InputError("a test render has " + unweightedChannel(s, depth + 2 - s, "R") + " but not " + name);
            const std::vector<float>& v = render.channels.at(name);
            for (size_t i = 0; i < pixels; ++i) sum[i] += double(v[i]);
        }
        std::vector<float>& mean = out->channels[ch];
        mean.resize(pixels);
        for (size_t i = 0; i < pixels; ++i) mean[i] = float(sum[i] / double(lightVertices.size()));
    }
    return true;
}

namespace {

// Sum over R, G, B of the image mean of `img`'s channels named prefix + R/G/B.
double meanOfRgb(const ExrImage& img, const std::string& prefix) {
    double sum = 0;
    for (const char* ch : {"R", "G", "B"})
        for (const float v : img.channels.at(prefix + ch)) sum += double(v);
    return sum / double(std::max<size_t>(1, size_t(img.width) * size_t(img.height)));
}

// The variance of the reference layer's image mean, from its per-pixel variances of the mean: the
// channels are taken as fully correlated (the safe side), the pixels as independent.
double referenceMeanVariance(const ExrImage& reference, const std::string& layer) {
    double sdSum = 0;
    const double pixels = double(std::max<size_t>(1, size_t(reference.width) * size_t(reference.height)));
    for (const char* ch : {"R", "G", "B"}) {
        const auto it = reference.channels.find(layer + ".variance." + ch);
        if (it == reference.channels.end()) continue;
        double v = 0;
        for (const float x : it->second) v += double(x);
        sdSum += std::sqrt(std::max(0.0, v)) / pixels;
    }
    return sdSum * sdSum;
}

// |t| with P(|T| >= |t|) = p for Student's t with `dof` degrees of freedom (bisection).
double studentQuantileTwoSided(double p, double dof) {
    double lo = 0, hi = 1e3;
    for (int i = 0; i < 200; ++i) {
        const double mid = 0.5 * (lo + hi);
        (stats::studentTTwoSidedP(mid, dof) > p ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}

// The class's image mean over N renders against the reference's depth layer: a t test of the mean
// of the N per-render image means (their spread is the noise), docs/validate.md, "Strategy classes".
// Image means, not compare's per-pixel tests: a class layer is sparse (an emitter hit by few camera
// subpaths leaves most pixels zero in most renders), where zero-variance pixels would look exact.
LayerOutcome compareClassMeans(const std::vector<double>& means, double referenceMean, double referenceVariance,
                               const std::string& name, int depth, double alpha) {
    LayerOutcome o;
    o.layer = name;
    o.depth = depth;
    const double n = double(means.size());
    double m = 0, ss = 0;
    for (double x : means) m += x / n;
    for (double x : means) ss += (x - m) * (x - m);
    const double variance = ss / (n - 1) / n + referenceVariance;
    if (!(referenceMean > 0) || !(ss > 0) || n < 2) {
        o.sentence = !(referenceMean > 0) ? "not compared: the reference's layer is black"
                                          : "not compared: the class is the same in every render (no light it carries)";
        return o;
    }
    const double sd = std::sqrt(variance), dof = n - 1;
    o.hasVerdict = true;
    o.p = stats::studentTTwoSidedP((m - referenceMean) / sd, dof);
    o.consistent = o.p >= alpha;
    const double half = studentQuantileTwoSided(0.05, dof) * sd / referenceMean;
    o.relativeBias = m / referenceMean - 1;
    o.relativeBiasLow = o.relativeBias - half;
    o.relativeBiasHigh = o.relativeBias + half;
    char b[160];
    std::snprintf(b, sizeof b, "%s: image mean off by %+.2f%% [%+.2f%%, %+.2f%%] over %d renders (p = %.2g)",
                  o.consistent ? "consistent" : "INCONSISTENT", 100 * o.relativeBias, 100 * o.relativeBiasLow,
                  100 * o.relativeBiasHigh, int(n), o.p);
    o.sentence = b;
    return o;
}

}  // namespace

void compareStrategyClasses(const std::vector<ExrImage>& renders, const ExrImage& reference, const std::vector<int>& depths,
                            double alpha, SceneOutcome& outcome, PortEstimator estimator) {
    outcome.strategyClassLayers.clear();
    if (!outcome.scene || outcome.scene->strategyClasses.empty() || renders.size() < 2) return;
    struct Pending {
        StrategyClass c;
        int depth;
        std::vector<double> means;  // per render
        std::string problem;        // why the class's layers cannot be read, or empty
    };
    std::vector<Pending> pending;
    for (const std::string& name : outcome.scene->strategyClasses) {
        const std::optional<StrategyClass> c = parseStrategyClass(name);
        if (!c || !estimatorHasClass(estimator, *c)) continue;  // the suite's loader refuses unknown names
        for (int d : depths) {
            Pending p{*c, d, {}, ""};
            ExrImage img;
            try {
                for (const ExrImage& r : renders)
                    if (strategyClassImage(r, *c, d, &img)) p.means.push_back(meanOfRgb(img, ""));
            } catch (const InputError& e) {  // a malformed optional layer: said, and the beauty's verdict kept
                p.problem = e.what();
            }
            // Every render or none: a port that wrote some renders' layers only is not compared.
            if (p.means.size() == renders.size() || !p.problem.empty()) pending.push_back(std::move(p));
        }
    }
    const double level = sidakLevel(alpha, std::max(1, int(pending.size())));
    for (const Pending& p : pending) {
        const std::string layer = "depth" + std::to_string(p.depth);
        if (!reference.has(layer + ".R")) continue;
        if (!p.problem.empty()) {
            LayerOutcome none;
            none.layer = layer + "." + strategyClassName(p.c);
            none.depth = p.depth;
            none.sentence = "not compared: " + p.problem;
            outcome.strategyClassLayers.push_back(none);
            continue;
        }
        outcome.strategyClassLayers.push_back(compareClassMeans(p.means, meanOfRgb(reference, layer + "."),
                                                                referenceMeanVariance(reference, layer),
                                                                layer + "." + strategyClassName(p.c), p.depth, level));
    }
}

}  // namespace bdptref
