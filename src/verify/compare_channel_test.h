// Shared by compare_pixels.cpp (the pixel pass) and compare_channel_test.cpp (the test of one
// channel of one pixel): what the rules of docs/compare.md, "Per pixel and channel", need. Not
// installed.
#pragma once

#include "verify/compare_internal.h"

#include <array>
#include <cstddef>
#include <limits>
#include <vector>

namespace bdptref::compare_detail {

// The rules that apply to the whole image, fixed before the pixel pass (testPixels), and the
// neighbourhood shapes they use.
struct PixelRules {
    double minEffective = 0.0;  // --min-effective (0: no effective-sample rule)
    double precision = 0.0;     // --precision
    double samplesPerRender = 0.0;
    // Counts in both images and variances in both: n_eff and the variance bound from each image's
    // own neighbourhood.
    bool pooled = false;
    // The test is N >= 2 renders without a count: its variances have N - 1 degrees of freedom.
    bool renders = false;
    double testDof = std::numeric_limits<double>::infinity();
    double nRenders = 0.0;
    bool rendersGuard = false;  // N renders, and the reference has variances (Welch)
    bool rendersShape = false;  // ... and a count: the renders' neighbourhood bound
    bool fewRenders = false;    // ... with fewer than 4 renders
    // The test's estimator shape (--test-shape), the largest of each pixel's 3 x 3 neighbourhood.
    bool useTestShape = false;
    std::array<std::vector<float>, 3> testShape;
    // Each image's estimator shape around every pixel (pooled or rendersShape only).
    std::array<NeighbourShape, 3> shapeT, shapeR;

    double testShapeAt(int c, size_t i) const { return useTestShape ? double(testShape[size_t(c)][i]) : 0.0; }
};

// One channel of one pixel: the test's mean a, variance of the mean va and count nT, the
// reference's b, vb, nR (counts infinite without a count layer).
struct ChannelValues {
    int c = 0;
    size_t i = 0;
    double a = 0.0, b = 0.0, va = 0.0, vb = 0.0, nT = 0.0, nR = 0.0;
};

// docs/compare.md "Per pixel and channel": the test of one channel; counts the channels it tests
// (testedChannels) and those whose variance a bound raised (pooledChannels) in r.
ChannelTest testChannel(const PixelRules& rules, const ChannelValues& v, CompareResult& r);

}  // namespace bdptref::compare_detail
