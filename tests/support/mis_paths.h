// MIS weights of sampled BDPT paths: for every strategy (s, t) the integrator evaluates on a set
// of sampled subpath pairs, the definition weights (mis_definition) of the full path must sum to
// 1 and the production weights (the recursive misWeightRecursive, which connectStrategy returns,
// and the ratio walk misWeight) must equal the definition's within the float32 budget of
// support/mis_tolerance.h. Feature tests use it to show
// that their feature keeps the weights exact, counting the paths that go through the feature.
#pragma once

#include "bdptref/path_vertex.h"
#include "bdptref/scene.h"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace bdptref::test {

struct MisPathCheck {
    long paths = 0;               // (path, strategy) pairs evaluated
    long s0 = 0, s1 = 0, t1 = 0;  // of which s = 0, s = 1, t = 1
    long sumFailures = 0;         // definition weights not summing to 1 (1e-9)
    long invalidButUsed = 0;      // a strategy the integrator used has weight 0 by the definition
    long weightFailures = 0;      // recursive or walk != definition beyond the tolerance
    long connectionFailures = 0;  // connectStrategy's weight != misWeightRecursive (balance)
    double worstSumError = 0, worstRatio = 0;  // |sum - 1|, |prod - def| / tolerance
    std::string firstFailures;    // the first few failures, described
    std::string summary() const;
    // Every count of failures is zero.
    bool passed() const { return sumFailures == 0 && invalidButUsed == 0 && weightFailures == 0 && connectionFailures == 0; }
};

// Samples `cameraSamples` camera and light subpath pairs (pixels spread over the image, seed
// `seed`) and checks every evaluated strategy under the balance, power (beta 2) and uniform
// heuristics. `visit` (optional) sees every checked full path, camera vertex first, with its s.
MisPathCheck checkSampledPathWeights(const Scene& scene, int cameraSamples, uint32_t seed, int maxDepth = 5,
                                     const std::function<void(const std::vector<PathVertex>& x, int s)>& visit = {});

}  // namespace bdptref::test
