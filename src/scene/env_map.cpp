// Equirectangular environment map: lookup, importance sampling and density (docs/lights.md,
// "Environment"). Within a texel the direction is uniform in solid angle (cos theta uniform between
// the row's boundaries, phi uniform between the column's), so the density is constant per texel and
// the 1x1 map is exactly the uniform sphere. lookup and pdf are 0 where w is no direction (NaN,
// infinite or zero: docs/hard-cases.md, "NaN-safe lookups").
#include "bdptref/env_map.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace bdptref {

namespace {
constexpr double kPiD = 3.14159265358979323846;
double luminanceD(const Rgb& e) { return 0.2126 * double(e.r) + 0.7152 * double(e.g) + 0.0722 * double(e.b); }
// A NaN, infinite or zero vector is no direction (e.g. the one between two coincident points): the
// map has no radiance and no density there, rather than those of the texel it would round to.
bool isDirection(const Vec3& w) { return isFinite(w) && w != Vec3(0.f); }
}  // namespace

EnvironmentMap::EnvironmentMap(int width, int height, std::vector<Rgb> texels, float rotationRadians)
    : width_(width), height_(height), rotation_(rotationRadians), texels_(std::move(texels)) {
    if (width <= 0 || height <= 0 || texels_.size() != size_t(width) * size_t(height))
        throw std::logic_error("internal: an environment map with a wrong size");
    for (const Rgb& t : texels_)
        if (!(isFinite(t) && t.r >= 0.f && t.g >= 0.f && t.b >= 0.f))
            throw std::logic_error("internal: an environment map texel is negative or not finite");
    if (!std::isfinite(rotation_)) throw std::logic_error("internal: an environment map rotation is not finite");
    if (rotation_ != 0.f) {
        cosRot_ = std::cos(rotation_);
        sinRot_ = std::sin(rotation_);
    }
    // Row boundaries theta_i = pi i / height; a texel of row i spans (2 pi / width) (cos theta_i -
    // cos theta_{i+1}) steradians (the sin theta weight integrated exactly over the row).
    cosTheta_.resize(size_t(height) + 1);
    for (int i = 0; i <= height; ++i) cosTheta_[size_t(i)] = std::cos(kPiD * double(i) / double(height));
    cosTheta_[0] = 1.0;
    cosTheta_[size_t(height)] = -1.0;
    texelSolidAngle_.resize(size_t(height));
    invTexelSolidAngle_.resize(size_t(height));
    std::vector<double> rowWeights(static_cast<size_t>(height));
    columns_.reserve(size_t(height));
    for (int i = 0; i < height; ++i) {
        const double omega = 2.0 * kPiD / double(width) * (cosTheta_[size_t(i)] - cosTheta_[size_t(i) + 1]);
        texelSolidAngle_[size_t(i)] = omega;
        invTexelSolidAngle_[size_t(i)] = omega > 0.0 ? 1.0 / omega : 0.0;
        std::vector<double> w(static_cast<size_t>(width));
        double sum = 0.0;
        for (int j = 0; j < width; ++j) sum += (w[size_t(j)] = luminanceD(texel(j, i)));
        rowWeights[size_t(i)] = sum * omega;
        columns_.emplace_back(w);
    }
    rows_ = Distribution1D(rowWeights);
}

EnvironmentMap EnvironmentMap::constant() { return EnvironmentMap(1, 1, {Rgb(1.f)}); }

Vec3 EnvironmentMap::toMap(const Vec3& w) const {
    if (rotation_ == 0.f) return w;
    return Vec3(cosRot_ * w.x - sinRot_ * w.z, w.y, sinRot_ * w.x + cosRot_ * w.z);  // R_y(-rotation) w
}

Vec3 EnvironmentMap::toWorld(const Vec3& m) const {
    if (rotation_ == 0.f) return m;
    return Vec3(cosRot_ * m.x + sinRot_ * m.z, m.y, -sinRot_ * m.x + cosRot_ * m.z);  // R_y(rotation) m
}

Vec2 EnvironmentMap::directionToUv(const Vec3& m) {
    const float u = 0.5f + std::atan2(m.z, m.x) * (0.5f * kInvPi);
    const float v = std::acos(glm::clamp(m.y, -1.f, 1.f)) * kInvPi;
    return Vec2(u, v);
}

void EnvironmentMap::texelOf(const Vec3& w, int* col, int* row) const {
    const Vec2 uv = directionToUv(toMap(w));
    // NaN compares false: such a direction lands in texel (0, 0) instead of indexing out of range.
    const float x = uv.x * float(width_), y = uv.y * float(height_);
    *col = x > 0.f ? std::min(int(x), width_ - 1) : 0;
    *row = y > 0.f ? std::min(int(y), height_ - 1) : 0;
}

Rgb EnvironmentMap::lookup(const Vec3& w) const {
    if (!valid() || !isDirection(w)) return Rgb(0.f);
    int col, row;
    texelOf(w, &col, &row);
    return texel(col, row);
}

bool EnvironmentMap::sample(Vec2 u, Vec3* w, float* pdfOut) const {
    *pdfOut = 0.f;
    if (!valid() || rows_.total() <= 0.0) return false;
    float pRow = 0.f, pCol = 0.f, uy = 0.f, ux = 0.f;
    const size_t row = rows_.sample(u.y, &pRow, &uy);
    const size_t col = columns_[row].sample(u.x, &pCol, &ux);
    if (!(pRow > 0.f) || !(pCol > 0.f)) return false;
    // cos theta uniform between the row's boundaries, phi uniform across the column.
    const float c0 = float(cosTheta_[row]), c1 = float(cosTheta_[row + 1]);
    const float cosT = c0 + uy * (c1 - c0);
    const float sinT = safeSqrt(1.f - cosT * cosT);
    const float phi = 2.f * kPi * ((float(col) + ux) / float(width_)) - kPi;
    *w = toWorld(Vec3(sinT * std::cos(phi), cosT, sinT * std::sin(phi)));
    // The density of the texel the direction lands in, so that pdf(w) is what every other caller
    // (MIS, the definition) computes; it differs from the sampled texel's only where rounding puts
    // w on the other side of a texel boundary.
    *pdfOut = pdf(*w);
    return *pdfOut > 0.f;
}

float EnvironmentMap::pdf(const Vec3& w) const {
    if (!valid() || rows_.total() <= 0.0 || !isDirection(w)) return 0.f;
    int col, row;
    texelOf(w, &col, &row);
    const double p = double(rows_.pmf(size_t(row))) * double(columns_[size_t(row)].pmf(size_t(col)));
    return float(p * invTexelSolidAngle_[size_t(row)]);
}

double EnvironmentMap::integratedLuminance(const Rgb& scale) const {
    double sum = 0.0;
    for (int i = 0; i < height_; ++i) {
        double row = 0.0;
        for (int j = 0; j < width_; ++j) row += luminanceD(scale * texel(j, i));
        sum += row * texelSolidAngle_[size_t(i)];
    }
    return sum;
}

}  // namespace bdptref
