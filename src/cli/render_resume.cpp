#include "cli/render_resume.h"

#include "bdptref/errors.h"
#include "bdptref/film_merge.h"

#include <cstdio>
#include <filesystem>
#include <map>
#include <sstream>

namespace bdptref::cli {

namespace {

std::string canonicalVec3(const std::string& text, const std::string& option) {
    if (text.empty()) return "";
    const Vec3 v = parseVec3(text, option);
    char buf[96];
    std::snprintf(buf, sizeof buf, "%.9g,%.9g,%.9g", double(v.x), double(v.y), double(v.z));
    return buf;
}

// The options that decide the pixels and their keys in the settings text (kAttrSettings).
struct SettingOption {
    const char* option;
    const char* key;
};
constexpr SettingOption kSettingOptions[] = {
    {"--width", "width"},           {"--height", "height"},         {"--camera-pos", "cameraPos"},
    {"--camera-target", "cameraTarget"}, {"--camera-up", "cameraUp"}, {"--fov", "fov"},
    {"--env", "env"},               {"--integrator", "integrator"}, {"--mis", "mis"},
    {"--mis-beta", "misBeta"},      {"--max-depth", "maxDepth"},    {"--seed", "seed"},
    {"--crop", "crop"},             {"--strategies", "strategies"}, {"--depth-layers", "depthLayers"},
    {"--light-sampler", "lightSampler"},
    {"--env-map", "envMap"},        {"--env-scale", "envScale"},    {"--env-rotate", "envRotate"},
};

int intOf(const std::string& text, const std::string& what, const std::string& path) {
    try {
        size_t used = 0;
        const long long v = std::stoll(text, &used);
        if (used == text.size() && v >= 0 && v <= 0xFFFFFFFFLL) return int(v);
    } catch (const std::exception&) {
    }
    throw InputError("--resume " + path + ": header setting " + what + " is not a number ('" + text + "')");
}

double numberOf(const std::string& text, const std::string& what, const std::string& path) {
    try {
        size_t used = 0;
        const double v = std::stod(text, &used);
        if (used == text.size()) return v;
    } catch (const std::exception&) {
    }
    throw InputError("--resume " + path + ": header setting " + what + " is not a number ('" + text + "')");
}

}  // namespace

ImageSettings settingsFromArgs(const RenderArgs& a) {
    ImageSettings s;
    s.scenePath = a.scene.scenePath;
    s.width = a.scene.width;
    s.height = a.scene.height;
    s.camera = a.scene.camera;
    if (!a.scene.cameraPos.empty()) {
        s.cameraPos = canonicalVec3(a.scene.cameraPos, "--camera-pos");
        s.cameraTarget = canonicalVec3(a.scene.cameraTarget, "--camera-target");
        s.cameraUp = canonicalVec3(a.scene.cameraUp, "--camera-up");
    }
    s.fovDegrees = a.scene.fovDegrees;
    s.env = canonicalVec3(a.scene.env, "--env");
    s.envMap = a.scene.envMap;
    s.envScale = a.scene.envScale;
    s.envRotate = a.scene.envRotate;
    s.integrator = a.integrator == "pt" ? "path" : a.integrator == "light" ? "lt" : a.integrator;
    s.mis = s.integrator == "bdpt" ? a.mis : "none";
    s.misBeta = a.misBeta;
    s.maxDepth = a.maxDepth;
    s.seed = uint32_t(a.seed);
    s.crop = a.crop;  // validated and made canonical by validateRenderArgs
    s.strategies = a.strategies;
    s.depthLayers = a.depthLayers;
    s.lightSampler = a.lightSampler;
    return s;
}

void applyResumeHeader(const FilmFile& ck, RenderArgs& a) {
    const std::string& path = ck.path;
    const std::string settingsText = ck.attribute(kAttrSettings);
    if (settingsText.empty())
        throw InputError("--resume " + path + ": the header has no " + std::string(kAttrSettings) +
                         " attribute (not written by 'bdptref render' or 'merge')");
    const std::map<std::string, std::string> h = parseSettingsText(settingsText);
    auto header = [&](const char* key) {
        const auto it = h.find(key);
        if (it == h.end()) throw InputError("--resume " + path + ": the header's settings lack '" + key + "'");
        return it->second;
    };
    // 1. Every setting not given comes from the header.
    if (!a.has("scene")) {
        a.scene.scenePath = ck.attribute("bdptref:scene");
        if (a.scene.scenePath.empty())
            throw InputError("--resume " + path + ": the header names no scene (bdptref:scene); give the scene file");
        // The header has the path as the first run was given it (maybe relative to another folder).
        std::error_code ec;
        if (!std::filesystem::is_regular_file(a.scene.scenePath, ec))
            throw InputError("--resume " + path + ": its scene '" + a.scene.scenePath + "' (bdptref:scene) is not found from " +
                             "here; give the scene file as the first argument (its content must hash to " +
                             header("sceneHash") + ")");
    }
    if (!a.has("--width")) a.scene.width = intOf(header("width"), "width", path);
    if (!a.has("--height")) a.scene.height = intOf(header("height"), "height", path);
    if (!a.has("--camera") && h.count("camera")) a.scene.camera = h.at("camera");
    if (!a.has("--camera-pos") && header("cameraPos") != "scene") a.scene.cameraPos = header("cameraPos");
    if (!a.has("--camera-target") && header("cameraTarget") != "scene") a.scene.cameraTarget = header("cameraTarget");
    if (!a.has("--camera-up") && header("cameraUp") != "scene") a.scene.cameraUp = header("cameraUp");
    if (!a.has("--fov") && header("fov") != "scene") a.scene.fovDegrees = numberOf(header("fov"), "fov", path);
    if (!a.has("--env") && header("env") != "none") a.scene.env = header("env");
    if (!a.has("--env-map") && h.count("envMap")) a.scene.envMap = h.at("envMap");
    if (!a.has("--env-scale") && h.count("envScale")) a.scene.envScale = numberOf(h.at("envScale"), "envScale", path);
    if (!a.has("--env-rotate") && h.count("envRotate")) a.scene.envRotate = numberOf(h.at("envRotate"), "envRotate", path);
    if (!a.has("--integrator")) a.integrator = header("integrator");
    if (!a.has("--mis") && header("mis") != "none") a.mis = header("mis");
    if (!a.has("--mis-beta") && header("misBeta") != "unused") a.misBeta = numberOf(header("misBeta"), "misBeta", path);
    if (!a.has("--max-depth")) a.maxDepth = intOf(header("maxDepth"), "maxDepth", path);
    if (!a.has("--seed")) a.seed = intOf(header("seed"), "seed", path);
    if (!a.has("--crop")) a.crop = header("crop") == "none" ? "" : header("crop");
    if (!a.has("--strategies")) a.strategies = header("strategies") == "on";
    if (!a.has("--depth-layers")) a.depthLayers = h.count("depthLayers") && h.at("depthLayers") == "on";
    if (!a.has("--light-sampler")) a.lightSampler = h.count("lightSampler") ? h.at("lightSampler") : "power";
    // The mode changes no bit of the image: the header's unless given (like --threads).
    if (!a.has("--mode") && !ck.attribute("bdptref:mode").empty()) a.mode = ck.attribute("bdptref:mode");
    if (!a.has("--spp") && !a.has("--sample-range")) {
        a.requestedFromHeader = ck.attribute(kAttrSamplesRequested);
        // Files written before kAttrSamplesRequested: from their first sample and bdptref:sppRequested.
        const std::string spp = ck.attribute("bdptref:sppRequested");
        if (a.requestedFromHeader.empty() && !spp.empty() && !ck.film.samples().empty()) {
            const uint64_t first = ck.film.samples().firstIndex();
            const uint64_t n = uint64_t(intOf(spp, "sppRequested", path));
            a.requestedFromHeader = std::to_string(first) + ":" + (n >= 0x7FFFFFFF ? "" : std::to_string(first + n));
        }
    }

    // 2. A setting given on the command line must be the header's.
    const std::map<std::string, std::string> mine = parseSettingsText(::bdptref::cli::settingsText(settingsFromArgs(a)));
    for (const SettingOption& o : kSettingOptions) {
        if (!a.has(o.option)) continue;
        // The --env-map and --depth-layers keys exist only with a map / with the layers.
        const auto m = mine.find(o.key);
        const std::string given = m == mine.end() ? "none" : m->second;
        const auto r = h.find(o.key);
        const std::string recorded = r == h.end() ? "none" : r->second;
        if (given != recorded)
            throw InputError("--resume " + path + ": " + o.option + " conflicts with the checkpoint: it was rendered with " +
                             o.key + "=" + recorded + ", this command gives " + o.key + "=" + given + " (" + o.key + ": " +
                             recorded + " vs " + given + "). With --resume, leave the option out (the header's value is "
                             "used) or give the same value; only --spp, --sample-range, --time and the output, checkpoint, "
                             "thread and message options may change");
    }
}

}  // namespace bdptref::cli
