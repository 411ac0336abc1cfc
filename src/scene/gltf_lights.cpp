// KHR_lights_punctual lights.

#include "scene/gltf_loader_internal.h"

namespace bdptref {
namespace gltfload {

// ----- lights and cameras

void Loader::addLight(int nodeIndex, const tinygltf::Value& ext, const dmat4& world) {
    const std::string nw = "node " + std::to_string(nodeIndex);
    if (!ext.IsObject() || !ext.Has("light") || !ext.Get("light").IsInt())
        fail(nw + ": KHR_lights_punctual has no integer 'light' index");
    const int li = ext.Get("light").Get<int>();
    if (li < 0 || size_t(li) >= model_.lights.size())
        fail(nw + ": KHR_lights_punctual light " + std::to_string(li) + " does not exist (the file has " +
             std::to_string(model_.lights.size()) + " lights)");
    const tinygltf::Light& g = model_.lights[size_t(li)];
    const std::string who = nw + ": KHR_lights_punctual light " + std::to_string(li) + (g.name.empty() ? "" : " ('" + g.name + "')");

    Light l;
    if (g.type == "point")
        l.type = LightType::Point;
    else if (g.type == "spot")
        l.type = LightType::Spot;
    else if (g.type == "directional")
        l.type = LightType::Directional;
    else
        fail(who + ": unknown light type '" + g.type + "'");

    Rgb color(1.f);
    if (!g.color.empty()) {
        if (g.color.size() != 3) fail(who + ": color must have 3 elements");
        for (int c = 0; c < 3; ++c)
            color[c] = factor(g.color[size_t(c)], who + ": color[" + std::to_string(c) + "]", 0.0, std::numeric_limits<double>::max());
    }
    const float intensity = factor(g.intensity, who + ": intensity", 0.0, std::numeric_limits<double>::max());
    for (int c = 0; c < 3; ++c)
        l.emission[c] = factor(double(color[c]) * double(intensity), who + ": color * intensity", 0.0, std::numeric_limits<double>::max());
    if (g.range > 0.0) {
        warn(who + " (range " + fmt(g.range) + ")", "range ignored (physically based inverse-square falloff is used)");
        const std::string feature = "KHR_lights_punctual range";
        auto& ignored = scene_.info.ignoredFeatures;
        if (std::find(ignored.begin(), ignored.end(), feature) == ignored.end()) ignored.push_back(feature);
    }
    else if (g.range < 0.0 || !std::isfinite(g.range))
        fail(who + ": invalid range " + fmt(g.range));

    const dvec3 p = dvec3(world[3]);
    const dvec3 d = dmat3(world) * dvec3(0.0, 0.0, -1.0);
    const double dl = glm::length(d);
    if (!(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z))) fail(who + ": position is not finite");
    l.position = Vec3(p);
    if (l.type != LightType::Point) {
        if (!(dl > 0.0) || !std::isfinite(dl)) fail(who + ": the node's transform collapses the light direction (zero scale)");
        l.direction = Vec3(d / dl);
    }
    if (l.type == LightType::Spot) {
        const double inner = g.spot.innerConeAngle, outer = g.spot.outerConeAngle;
        const double halfPi = 1.57079632679489661923;
        if (!std::isfinite(inner) || !std::isfinite(outer) || inner < 0.0 || outer <= 0.0 || outer > halfPi + 1e-9 || inner >= outer)
            fail(who + ": spot cone angles must satisfy 0 <= innerConeAngle < outerConeAngle <= pi/2 (got inner " + fmt(inner) +
                 ", outer " + fmt(outer) + ")");
        l.cosInner = float(std::cos(inner));
        l.cosOuter = float(std::cos(std::min(outer, halfPi)));
    }
    scene_.lights.push_back(l);
    scene_.lightNames.resize(scene_.lights.size() - 1);  // lights added without a name stay unnamed
    scene_.lightNames.push_back(who);
}


}  // namespace gltfload
}  // namespace bdptref
