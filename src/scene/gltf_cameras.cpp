// glTF cameras, and the default camera for a file without one.

#include "scene/gltf_loader_internal.h"

namespace bdptref {
namespace gltfload {

void Loader::addCamera(int nodeIndex, const dmat4& world) {
    const tinygltf::Node& node = model_.nodes[size_t(nodeIndex)];
    const std::string nw = "node " + std::to_string(nodeIndex);
    if (node.camera < 0 || size_t(node.camera) >= model_.cameras.size())
        fail(nw + ": camera " + std::to_string(node.camera) + " does not exist (the file has " + std::to_string(model_.cameras.size()) +
             " cameras)");
    const tinygltf::Camera& cam = model_.cameras[size_t(node.camera)];
    const std::string who = nw + ": camera " + std::to_string(node.camera);
    if (cam.type == "orthographic") fail(who + ": orthographic cameras are not implemented");
    if (cam.type != "perspective") fail(who + ": unknown camera type '" + cam.type + "'");
    if (cameraNode_ >= 0) {
        ++extraCameraNodes_;
        return;
    }
    const double yfov = cam.perspective.yfov;
    if (!(yfov > 0.0) || !(yfov < 3.14159265358979323846))
        fail(who + ": perspective.yfov " + fmt(yfov) + " is not in (0, pi)");
    const dvec3 p(world[3]);
    const dmat3 a(world);
    const double det = glm::determinant(a);
    if (!(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)) || !(std::abs(det) > 0.0) || !std::isfinite(det))
        fail(who + ": the node's transform is degenerate (non-finite or zero scale)");
    if (det < 0.0) warn(who, "the node's transform mirrors (negative determinant); the camera is rendered unmirrored");
    const double aspect = double(options_.width) / double(options_.height);
    if (cam.perspective.aspectRatio > 0.0 && std::abs(cam.perspective.aspectRatio - aspect) > 1e-3 * aspect)
        warn(who, "aspectRatio " + fmt(cam.perspective.aspectRatio) + " differs from the image's " + fmt(aspect) +
             "; the vertical field of view is kept");
    scene_.camera = Camera::fromMatrix(Mat4(world), float(yfov), options_.width, options_.height);
    scene_.hasSceneCamera = true;
    cameraNode_ = nodeIndex;
    scene_.info.cameraSource = "scene node " + (node.name.empty() ? std::string() : "'" + node.name + "' ") + "(node " +
                               std::to_string(nodeIndex) + ", camera " + std::to_string(node.camera) +
                               (cam.name.empty() ? std::string() : " '" + cam.name + "'") + ")";
}

void Loader::defaultCamera() {
    const TriangleMesh& m = scene_.mesh;
    dvec3 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
    bool any = false;
    for (const glm::uvec3& t : m.indices)
        for (int k = 0; k < 3; ++k) {
            const dvec3 p(m.positions[t[k]]);
            lo = glm::min(lo, p);
            hi = glm::max(hi, p);
            any = true;
        }
    dvec3 center(0.0);
    double radius = 1.0;
    if (any) {
        center = 0.5 * (lo + hi);
        double r2 = 0.0;
        for (const glm::uvec3& t : m.indices)
            for (int k = 0; k < 3; ++k) {
                const dvec3 d = dvec3(m.positions[t[k]]) - center;
                r2 = std::max(r2, glm::dot(d, d));
            }
        radius = std::sqrt(r2);
        if (!(radius > 0.0)) radius = 1.0;
    }
    const double yfov = 45.0 * 3.14159265358979323846 / 180.0;
    const double aspect = double(options_.width) / double(options_.height);
    const double tanHalfY = std::tan(0.5 * yfov);
    const double halfMin = std::min(0.5 * yfov, std::atan(tanHalfY * aspect));
    const double distance = radius / std::sin(halfMin);
    const Vec3 target(center);
    const Vec3 eye(center + dvec3(0.0, 0.0, distance));
    scene_.camera = Camera::lookAt(eye, target, Vec3(0.f, 1.f, 0.f), float(yfov), options_.width, options_.height);
    scene_.hasSceneCamera = false;
    scene_.info.cameraSource = "default (no camera in the scene)";
}


}  // namespace gltfload
}  // namespace bdptref
