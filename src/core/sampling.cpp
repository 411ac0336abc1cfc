#include "bdptref/sampling.h"

#include <algorithm>
#include <cmath>

namespace bdptref {

namespace {
// A warp's input clamped into the unit square, NaN to 0: every warp then returns a point of its
// domain whose density is the stated one, never a NaN or a point off the sphere/disk (a random
// number is in [0, 1) already, and is returned unchanged, so images are unaffected).
float unitClamp(float x) { return x > 0.f ? (x < 1.f ? x : 1.f) : 0.f; }
Vec2 unitClamp(Vec2 u) { return Vec2(unitClamp(u.x), unitClamp(u.y)); }
}  // namespace

Vec2 squareToConcentricDisk(Vec2 u) {
    // Shirley-Chiu concentric map: area-preserving, low distortion.
    const Vec2 o = 2.f * unitClamp(u) - Vec2(1.f);
    if (o.x == 0.f && o.y == 0.f) return Vec2(0.f);
    float r, theta;
    if (std::abs(o.x) > std::abs(o.y)) {
        r = o.x;
        theta = (kPi / 4.f) * (o.y / o.x);
    } else {
        r = o.y;
        theta = kPi / 2.f - (kPi / 4.f) * (o.x / o.y);
    }
    return r * Vec2(std::cos(theta), std::sin(theta));
}

Vec3 squareToUniformSphere(Vec2 u) {
    u = unitClamp(u);
    const float z = 1.f - 2.f * u.x;
    const float r = safeSqrt(1.f - z * z);
    const float phi = 2.f * kPi * u.y;
    return Vec3(r * std::cos(phi), r * std::sin(phi), z);
}

Vec3 squareToCosineHemisphere(Vec2 u) {
    // Malley's method: project the uniform disk up to the hemisphere.
    const Vec2 d = squareToConcentricDisk(u);
    return Vec3(d.x, d.y, safeSqrt(1.f - d.x * d.x - d.y * d.y));
}

Vec3 squareToUniformCone(Vec2 u, float cosThetaMax) {
    u = unitClamp(u);
    const float cosTheta = (1.f - u.x) + u.x * cosThetaMax;
    const float sinTheta = safeSqrt(1.f - cosTheta * cosTheta);
    const float phi = 2.f * kPi * u.y;
    return Vec3(sinTheta * std::cos(phi), sinTheta * std::sin(phi), cosTheta);
}

Vec2 squareToUniformTriangle(Vec2 u) {
    u = unitClamp(u);
    const float s = std::sqrt(u.x);
    return Vec2(1.f - s, u.y * s);
}

Distribution1D::Distribution1D(const std::vector<double>& weights) {
    const size_t n = weights.size();
    cdf_.assign(n + 1, 0.0);
    for (size_t i = 0; i < n; ++i) cdf_[i + 1] = cdf_[i] + std::max(0.0, weights[i]);
    total_ = cdf_[n];
    pmf_.assign(n, 0.f);
    if (total_ <= 0.0) {
        // All weights zero: nothing can be chosen (callers treat an empty total as "no lights").
        return;
    }
    for (size_t i = 0; i < n; ++i) {
        cdf_[i + 1] /= total_;
        pmf_[i] = float(std::max(0.0, weights[i]) / total_);
    }
    cdf_[n] = 1.0;
}

size_t Distribution1D::sample(float u, float* pmf, float* uRemapped) const {
    // A NaN u chooses nothing (pmf 0: a failed sample), rather than the last bucket with a NaN
    // remapped number; +-Inf pick the first / last bucket as any u outside [0, 1) does.
    if (total_ <= 0.0 || pmf_.empty() || std::isnan(u)) {
        if (pmf) *pmf = 0.f;
        if (uRemapped) *uRemapped = 0.f;
        return 0;
    }
    // First bucket whose upper cdf exceeds u, skipping zero-probability buckets.
    const double ud = double(u);
    size_t i = size_t(std::upper_bound(cdf_.begin() + 1, cdf_.end(), ud) - (cdf_.begin() + 1));
    i = std::min(i, pmf_.size() - 1);
    while (pmf_[i] == 0.f && i > 0) --i;  // only reachable through rounding at the top end
    if (pmf) *pmf = pmf_[i];
    if (uRemapped) {
        const double width = cdf_[i + 1] - cdf_[i];
        const double r = width > 0 ? (ud - cdf_[i]) / width : 0.0;
        *uRemapped = float(std::min(std::max(r, 0.0), double(0x1.fffffep-1f)));
    }
    return i;
}

}  // namespace bdptref
