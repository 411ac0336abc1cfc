#include "cli/render_record.h"

#include <cstdio>

namespace bdptref::cli {

std::string exactNumber(double v) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    return buf;
}

std::string shellQuote(const std::string& s) {
    if (!s.empty() && s.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-+=.,:/@%") ==
                          std::string::npos)
        return s;
    std::string q = "'";
    for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
}

std::string settingsText(const ImageSettings& s) {
    std::string t;
    auto add = [&](const char* key, const std::string& value) { t += std::string(key) + "=" + value + "\n"; };
    add("sceneHash", s.sceneHash);
    add("width", std::to_string(s.width));
    add("height", std::to_string(s.height));
    if (!s.camera.empty()) add("camera", s.camera);  // only when chosen: older headers stay comparable
    add("cameraPos", s.cameraPos.empty() ? "scene" : s.cameraPos);
    add("cameraTarget", s.cameraTarget.empty() ? "scene" : s.cameraTarget);
    add("cameraUp", s.cameraPos.empty() ? "scene" : s.cameraUp);
    add("fov", s.fovDegrees > 0 ? exactNumber(s.fovDegrees) : "scene");
    add("env", s.env.empty() ? "none" : s.env);
    if (!s.envMap.empty()) {  // only with a map: older headers stay comparable
        add("envMap", s.envMap);
        add("envScale", exactNumber(s.envScale));
        add("envRotate", exactNumber(s.envRotate));
    }
    add("integrator", s.integrator);
    add("mis", s.mis);
    add("misBeta", s.mis == "power" ? exactNumber(s.misBeta) : "unused");
    add("maxDepth", std::to_string(s.maxDepth));
    add("seed", std::to_string(s.seed));
    add("crop", s.crop.empty() ? "none" : s.crop);
    add("strategies", s.strategies ? "on" : "off");
    if (s.depthLayers) add("depthLayers", "on");  // only when on: older headers stay comparable
    if (s.lightSampler != "power") add("lightSampler", s.lightSampler);  // likewise
    return t;
}

std::string reproduceCommand(const ImageSettings& s, const SampleRanges& samples, const std::string& output) {
    std::string c = "bdptref render " + shellQuote(s.scenePath) + " --width " + std::to_string(s.width) + " --height " +
                    std::to_string(s.height);
    if (!s.camera.empty()) c += " --camera " + shellQuote(s.camera);
    if (!s.cameraPos.empty())
        c += " --camera-pos " + s.cameraPos + " --camera-target " + s.cameraTarget + " --camera-up " + s.cameraUp;
    if (s.fovDegrees > 0) c += " --fov " + exactNumber(s.fovDegrees);
    if (!s.env.empty()) c += " --env " + s.env;
    if (!s.envMap.empty())
        c += " --env-map " + shellQuote(s.envMap) + " --env-scale " + exactNumber(s.envScale) + " --env-rotate " + exactNumber(s.envRotate);
    c += " --integrator " + s.integrator;
    if (s.integrator == "bdpt") c += " --mis " + s.mis + " --mis-beta " + exactNumber(s.misBeta);
    c += " --max-depth " + std::to_string(s.maxDepth) + " --seed " + std::to_string(s.seed);
    if (!s.crop.empty()) c += " --crop " + s.crop;
    if (s.strategies) c += " --strategies";
    if (s.depthLayers) c += " --depth-layers";
    if (s.lightSampler != "power") c += " --light-sampler " + s.lightSampler;
    return retargetCommand(c + " --sample-range 0:1 -o x", samples, output);
}

std::string retargetCommand(const std::string& command, const SampleRanges& samples, const std::string& output) {
    const size_t at = command.find(" --sample-range ");
    if (at == std::string::npos || samples.empty()) return command;
    const std::string base = command.substr(0, at);  // --sample-range and -o come last
    if (samples.contiguous()) return base + " --sample-range " + samples.text() + " -o " + shellQuote(output);
    std::string c, parts;
    int k = 0;
    for (const SampleRange& r : samples.ranges()) {
        const std::string part = shellQuote(output + ".part" + std::to_string(k++) + ".exr");
        c += base + " --sample-range " + std::to_string(r.begin) + ":" + std::to_string(r.end) + " -o " + part + " && ";
        parts += part + " ";
    }
    return c + "bdptref merge " + parts + "--allow-gaps -o " + shellQuote(output);
}

}  // namespace bdptref::cli
