// Sampling warps (unit square -> domain) with their densities, and a discrete distribution.
// Every warp here has a chi-square test against its pdf in tests/unit/test_sampling.cpp.
#pragma once

#include "bdptref/math.h"

#include <cstddef>
#include <vector>

namespace bdptref {

Vec2 squareToConcentricDisk(Vec2 u);  // unit disk, pdf 1/pi
Vec3 squareToUniformSphere(Vec2 u);
inline float uniformSpherePdf() { return kInv4Pi; }
Vec3 squareToCosineHemisphere(Vec2 u);  // about +z
inline float cosineHemispherePdf(float cosTheta) { return cosTheta > 0.f ? cosTheta * kInvPi : 0.f; }
Vec3 squareToUniformCone(Vec2 u, float cosThetaMax);  // about +z
inline float uniformConePdf(float cosThetaMax) { return 1.f / (2.f * kPi * (1.f - cosThetaMax)); }
// Barycentrics (b0, b1) of a uniformly distributed point on a triangle; b2 = 1 - b0 - b1.
Vec2 squareToUniformTriangle(Vec2 u);

// Discrete distribution proportional to non-negative weights.
class Distribution1D {
public:
    Distribution1D() = default;
    explicit Distribution1D(const std::vector<double>& weights);
    size_t size() const { return pmf_.size(); }
    bool empty() const { return pmf_.empty(); }
    // Index with probability pmf(i); `uRemapped`, if given, receives u rescaled to [0,1) within
    // the chosen bucket so it can be reused.
    size_t sample(float u, float* pmf, float* uRemapped = nullptr) const;
    float pmf(size_t i) const { return i < pmf_.size() ? pmf_[i] : 0.f; }
    double total() const { return total_; }

private:
    std::vector<float> pmf_;
    std::vector<double> cdf_;  // cdf_[i] = P(index < i), size n+1
    double total_ = 0;
};

}  // namespace bdptref
