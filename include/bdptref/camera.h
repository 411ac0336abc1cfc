// Pinhole perspective camera with its importance function We (needed by light tracing and the
// t=1 strategies of BDPT). Derivation: docs/camera.md.
//
// The image plane sits at distance 1 in front of the pinhole and has area
//   A = (2 tan(fovx/2)) * (2 tan(fovy/2)).
// For a direction w making angle theta with the viewing axis and landing inside the image:
//   We(w)      = 1 / (A cos^4 theta)
//   pdfDir(w)  = 1 / (A cos^3 theta)   (solid angle, for uniformly chosen film points)
//   pdfPos     = 1                      (delta position)
// so that the integral of We(w) cos(theta) dw over the sphere is 1.
#pragma once

#include "bdptref/math.h"

namespace bdptref {

struct CameraImportanceSample {
    Vec3 wi;        // unit, from the reference point towards the pinhole
    float dist = 0;  // distance from the reference point to the pinhole
    float pdf = 0;   // solid angle at the reference point (dist^2 / |cos| at the pinhole)
    float We = 0;    // importance along -wi
    Vec2 raster;     // continuous raster position (pixels, origin top-left)
};

class Camera {
public:
    Camera() = default;
    // yfov in radians; width x height is the full image (crop windows keep the full image's
    // camera so that splats and pixel indices do not change).
    static Camera lookAt(const Vec3& eye, const Vec3& target, const Vec3& up, float yfov, int width, int height);
    static Camera fromMatrix(const Mat4& cameraToWorld, float yfov, int width, int height);

    // Primary ray through continuous raster position (x right, y down, in pixels).
    Ray generateRay(Vec2 raster) const;

    // Importance leaving the pinhole in direction w (unit, world); 0 outside the image.
    // `raster` (optional) receives where w lands.
    float We(const Vec3& w, Vec2* raster = nullptr) const;
    void pdfWe(const Vec3& w, float* pdfPos, float* pdfDir) const;
    // Samples the pinhole as seen from `ref` (the pinhole is a point: always the same point).
    bool sampleWi(const Vec3& ref, CameraImportanceSample* out) const;

    const Vec3& position() const { return origin_; }
    const Vec3& forward() const { return forward_; }
    const Vec3& up() const { return up_; }
    int width() const { return width_; }
    int height() const { return height_; }
    float yfov() const { return yfov_; }
    float imagePlaneArea() const { return area_; }
    // The same camera moved to `position` (orientation, field of view, resolution and crop kept):
    // Scene::finalize() puts the camera at the render-space origin with it.
    Camera withPosition(const Vec3& position) const;
    // Resizes the film while keeping the vertical field of view (and resets the crop window).
    Camera withResolution(int width, int height) const;
    // Restricts sampling to the pixels [x0, x1) x [y0, y1) of the full image. We and the densities
    // are then defined over that window (its area replaces A), so that light-tracing splats and
    // the t = 1 MIS densities stay consistent with camera samples drawn only inside it
    // (docs/camera.md, "Crop windows"). Directions outside the window have no importance.
    Camera withCrop(int x0, int y0, int x1, int y1) const;
    int cropX0() const { return cropX0_; }
    int cropY0() const { return cropY0_; }
    int cropX1() const { return cropX1_; }
    int cropY1() const { return cropY1_; }

private:
    void init();
    void updateArea();
    Vec3 origin_{0.f}, forward_{0, 0, -1}, right_{1, 0, 0}, up_{0, 1, 0};
    float yfov_ = 0.7f;
    int width_ = 1, height_ = 1;
    float tanHalfX_ = 0, tanHalfY_ = 0, area_ = 0;
    int cropX0_ = 0, cropY0_ = 0, cropX1_ = 1, cropY1_ = 1;
};

}  // namespace bdptref
