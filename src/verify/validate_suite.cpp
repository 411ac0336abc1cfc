// The conformance suite's manifest (docs/validate.md, "The suite file"): which scenes, their
// references, the settings a renderer must use, and what each scene exercises.
#include "verify/validate.h"

#include "bdptref/errors.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

namespace fs = std::filesystem;

namespace bdptref {

PortEstimator parsePortEstimator(const std::string& name) {
    if (name == "path") return PortEstimator::Path;
    if (name == "light") return PortEstimator::Light;
    if (name == "bidirectional") return PortEstimator::Bidirectional;
    throw InputError("unknown estimator '" + name + "': use path (a path tracer with next-event estimation), light "
                     "(light tracing) or bidirectional (BDPT, VCM, or anything that samples every path)");
}

const char* portEstimatorName(PortEstimator e) {
    switch (e) {
        case PortEstimator::Path: return "path";
        case PortEstimator::Light: return "light";
        case PortEstimator::Bidirectional: return "bidirectional";
    }
    return "?";
}

const char* lightKindName(LightKind k) {
    switch (k) {
        case LightKind::Area: return "area";
        case LightKind::Punctual: return "punctual";
        case LightKind::Directional: return "directional";
        case LightKind::Environment: return "environment";
    }
    return "?";
}

std::optional<LightKind> parseLightKind(const std::string& name) {
    for (int k = 0; k < kLightKindCount; ++k)
        if (name == lightKindName(LightKind(k))) return LightKind(k);
    return std::nullopt;
}

std::vector<std::string> SuiteScene::renderOptions() const {
    std::vector<std::string> o{"--max-depth", std::to_string(maxDepth)};
    if (!envMap.empty()) {
        o.insert(o.end(), {"--env-map", envMap});
        if (envScale != 1.0) {
            std::ostringstream s;
            s.precision(17);
            s << envScale;
            o.insert(o.end(), {"--env-scale", s.str()});
        }
    }
    if (!envConstant.empty()) o.insert(o.end(), {"--env", envConstant});
    return o;
}

namespace {

using Json = nlohmann::json;

std::vector<std::string> stringList(const Json& j, const char* key, const std::string& where) {
    std::vector<std::string> out;
    if (!j.contains(key)) return out;
    if (!j[key].is_array()) throw InputError(where + ": '" + key + "' must be a list of strings");
    for (const Json& s : j[key]) {
        if (!s.is_string()) throw InputError(where + ": '" + key + "' must be a list of strings");
        out.push_back(s.get<std::string>());
    }
    return out;
}

// A map of known names to shares of the image, each in [0, 1] ("strategyShares", "emitterShares").
std::map<std::string, double> namedShares(const Json& j, const char* key, bool (*known)(const std::string&), const std::string& what) {
    std::map<std::string, double> out;
    if (!j.contains(key)) return out;
    if (!j[key].is_object()) throw InputError(what);
    for (const auto& [k, v] : j[key].items()) {
        if (!known(k) || !v.is_number() || !(v.get<double>() >= 0 && v.get<double>() <= 1)) throw InputError(what + " (got '" + k + "')");
        out[k] = v.get<double>();
    }
    return out;
}

// "emitterShares": {"doubleSidedFromDepth1": 0.22}.
std::map<std::string, double> emitterShares(const Json& j, const std::string& where) {
    return namedShares(j, "emitterShares", [](const std::string& k) { return k == kDoubleSidedFromDepth1Share; },
                       where + ": 'emitterShares' must map doubleSidedFromDepth1 to its share of the image, in [0, 1]");
}

// "strategyShares": {"lightTracing": 0.19, "deepestEmitterHit": 0.5, "emitterHit": 0.6}: the two
// deepest shares and the strategy classes' names.
std::map<std::string, double> strategyShares(const Json& j, const std::string& where) {
    return namedShares(j, "strategyShares",
                       [](const std::string& k) {
                           return k == kDeepestEmitterHitShare || k == kDeepestLightTracingShare || parseStrategyClass(k).has_value();
                       },
                       where + ": 'strategyShares' must map deepestEmitterHit, deepestLightTracing and the strategy classes "
                               "(emitterHit, nextEvent, lightTracing, connections) to their shares of the image, in [0, 1]");
}

// "lightShares": {"area": 0.475, "punctual": 0.525}: known kinds, each share in [0, 1], summing to 1
// (to the 4 decimals light_shares.py writes).
std::map<LightKind, double> lightShares(const Json& j, const std::string& where) {
    std::map<LightKind, double> out;
    if (!j.contains("lightShares")) return out;
    const std::string what = where + ": 'lightShares' must map kinds of light (area, punctual, directional, environment) "
                                     "to their shares of the image, in [0, 1] and summing to 1";
    if (!j["lightShares"].is_object()) throw InputError(what);
    double sum = 0;
    for (const auto& [k, v] : j["lightShares"].items()) {
        const std::optional<LightKind> kind = parseLightKind(k);
        if (!kind || !v.is_number() || !(v.get<double>() >= 0 && v.get<double>() <= 1)) throw InputError(what + " (got '" + k + "')");
        out[*kind] = v.get<double>();
        sum += v.get<double>();
    }
    if (!out.empty() && std::abs(sum - 1) > 1e-3) throw InputError(what + " (they sum to " + std::to_string(sum) + ")");
    return out;
}

std::string existingFile(const fs::path& folder, const Json& j, const char* key, const std::string& where) {
    if (!j.contains(key) || !j[key].is_string()) throw InputError(where + ": '" + key + "' (a file name) is missing");
    const fs::path p = fs::weakly_canonical(folder / j[key].get<std::string>());
    if (!fs::is_regular_file(p)) throw InputError(where + ": " + key + " " + p.string() + " does not exist");
    return p.string();
}

}  // namespace

Suite loadSuite(const std::string& manifestPath) {
    std::ifstream in(manifestPath);
    if (!in) throw InputError("suite " + manifestPath + ": cannot be read");
    Json j;
    try {
        j = Json::parse(in);
    } catch (const std::exception& e) {
        throw InputError("suite " + manifestPath + ": not valid JSON (" + e.what() + ")");
    }
    Suite s;
    s.path = fs::weakly_canonical(manifestPath).string();
    const fs::path folder = fs::path(s.path).parent_path();
    if (!j.is_object() || !j.contains("scenes") || !j["scenes"].is_array() || j["scenes"].empty())
        throw InputError("suite " + manifestPath + ": needs a non-empty 'scenes' list");
    s.width = j.value("width", 64);
    s.height = j.value("height", 64);
    if (s.width < 1 || s.height < 1 || s.width > 4096 || s.height > 4096)
        throw InputError("suite " + manifestPath + ": width and height must be in 1..4096");
    std::set<std::string> names;
    for (const Json& e : j["scenes"]) {
        SuiteScene sc;
        if (!e.is_object() || !e.contains("name") || !e["name"].is_string())
            throw InputError("suite " + manifestPath + ": every scene needs a 'name'");
        sc.name = e["name"].get<std::string>();
        const std::string where = "suite " + manifestPath + ", scene '" + sc.name + "'";
        if (!names.insert(sc.name).second) throw InputError(where + ": the name is used twice");
        sc.scene = existingFile(folder, e, "scene", where);
        sc.reference = existingFile(folder, e, "reference", where);
        sc.maxDepth = e.value("maxDepth", 8);
        if (sc.maxDepth < 0 || sc.maxDepth > 1024) throw InputError(where + ": maxDepth must be in 0..1024");
        if (e.contains("envMap")) sc.envMap = existingFile(folder, e, "envMap", where);
        sc.envScale = e.value("envScale", 1.0);
        sc.envConstant = e.value("env", std::string());
        for (const std::string& k : stringList(e, "estimators", where)) {
            try {
                sc.estimators.push_back(parsePortEstimator(k));
            } catch (const InputError& err) {
                throw InputError(where + ": " + err.what());
            }
        }
        if (sc.estimators.empty()) throw InputError(where + ": 'estimators' (who can render it) is missing");
        if (e.contains("shapes")) {
            if (!e["shapes"].is_object())
                throw InputError(where + ": 'shapes' must map an estimator to a file ({\"light\": \"...exr\"})");
            for (const auto& [k, v] : e["shapes"].items()) {
                PortEstimator pe;
                try {
                    pe = parsePortEstimator(k);
                } catch (const InputError& err) {
                    throw InputError(where + ": shapes: " + err.what());
                }
                sc.shapes[pe] = existingFile(folder, e["shapes"], k.c_str(), where + ", shapes");
            }
        }
        sc.exercises = stringList(e, "exercises", where);
        sc.suspects = stringList(e, "suspects", where);
        sc.terms = stringList(e, "terms", where);  // checked against the catalogue by the tests
        sc.ior = e.value("ior", 0.0);
        sc.lightShares = lightShares(e, where);
        sc.strategyShares = strategyShares(e, where);
        sc.emitterShares = emitterShares(e, where);
        sc.strategyClasses = stringList(e, "strategyClasses", where);
        for (const std::string& c : sc.strategyClasses)
            if (!parseStrategyClass(c))
                throw InputError(where + ": strategyClasses: '" + c + "' is none of emitterHit, nextEvent, lightTracing, connections");
        s.scenes.push_back(std::move(sc));
    }
    if (j.contains("signatures")) {
        const std::string where = "suite " + manifestPath;
        s.signatures = loadSignatures(existingFile(folder, j, "signatures", where));
    }
    return s;
}

std::string defaultSuitePath(const std::string& executable) {
    if (const char* env = std::getenv("BDPTREF_SUITE"); env && *env) {
        if (!fs::is_regular_file(env)) throw InputError("$BDPTREF_SUITE = " + std::string(env) + " is not a file");
        return env;
    }
    std::vector<fs::path> candidates;
    std::error_code ec;
    const fs::path exe = fs::canonical(executable, ec);
    if (!ec) candidates.push_back(exe.parent_path().parent_path() / "share/bdptref/scenes/conformance/suite.json");
#ifdef BDPTREF_SUITE_SOURCE
    candidates.push_back(BDPTREF_SUITE_SOURCE);
#endif
    for (const fs::path& c : candidates)
        if (fs::is_regular_file(c)) return c.string();
    std::string tried;
    for (const fs::path& c : candidates) tried += " " + c.string();
    throw InputError("the conformance suite was not found (tried:" + tried +
                     "); give it with --suite scenes/conformance/suite.json or $BDPTREF_SUITE");
}

}  // namespace bdptref
