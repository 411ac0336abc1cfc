// Reading the suite's bug signatures (validate_signatures.h; docs/diagnosis.md, "Bug signatures").
#include "verify/validate_signatures.h"

#include "verify/validate.h"

#include "bdptref/errors.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>

namespace bdptref {

namespace {

using Json = nlohmann::json;

double finiteNumber(const Json& j, const char* key, const std::string& where) {
    if (!j.contains(key) || !j[key].is_number() || !std::isfinite(j[key].get<double>()))
        throw InputError(where + ": '" + key + "' must be a finite number");
    return j[key].get<double>();
}

// An optional list of strategy class names as StrategyClass bits.
unsigned classBits(const Json& j, const char* key, const std::string& where) {
    if (!j.contains(key)) return 0;
    if (!j[key].is_array()) throw InputError(where + ": '" + key + "' must list strategy classes");
    unsigned bits = 0;
    for (const Json& c : j[key]) {
        const std::optional<StrategyClass> sc = c.is_string() ? parseStrategyClass(c.get<std::string>()) : std::nullopt;
        if (!sc) throw InputError(where + ": '" + key + "' holds " + c.dump() + ", not a strategy class");
        bits |= 1u << unsigned(*sc);
    }
    return bits;
}

SignatureScene sceneOf(const std::string& name, const Json& j, const std::string& where) {
    if (!j.is_object() || !j.contains("failed") || !j["failed"].is_boolean())
        throw InputError(where + ": needs \"failed\": true or false");
    SignatureScene s;
    s.name = name;
    s.failed = j["failed"].get<bool>();
    s.ratio = finiteNumber(j, "ratio", where);
    s.low = finiteNumber(j, "low", where);
    s.high = finiteNumber(j, "high", where);
    if (!(s.low <= s.ratio && s.ratio <= s.high)) throw InputError(where + ": needs low <= ratio <= high");
    s.testedClasses = classBits(j, "testedClasses", where);
    s.failedClasses = classBits(j, "failedClasses", where);
    if ((s.failedClasses & ~s.testedClasses) != 0) throw InputError(where + ": a failed class that was not tested");
    return s;
}

}  // namespace

std::vector<BugSignature> loadSignatures(const std::string& path) {
    std::ifstream in(path);
    if (!in) throw InputError("signatures " + path + ": cannot be read");
    Json j;
    try {
        j = Json::parse(in);
    } catch (const std::exception& e) {
        throw InputError("signatures " + path + ": not valid JSON (" + e.what() + ")");
    }
    if (!j.is_object() || !j.contains("signatures") || !j["signatures"].is_array())
        throw InputError("signatures " + path + ": needs a 'signatures' list");
    std::vector<BugSignature> out;
    for (const Json& e : j["signatures"]) {
        const std::string where = "signatures " + path + ", entry " + std::to_string(out.size() + 1);
        BugSignature b;
        for (auto [key, field] : {std::pair{"bug", &b.bug}, std::pair{"term", &b.term}, std::pair{"estimator", &b.estimator}}) {
            if (!e.is_object() || !e.contains(key) || !e[key].is_string()) throw InputError(where + ": '" + key + "' is missing");
            *field = e[key].get<std::string>();
        }
        if (b.estimator != "path" && b.estimator != "light" && b.estimator != "bidirectional")
            throw InputError(where + ": estimator must be path, light or bidirectional");
        if (!e.contains("scenes") || !e["scenes"].is_object()) throw InputError(where + ": 'scenes' must map a scene to its result");
        for (const auto& [name, s] : e["scenes"].items()) b.scenes.push_back(sceneOf(name, s, where + ", scene '" + name + "'"));
        out.push_back(std::move(b));
    }
    return out;
}

}  // namespace bdptref
