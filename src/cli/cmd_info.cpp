#include "bdptref/scene.h"
#include "cli/commands.h"
#include "cli/scene_options.h"

#include <cstdio>
#include <memory>

namespace bdptref::cli {

namespace {


int run(const SceneOptions& o) {
    const Scene scene = loadScene(o);
    const SceneInfo& in = scene.info;
    std::printf("scene:        %s\n", in.path.c_str());
    std::printf("content hash: %s\n", in.contentHash.c_str());
    std::printf("triangles:    %zu (vertices %zu)\n", scene.mesh.triangleCount(), scene.mesh.positions.size());
    // World coordinates throughout (the scene holds render space: docs/self-intersection.md), with
    // 7 significant digits (float precision) for geometry, 9 (exact floats) for the camera/origin.
    const DVec3 lo = scene.toWorld(scene.boundsMin()), hi = scene.toWorld(scene.boundsMax());
    std::printf("bounds:       (%.7g, %.7g, %.7g) - (%.7g, %.7g, %.7g), radius %g\n", lo.x, lo.y, lo.z, hi.x, hi.y, hi.z,
                scene.boundingRadius());
    std::printf("materials:    %zu\n", scene.materials.size());
    for (size_t i = 0; i < scene.materials.size(); ++i) {
        const Material& m = scene.materials[i];
        std::printf("  [%zu] %-20s base (%g, %g, %g)%s metallic %g roughness %g ior %g transmission %g specular %g",
                    i, m.name.empty() ? "(unnamed)" : m.name.c_str(), m.baseColor.r, m.baseColor.g, m.baseColor.b,
                    m.baseColorTexture.valid() ? " x texture" : "", m.metallic, m.roughness, m.ior, m.transmission,
                    m.specular);
        if (!isBlack(m.emission))
            std::printf(" emission (%g, %g, %g)%s", m.emission.r, m.emission.g, m.emission.b,
                        m.doubleSided ? " two-sided" : " one-sided");
        if (!isBlack(m.absorption))  // KHR_materials_volume sigma_a per world unit (docs/materials.md)
            std::printf(" absorption (%g, %g, %g) /unit", m.absorption.r, m.absorption.g, m.absorption.b);
        if (!isBlack(m.sheenColor))  // KHR_materials_sheen (docs/materials.md, "Sheen")
            std::printf(" sheen (%g, %g, %g)%s roughness %g%s", m.sheenColor.r, m.sheenColor.g, m.sheenColor.b,
                        m.sheenColorTexture.valid() ? " x texture" : "", m.sheenRoughness,
                        m.sheenRoughnessTexture.valid() ? " x texture" : "");
        if (m.clearcoat > 0.f)  // KHR_materials_clearcoat (docs/materials.md, "Clearcoat")
            std::printf(" clearcoat %g%s roughness %g%s%s", m.clearcoat, m.clearcoatTexture.valid() ? " x texture" : "",
                        m.clearcoatRoughness, m.clearcoatRoughnessTexture.valid() ? " x texture" : "",
                        m.clearcoatNormalTexture.valid() ? " normal map" : "");
        std::printf("\n");
    }
    std::printf("textures:     %zu\n", scene.textures.size());
    size_t area = 0;
    double areaPower = 0;
    for (const Light& l : scene.lights)
        if (l.type == LightType::Area) {
            ++area;
            areaPower += l.power;
        }
    std::printf("lights:       %zu (%zu emissive triangles, total power %g)\n", scene.lights.size(), area, areaPower);
    for (size_t i = 0; i < scene.lights.size(); ++i) {
        const Light& l = scene.lights[i];
        if (l.type == LightType::Area) continue;
        std::printf("  [%zu] %-11s emission (%g, %g, %g) power %g", i, lightTypeName(l.type), l.emission.r,
                    l.emission.g, l.emission.b, l.power);
        if (isDeltaPosition(l)) {
            const DVec3 p = scene.toWorld(l.position);
            std::printf(" at (%.7g, %.7g, %.7g)", p.x, p.y, p.z);
        }
        if (l.type == LightType::Spot || l.type == LightType::Directional)
            std::printf(" direction (%g, %g, %g)", l.direction.x, l.direction.y, l.direction.z);
        if (l.type == LightType::Environment && l.envMap >= 0 && size_t(l.envMap) < scene.environmentMaps.size()) {
            const EnvironmentMap& m = scene.environmentMaps[size_t(l.envMap)];
            std::printf(": %s, %dx%d texels, rotated %g deg about +Y", i < scene.lightNames.size() ? scene.lightNames[i].c_str() : "map",
                        m.width(), m.height(), double(m.rotation()) * 180.0 / 3.14159265358979323846);
        }
        std::printf("\n");
    }
    std::printf("cameras:      %zu in the file%s\n", in.cameras.size(), in.cameras.size() > 1 ? " (choose with --camera N|NAME)" : "");
    for (size_t i = 0; i < in.cameras.size(); ++i) {
        const SceneCameraEntry& e = in.cameras[i];
        auto quoted = [](const std::string& n) { return n.empty() ? std::string() : " '" + n + "'"; };
        std::printf("  [%zu] node %d%s, camera %d%s: %s", i, e.node, quoted(e.nodeName).c_str(), e.camera,
                    quoted(e.cameraName).c_str(), e.type.c_str());
        if (e.type == "perspective")
            std::printf(", yfov %.4g deg, aspectRatio %s", e.yfov * 180.0 / kPi,
                        e.aspectRatio > 0 ? std::to_string(e.aspectRatio).c_str() : "(none)");
        else if (e.type == "orthographic")
            std::printf(", xmag %g, ymag %g", e.xmag, e.ymag);
        if (!e.problem.empty()) std::printf(" (cannot be rendered: %s)", e.problem.c_str());
        std::printf("%s\n", int(i) == in.cameraUsed ? "  <- used" : "");
    }
    const Camera& c = scene.camera;
    const DVec3 eye = scene.toWorld(c.position());
    std::printf("camera:       %s; at (%.9g, %.9g, %.9g) looking (%g, %g, %g), ", in.cameraSource.c_str(), eye.x, eye.y,
                eye.z, c.forward().x, c.forward().y, c.forward().z);
    if (c.isOrthographic())
        std::printf("orthographic xmag %g ymag %g, %dx%d\n", double(c.xmag()), double(c.ymag()), c.width(), c.height());
    else
        std::printf("vertical fov %.4g deg, %dx%d\n", double(c.yfov()) * 180.0 / double(kPi), c.width(), c.height());
    std::printf("render space: world minus (%.9g, %.9g, %.9g) (the camera position)\n", scene.worldOrigin.x,
                scene.worldOrigin.y, scene.worldOrigin.z);
    auto list = [](const std::vector<std::string>& v) {
        std::string s;
        for (const auto& e : v) s += (s.empty() ? "" : ", ") + e;
        return s.empty() ? std::string("none") : s;
    };
    std::printf("extensions:   used %s; ignored %s\n", list(in.extensionsUsed).c_str(), list(in.extensionsIgnored).c_str());
    std::printf("uses:         %s\n", list(in.featuresUsed).c_str());
    std::printf("ignored:      %s\n", list(in.ignoredFeatures).c_str());
    for (const std::string& w : in.warnings) std::printf("warning:      %s\n", w.c_str());
    return 0;
}

}  // namespace

std::function<int()> addInfoCommand(CLI::App& app) {
    auto o = std::make_shared<SceneOptions>();
    CLI::App* cmd = app.add_subcommand("info", "print what a scene contains as loaded (geometry, materials, lights, camera)");
    addSceneOptions(*cmd, *o);
    return [o] { return run(*o); };
}

}  // namespace bdptref::cli
