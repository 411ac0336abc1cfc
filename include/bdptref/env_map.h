// An equirectangular environment map and its importance-sampling tables (docs/lights.md,
// "Environment"). The constant environment (--env R,G,B) is the 1x1 map of value 1 scaled by the
// light's emission; every environment goes through this class.
//
// Direction <-> (u, v), the Khronos glTF-Sample-Viewer's panorama convention (dirToUV) with the
// image's top row at +Y (glTF's up axis), for a unit direction w = (x, y, z) in MAP space:
//   u = 0.5 + atan2(z, x) / (2 pi)   (the image's centre column looks along +X, u = 0.75 along +Z)
//   v = acos(y) / pi                 (v = 0: the top row, +Y; v = 1: the bottom row, -Y)
// World space = R_y(rotation) map space (a right-handed turn about +Y; see rotation()).
//
// The radiance is piecewise constant: texel (col, row) holds for every direction whose (u, v)
// falls in it (no filtering), which is what the sampling tables describe exactly.
#pragma once

#include "bdptref/math.h"
#include "bdptref/sampling.h"

#include <string>
#include <vector>

namespace bdptref {

class EnvironmentMap {
public:
    EnvironmentMap() = default;  // empty (width 0): valid() is false
    // Texels row-major, row 0 = top (v = 0), width * height values, each finite and >= 0 (the
    // loader checks; here a violation is a std::logic_error). rotationRadians: about +Y.
    EnvironmentMap(int width, int height, std::vector<Rgb> texels, float rotationRadians = 0.f);
    static EnvironmentMap constant();  // 1x1, value (1, 1, 1): the constant environment

    bool valid() const { return width_ > 0; }
    int width() const { return width_; }
    int height() const { return height_; }
    float rotation() const { return rotation_; }
    Rgb texel(int col, int row) const { return texels_[size_t(row) * size_t(width_) + size_t(col)]; }

    // Map-space (rotation undone) direction <-> (u, v) and the texel holding a direction.
    Vec3 toMap(const Vec3& w) const;
    Vec3 toWorld(const Vec3& m) const;
    static Vec2 directionToUv(const Vec3& mapDir);
    void texelOf(const Vec3& w, int* col, int* row) const;  // w in world space, unit

    // Map value in the world direction w (unit, from the scene towards the environment).
    Rgb lookup(const Vec3& w) const;
    // A world direction w (towards the environment) chosen with probability proportional to the
    // texel's luminance times its solid angle; *pdf = pdf(*w). False when the map is black.
    bool sample(Vec2 u, Vec3* w, float* pdf) const;
    // Solid-angle density of sample() at w: P(texel) / solid angle of the texel.
    float pdf(const Vec3& w) const;
    // Solid angle of one texel of row `row`: (2 pi / width) (cos theta_row - cos theta_row+1).
    double texelSolidAngle(int row) const { return texelSolidAngle_[size_t(row)]; }
    // Integral over the sphere of luminance(scale * L(w)) dw (double; the light's power / (pi R^2)).
    double integratedLuminance(const Rgb& scale) const;

private:
    int width_ = 0, height_ = 0;
    float rotation_ = 0.f, cosRot_ = 1.f, sinRot_ = 0.f;
    std::vector<Rgb> texels_;
    std::vector<double> cosTheta_;           // cos of the row boundaries, height + 1 values
    std::vector<double> texelSolidAngle_;    // per row
    std::vector<double> invTexelSolidAngle_; // per row
    Distribution1D rows_;                    // marginal: sum over the row of luminance x solid angle
    std::vector<Distribution1D> columns_;    // conditional per row: luminance
};

// Reads an equirectangular map (EXR or Radiance .hdr; channels R, G, B, or one grey channel) for
// --env-map. InputError naming the file when it is missing, not a readable image, empty, has a
// texel that is NaN, infinite or negative, or is black everywhere.
EnvironmentMap loadEnvironmentMap(const std::string& path, float rotationDegrees);

}  // namespace bdptref
