// The camera with its importance function We (needed by light tracing and the t=1 strategies of
// BDPT): a pinhole perspective camera, or an orthographic one. Derivation: docs/camera.md.
//
// Pinhole: the image plane sits at distance 1 in front of the pinhole and has area
//   A = (2 tan(fovx/2)) * (2 tan(fovy/2)).
// For a direction w making angle theta with the viewing axis and landing inside the image:
//   We(w)      = 1 / (A cos^4 theta)
//   pdfDir(w)  = 1 / (A cos^3 theta)   (solid angle, for uniformly chosen film points)
//   pdfPos     = 1                      (delta position)
// so that the integral of We(w) cos(theta) dw over the sphere is 1.
//
// Orthographic: a film rectangle of half-extents xmag x ymag through the camera position,
// perpendicular to forward; every ray leaves it along forward (a delta direction). With A the film
// (crop window) area:
//   pdfPos = 1/A on the film (area),  pdfDir = 1 (Dirac convention, like the directional light),
//   We     = 1/A                       (importance per unit film area, times the direction's Dirac)
// and the camera subpath's first vertex x1 has area density pdfPosition(x1) |cos_1| = |cos_1| / A.
#pragma once

#include "bdptref/math.h"

#include <string>

namespace bdptref {

// One camera node instance of a scene file, as `bdptref info` lists it (docs/camera.md,
// "Choosing a camera"). `problem` says why it cannot be rendered ("" = it can).
struct SceneCameraEntry {
    int node = -1, camera = -1;  // glTF indices
    std::string nodeName, cameraName;
    std::string type;            // "perspective", "orthographic" or what the file says
    double yfov = 0, aspectRatio = 0, xmag = 0, ymag = 0, znear = 0, zfar = 0;
    std::string problem;
};

struct CameraImportanceSample {
    Vec3 wi;        // unit, from the reference point towards the pinhole
    float dist = 0;  // distance from the reference point to the pinhole
    float pdf = 0;   // solid angle at the reference point (dist^2 / |cos| at the pinhole)
    float We = 0;    // importance along -wi
    Vec2 raster;     // continuous raster position (pixels, origin top-left)
    Vec3 pCamera;    // the camera vertex: the pinhole, or the film point (orthographic)
};

class Camera {
public:
    Camera() = default;
    // yfov in radians; width x height is the full image (crop windows keep the full image's
    // camera so that splats and pixel indices do not change).
    static Camera lookAt(const Vec3& eye, const Vec3& target, const Vec3& up, float yfov, int width, int height);
    static Camera fromMatrix(const Mat4& cameraToWorld, float yfov, int width, int height);
    // Orthographic camera: film of half-height ymag (world units) centred on the camera position;
    // its half-width is ymag * width / height (the vertical extent is kept, like the pinhole's yfov).
    static Camera orthographic(const Mat4& cameraToWorld, float ymag, int width, int height);
    static Camera orthographicLookAt(const Vec3& eye, const Vec3& target, const Vec3& up, float ymag, int width, int height);

    // Primary ray through continuous raster position (x right, y down, in pixels).
    Ray generateRay(Vec2 raster) const;

    // Importance leaving the pinhole in direction w (unit, world); 0 outside the image.
    // `raster` (optional) receives where w lands. Pinhole only (orthographic: 0; see sampleWi and
    // pdfOrthographicVertex, which cover both projections).
    float We(const Vec3& w, Vec2* raster = nullptr) const;
    // Pinhole: pdfPos = 1, pdfDir = 1/(A cos^3). Orthographic: pdfPos = 1/A and pdfDir = 1 (Dirac)
    // for w = forward, else both 0.
    void pdfWe(const Vec3& w, float* pdfPos, float* pdfDir) const;
    // The camera vertex as seen from `ref`: the pinhole, or (orthographic) the film point that
    // ref projects onto along -forward. False when ref is outside the image (crop window) or,
    // orthographic, not in front of the film.
    bool sampleWi(const Vec3& ref, CameraImportanceSample* out) const;
    // Orthographic only: density with which the camera subpath chooses `p` as its first vertex,
    // in area measure at p: cosP / A when p projects inside the image (crop window) in front of
    // the film, else 0 (cosP = |cos| at p between its geometric normal and forward; 1 for a point
    // without a surface). For an environment vertex (`pIsDirection`) the direction is a Dirac
    // factor: 1 (pbrt's convention, as for the directional light). The pinhole's density is
    // pdfWe's direction density converted to area (convertDensity). docs/camera.md.
    double pdfOrthographicVertex(const Vec3& p, double cosP, bool pIsDirection) const;
    // Orthographic only: where p projects on the film (raster), false outside the image (crop
    // window) or behind the film. `filmPoint` (optional) receives the film point.
    bool projectOrthographic(const Vec3& p, Vec2* raster, Vec3* filmPoint = nullptr, float* depth = nullptr) const;

    bool isOrthographic() const { return ortho_; }
    float xmag() const { return tanHalfX_; }  // orthographic half-extents of the film (world units)
    float ymag() const { return tanHalfY_; }

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
    bool ortho_ = false;
    float yfov_ = 0.7f;   // pinhole: vertical field of view; orthographic: unused
    float ymag_ = 1.f;    // orthographic: half-height of the film
    int width_ = 1, height_ = 1;
    float tanHalfX_ = 0, tanHalfY_ = 0, area_ = 0;  // orthographic: the half-extents, the film area
    int cropX0_ = 0, cropY0_ = 0, cropX1_ = 1, cropY1_ = 1;
};

}  // namespace bdptref
