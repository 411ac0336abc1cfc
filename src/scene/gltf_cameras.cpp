// glTF cameras: every camera node instance is validated and listed (info.cameras); only the one
// rendered (LoadOptions::camera, else the first in traversal order) can make the file fail, and
// none can when the command line replaces the camera. A file without a camera gets a default view.
// Behaviour: docs/camera.md, "Choosing a camera", "Image size", "The default camera".

#include "scene/gltf_loader_internal.h"

namespace bdptref {
namespace gltfload {

namespace {

std::string describeEntry(size_t index, const SceneCameraEntry& e) {
    std::string s = std::to_string(index) + ": node " + std::to_string(e.node);
    if (!e.nodeName.empty()) s += " '" + e.nodeName + "'";
    s += ", camera " + std::to_string(e.camera);
    if (!e.cameraName.empty()) s += " '" + e.cameraName + "'";
    if (!e.type.empty()) s += " (" + e.type + ")";
    return s;
}

bool allDigits(const std::string& s) {
    return !s.empty() && s.size() < 9 && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

}  // namespace

void Loader::addCamera(int nodeIndex, const dmat4& world) {
    const tinygltf::Node& node = model_.nodes[size_t(nodeIndex)];
    SceneCameraEntry e;
    e.node = nodeIndex;
    e.nodeName = node.name;
    e.camera = node.camera;
    auto problem = [&e](const std::string& what) {
        if (e.problem.empty()) e.problem = what;
    };
    if (node.camera < 0 || size_t(node.camera) >= model_.cameras.size()) {
        problem("camera " + std::to_string(node.camera) + " does not exist (the file has " +
                std::to_string(model_.cameras.size()) + " cameras)");
    } else {
        const tinygltf::Camera& cam = model_.cameras[size_t(node.camera)];
        e.cameraName = cam.name;
        e.type = cam.type;
        if (cam.type == "perspective") {
            e.yfov = cam.perspective.yfov;
            e.aspectRatio = cam.perspective.aspectRatio;
            e.znear = cam.perspective.znear;
            e.zfar = cam.perspective.zfar;
            if (!(e.yfov > 0.0) || !(e.yfov < 3.14159265358979323846))
                problem("perspective.yfov " + fmt(e.yfov) + " is not in (0, pi)");
            else if (e.aspectRatio != 0.0 && !(e.aspectRatio > 0.0 && std::isfinite(e.aspectRatio)))
                problem("perspective.aspectRatio " + fmt(e.aspectRatio) + " is not a positive number");
        } else if (cam.type == "orthographic") {
            e.xmag = cam.orthographic.xmag;
            e.ymag = cam.orthographic.ymag;
            e.znear = cam.orthographic.znear;
            e.zfar = cam.orthographic.zfar;
            // Negative magnifications would mirror the image (the spec says SHOULD NOT): refused
            // rather than rendered differently.
            if (!(e.xmag > 0.0 && std::isfinite(e.xmag)) || !(e.ymag > 0.0 && std::isfinite(e.ymag)))
                problem("orthographic.xmag " + fmt(e.xmag) + " / ymag " + fmt(e.ymag) + " must be positive and finite");
        } else {
            problem("unknown camera type '" + cam.type + "'");
        }
    }
    const dvec3 p(world[3]);
    const double det = glm::determinant(dmat3(world));
    if (!(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)) || !(std::abs(det) > 0.0) || !std::isfinite(det))
        problem("the node's transform is degenerate (non-finite or zero scale)");
    scene_.info.cameras.push_back(e);
    cameraWorlds_.push_back(world);
}

int Loader::chooseCamera() {
    const std::vector<SceneCameraEntry>& list = scene_.info.cameras;
    const std::string& want = options_.camera;
    auto available = [&]() {
        if (list.empty()) return std::string("the file has no cameras");
        std::string s = "the file's cameras (index: node, camera): ";
        for (size_t i = 0; i < list.size(); ++i) s += (i ? "; " : "") + describeEntry(i, list[i]);
        return s;
    };
    if (want.empty()) return list.empty() ? -1 : 0;
    if (allDigits(want)) {
        const size_t i = size_t(std::stoul(want));
        if (i >= list.size()) fail("--camera " + want + ": there is no camera " + want + "; " + available());
        return int(i);
    }
    std::vector<int> hits;
    for (size_t i = 0; i < list.size(); ++i)
        if (list[i].nodeName == want || list[i].cameraName == want) hits.push_back(int(i));
    if (hits.empty()) fail("--camera '" + want + "': no camera node or camera is called that; " + available());
    if (hits.size() > 1) fail("--camera '" + want + "': " + std::to_string(hits.size()) + " cameras have that name; give its index. " + available());
    return hits[0];
}

void Loader::resolveCameras() {
    std::vector<SceneCameraEntry>& list = scene_.info.cameras;
    const int used = options_.cameraFromCommandLine ? -1 : chooseCamera();
    for (size_t i = 0; i < list.size(); ++i)
        if (int(i) != used && !list[i].problem.empty())
            warn("camera " + describeEntry(i, list[i]), "cannot be rendered (" + list[i].problem + "); it is not used");
    if (used < 0) {
        defaultCamera();
        return;
    }
    const SceneCameraEntry& e = list[size_t(used)];
    const std::string who = "node " + std::to_string(e.node) + ": camera " + std::to_string(e.camera);
    if (!e.problem.empty()) fail(who + ": " + e.problem + " (choose another camera with --camera, or give --camera-pos)");
    if (list.size() > 1 && options_.camera.empty())
        warn(std::to_string(list.size()) + " camera nodes in the scene; the first in traversal order is used (--camera N|NAME picks another)");
    const dmat4& world = cameraWorlds_[size_t(used)];
    if (glm::determinant(dmat3(world)) < 0.0)
        warn(who, "the node's transform mirrors (negative determinant); the camera is rendered unmirrored");
    const bool ortho = e.type == "orthographic";
    int w = 0, h = 0;
    imageSize(ortho ? e.xmag / e.ymag : e.aspectRatio, who, ortho ? "xmag/ymag" : "aspectRatio", &w, &h);
    scene_.camera = ortho ? Camera::orthographic(Mat4(world), float(e.ymag), w, h)
                          : Camera::fromMatrix(Mat4(world), float(e.yfov), w, h);
    scene_.hasSceneCamera = true;
    scene_.info.cameraUsed = used;
    scene_.info.cameraSource = "scene camera " + describeEntry(size_t(used), e);
}

void Loader::imageSize(double aspect, const std::string& who, const std::string& what, int* width, int* height) {
    // docs/camera.md, "Image size": a missing side follows the camera's aspect; both given keep
    // the vertical extent (yfov / ymag); neither: the longer side is 256.
    constexpr int kDefault = 256;
    int w = options_.width, h = options_.height;
    if (aspect > 0.0) {
        double dw = w, dh = h;
        if (w > 0 && h > 0) {
            const double image = double(w) / double(h);
            if (std::abs(aspect - image) > 1e-3 * aspect)
                warn(who, what + " " + fmt(aspect) + " differs from the image's " + fmt(image) + " (" + std::to_string(w) + "x" +
                              std::to_string(h) + " from --width and --height); the vertical " +
                              (what == "aspectRatio" ? "field of view" : "extent (ymag)") + " is kept");
        } else if (w > 0) {
            dh = std::max(1.0, std::round(double(w) / aspect));
        } else if (h > 0) {
            dw = std::max(1.0, std::round(double(h) * aspect));
        } else if (aspect >= 1.0) {
            dw = kDefault;
            dh = std::max(1.0, std::round(kDefault / aspect));
        } else {
            dh = kDefault;
            dw = std::max(1.0, std::round(kDefault * aspect));
        }
        if (!(dw <= 65536.0 && dh <= 65536.0))
            fail(who + ": " + what + " " + fmt(aspect) + " gives an image size out of range; give both --width and --height");
        w = int(dw);
        h = int(dh);
    }
    *width = w > 0 ? w : kDefault;
    *height = h > 0 ? h : kDefault;
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
    int w = 0, h = 0;
    imageSize(0.0, "", "", &w, &h);
    const double yfov = 45.0 * 3.14159265358979323846 / 180.0;
    const double aspect = double(w) / double(h);
    const double tanHalfY = std::tan(0.5 * yfov);
    const double halfMin = std::min(0.5 * yfov, std::atan(tanHalfY * aspect));
    const double distance = radius / std::sin(halfMin);
    // Oblique view (docs/camera.md, "The default camera"): from azimuth 45 degrees between +x and
    // +z, elevated 30 degrees, so that three faces of an axis-aligned box show (a view straight
    // down -z sees a box as a flat rectangle). The whole bounding sphere fits the narrower fov.
    const double elevation = 30.0 * 3.14159265358979323846 / 180.0, azimuth = 45.0 * 3.14159265358979323846 / 180.0;
    const dvec3 toEye(std::cos(elevation) * std::sin(azimuth), std::sin(elevation), std::cos(elevation) * std::cos(azimuth));
    const Vec3 target(center);
    const Vec3 eye(center + distance * toEye);
    scene_.camera = Camera::lookAt(eye, target, Vec3(0.f, 1.f, 0.f), float(yfov), w, h);
    scene_.hasSceneCamera = false;
    scene_.info.cameraSource = "default (no camera in the scene)";
}

}  // namespace gltfload
}  // namespace bdptref
