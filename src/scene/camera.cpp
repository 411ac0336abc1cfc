#include "bdptref/camera.h"

namespace bdptref {

Camera Camera::lookAt(const Vec3& eye, const Vec3& target, const Vec3& up, float yfov, int width, int height) {
    Camera c;
    c.origin_ = eye;
    c.forward_ = glm::normalize(target - eye);
    c.right_ = glm::normalize(glm::cross(c.forward_, up));
    c.up_ = glm::cross(c.right_, c.forward_);
    c.yfov_ = yfov;
    c.width_ = width;
    c.height_ = height;
    c.init();
    return c;
}

Camera Camera::fromMatrix(const Mat4& m, float yfov, int width, int height) {
    // glTF: a camera looks down its local -Z with +Y up. Orthonormalise in case of scale/shear.
    const Vec3 eye(m[3]);
    const Vec3 forward = glm::normalize(-Vec3(m[2]));
    const Vec3 up = glm::normalize(Vec3(m[1]));
    return lookAt(eye, eye + forward, up, yfov, width, height);
}

Camera Camera::orthographicLookAt(const Vec3& eye, const Vec3& target, const Vec3& up, float ymag, int width, int height) {
    Camera c = lookAt(eye, target, up, 0.f, width, height);
    c.ortho_ = true;
    c.ymag_ = ymag;
    c.init();
    return c;
}

Camera Camera::orthographic(const Mat4& m, float ymag, int width, int height) {
    const Vec3 eye(m[3]);
    const Vec3 forward = glm::normalize(-Vec3(m[2]));
    const Vec3 up = glm::normalize(Vec3(m[1]));
    return orthographicLookAt(eye, eye + forward, up, ymag, width, height);
}

Camera Camera::withPosition(const Vec3& position) const {
    Camera c = *this;
    c.origin_ = position;
    return c;
}

Camera Camera::withResolution(int width, int height) const {
    Camera c = *this;
    c.width_ = width;
    c.height_ = height;
    c.init();
    return c;
}

Camera Camera::withCrop(int x0, int y0, int x1, int y1) const {
    Camera c = *this;
    c.cropX0_ = std::max(0, x0);
    c.cropY0_ = std::max(0, y0);
    c.cropX1_ = std::min(width_, x1);
    c.cropY1_ = std::min(height_, y1);
    c.updateArea();
    return c;
}

void Camera::init() {
    // Orthographic: the "image plane" is the film itself, of half-extents tanHalfX_ x tanHalfY_.
    tanHalfY_ = ortho_ ? ymag_ : std::tan(0.5f * yfov_);
    tanHalfX_ = tanHalfY_ * float(width_) / float(height_);
    cropX0_ = cropY0_ = 0;
    cropX1_ = width_;
    cropY1_ = height_;
    updateArea();
}

void Camera::updateArea() {
    // Area of the crop window on the image plane at distance 1 (orthographic: on the film).
    const float fullArea = 4.f * tanHalfX_ * tanHalfY_;
    area_ = fullArea * float(cropX1_ - cropX0_) * float(cropY1_ - cropY0_) / (float(width_) * float(height_));
}

Ray Camera::generateRay(Vec2 raster) const {
    const float sx = (2.f * raster.x / float(width_) - 1.f) * tanHalfX_;
    const float sy = (1.f - 2.f * raster.y / float(height_)) * tanHalfY_;
    Ray r;
    if (ortho_) {  // parallel rays from the film point
        r.origin = origin_ + sx * right_ + sy * up_;
        r.dir = forward_;
        return r;
    }
    r.origin = origin_;
    r.dir = glm::normalize(forward_ + sx * right_ + sy * up_);
    return r;
}

float Camera::We(const Vec3& w, Vec2* raster) const {
    if (ortho_) return 0.f;  // a delta direction: no finite importance per solid angle
    const float cosTheta = glm::dot(w, forward_);
    if (cosTheta <= 0.f) return 0.f;
    const Vec3 q = w / cosTheta;  // point on the image plane at distance 1
    const float sx = glm::dot(q, right_) / tanHalfX_;
    const float sy = glm::dot(q, up_) / tanHalfY_;
    if (!(std::abs(sx) <= 1.f && std::abs(sy) <= 1.f)) return 0.f;
    const Vec2 r(0.5f * (sx + 1.f) * float(width_), 0.5f * (1.f - sy) * float(height_));
    if (!(r.x >= float(cropX0_) && r.x < float(cropX1_) && r.y >= float(cropY0_) && r.y < float(cropY1_))) return 0.f;
    if (raster) *raster = r;
    const float cos2 = cosTheta * cosTheta;
    return 1.f / (area_ * cos2 * cos2);
}

void Camera::pdfWe(const Vec3& w, float* pdfPos, float* pdfDir) const {
    *pdfPos = 0.f;
    *pdfDir = 0.f;
    if (ortho_) {  // uniform film point; the direction is a Dirac factor (1) along forward only
        if (glm::dot(w, forward_) >= 1.f - 1e-6f) {
            *pdfPos = 1.f / area_;
            *pdfDir = 1.f;
        }
        return;
    }
    if (We(w) == 0.f) return;
    const float cosTheta = glm::dot(w, forward_);
    *pdfPos = 1.f;
    *pdfDir = 1.f / (area_ * cosTheta * cosTheta * cosTheta);
}

bool Camera::projectOrthographic(const Vec3& p, Vec2* raster, Vec3* filmPoint, float* depth) const {
    const Vec3 d = p - origin_;
    const float z = glm::dot(d, forward_);
    if (!(z > 0.f)) return false;  // behind the film: no ray reaches it
    const float x = glm::dot(d, right_), y = glm::dot(d, up_);
    const float sx = x / tanHalfX_, sy = y / tanHalfY_;
    if (!(std::abs(sx) <= 1.f && std::abs(sy) <= 1.f)) return false;
    const Vec2 r(0.5f * (sx + 1.f) * float(width_), 0.5f * (1.f - sy) * float(height_));
    if (!(r.x >= float(cropX0_) && r.x < float(cropX1_) && r.y >= float(cropY0_) && r.y < float(cropY1_))) return false;
    if (raster) *raster = r;
    if (filmPoint) *filmPoint = origin_ + x * right_ + y * up_;
    if (depth) *depth = z;
    return true;
}

double Camera::pdfOrthographicVertex(const Vec3& p, double cosP, bool pIsDirection) const {
    if (pIsDirection) return 1.0;  // the Dirac direction (only forward is ever generated)
    if (!projectOrthographic(p, nullptr)) return 0.0;
    return cosP / double(area_);  // uniform film point (1/A), projected onto p's surface
}

bool Camera::sampleWi(const Vec3& ref, CameraImportanceSample* out) const {
    if (ortho_) {
        // The film point that ref projects onto: a delta direction (-forward) with Dirac density
        // 1, and importance 1/A per unit film area (docs/camera.md, "Orthographic").
        Vec2 raster;
        Vec3 film;
        float depth = 0.f;
        if (!projectOrthographic(ref, &raster, &film, &depth)) return false;
        out->wi = -forward_;
        out->dist = depth;
        out->pdf = 1.f;
        out->We = 1.f / area_;
        out->raster = raster;
        out->pCamera = film;
        return true;
    }
    Vec3 wi = origin_ - ref;
    const float dist = glm::length(wi);
    if (!(dist > 0.f)) return false;
    wi /= dist;
    Vec2 raster;
    const float we = We(-wi, &raster);
    if (we == 0.f) return false;
    const float cosCamera = glm::dot(forward_, -wi);
    out->wi = wi;
    out->dist = dist;
    out->pdf = dist * dist / cosCamera;
    out->We = we;
    out->raster = raster;
    out->pCamera = origin_;
    return true;
}

}  // namespace bdptref
