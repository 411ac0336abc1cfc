// `bdptref info FILE`: what a scene contains as loaded, or, for an EXR, how the image was made
// (its header: docs/exr.md, "Header attributes"), so a reference says which settings a port must use.
#include "bdptref/scene.h"
#include "cli/commands.h"
#include "cli/scene_options.h"
#include "film/exr_read.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <set>

namespace bdptref::cli {

namespace {

// The channels as layers: R, G, B as one, "x.R/G/B" as "x", and each numbered family
// (depth<d>..., s<S>t<T>...) as one entry with its range or count.
std::vector<std::string> layerSummary(const std::vector<std::string>& channels) {
    std::set<std::string> layers;
    for (const std::string& c : channels) {
        const size_t dot = c.rfind('.');
        const std::string last = dot == std::string::npos ? c : c.substr(dot + 1);
        const bool rgb = last == "R" || last == "G" || last == "B";
        layers.insert(!rgb ? c : dot == std::string::npos ? std::string("R,G,B") : c.substr(0, dot));
    }
    // Families: the name with its digit runs replaced by '#'.
    std::map<std::string, std::vector<std::string>> families;
    std::vector<std::string> out;
    for (const std::string& l : layers) {
        std::string key;
        for (size_t i = 0; i < l.size(); ++i)
            if (std::isdigit(static_cast<unsigned char>(l[i]))) {
                if (key.empty() || key.back() != '#') key += '#';
            } else {
                key += l[i];
            }
        if (key == l) out.push_back(l);
        else families[key].push_back(l);
    }
    for (const auto& [key, members] : families) {
        if (members.size() == 1) {
            out.push_back(members.front());
            continue;
        }
        // depth<d>: the range of d; other families (s<S>t<T>): how many.
        if (key.rfind("depth#", 0) == 0) {
            int lo = 1 << 30, hi = -1;
            for (const std::string& m : members) {
                const int d = std::atoi(m.c_str() + 5);
                lo = std::min(lo, d), hi = std::max(hi, d);
            }
            out.push_back("depth" + std::to_string(lo) + ".." + std::to_string(hi) + key.substr(6));
        } else {
            std::string shown = key;
            for (size_t at = shown.find('#'); at != std::string::npos; at = shown.find('#', at)) shown.replace(at, 1, "<n>");
            out.push_back(shown + " (" + std::to_string(members.size()) + ")");
        }
    }
    return out;
}

// The header of a bdptref EXR: its settings, command and provenance (docs/exr.md).
int exrInfo(const std::string& path) {
    const ExrReader file(path);
    const ExrPartInfo& img = file.part(0);
    auto attr = [&](const char* name) {
        const auto it = img.attributes.find(std::string("bdptref:") + name);
        return it == img.attributes.end() ? std::string() : it->second;
    };
    auto line = [](const char* label, const std::string& value) {
        if (!value.empty()) std::printf("%-14s%s\n", label, value.c_str());
    };
    std::printf("%-14s%s: %dx%d pixels", "image:", path.c_str(), img.fullWidth, img.fullHeight);
    if (img.width != img.fullWidth || img.height != img.fullHeight)
        std::printf(" (data window %dx%d at %d,%d)", img.width, img.height, img.x - img.fullX, img.y - img.fullY);
    std::printf(", %d part%s\n", file.parts(), file.parts() == 1 ? "" : "s");
    if (attr("version").empty()) {
        std::printf("%-14snot written by bdptref (no bdptref:* attributes)\n", "made by:");
    } else {
        const std::string mis = attr("mis");
        line("made by:", "bdptref " + attr("version") + (attr("gitRevision").empty() ? "" : " (git " + attr("gitRevision") + ")"));
        line("status:", attr("status"));
        line("integrator:", attr("integrator") + (attr("mode").empty() ? "" : ", " + attr("mode")) +
                                (mis.empty() || mis == "none" ? "" : ", mis " + mis + (mis == "power" ? " beta " + attr("misBeta") : "")));
        line("samples:", attr("spp") + " spp (requested " + attr("sppRequested") + "), sample range " + attr("sampleRanges"));
        line("seed:", attr("seed"));
        line("max depth:", attr("maxDepth"));
        line("scene:", attr("scene") + " (hash " + attr("sceneHash") + ")");
        line("camera:", attr("camera"));
        line("environment:", attr("environment"));
        if (attr("crop") != "none") line("crop:", attr("crop"));
        const std::string seconds = attr("renderSecondsExact").empty() ? attr("renderSeconds") : attr("renderSecondsExact");
        char time[160];
        std::snprintf(time, sizeof time, "%.4g s (load %.3g s, %s threads)", std::atof(seconds.c_str()),
                      std::atof(attr("loadSeconds").c_str()), attr("threads").c_str());
        line("render time:", time);
        line("noise:", attr("relativeStandardError"));
        line("command:", attr("commandLine"));
        line("invocation:", attr("invocation"));
        if (!attr("mergedFrom").empty()) line("merged from:", attr("mergedFrom"));
    }
    std::string layers;
    for (const std::string& l : layerSummary(img.channels)) layers += (layers.empty() ? "" : "; ") + l;
    line("layers:", layers);
    for (int k = 1; k < file.parts(); ++k)
        line("part:", file.part(k).name + " (" + std::to_string(file.part(k).channels.size()) + " channels" +
                          (file.part(k).name == "exact" ? ": the exact film state, for --resume and merge)" : ")"));
    return 0;
}


int run(const SceneOptions& o) {
    if (hasExrMagic(o.scenePath)) return exrInfo(o.scenePath);
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
    CLI::App* cmd = app.add_subcommand("info", "print what a scene contains as loaded (geometry, materials, lights, camera), "
                                               "or, given an EXR, how the image was made (settings, command, scene hash)");
    addSceneOptions(*cmd, *o);
    return [o] { return run(*o); };
}

}  // namespace bdptref::cli
