// The diagnosis in validate's report (docs/diagnosis.md): a ValidateReport turned into the small
// per-scene struct `diagnose` takes, and its ranking written for the summary, the JSON and the HTML.
#include "verify/validate_diagnosis.h"

#include "bdptref/errors.h"

#include <cstdio>
#include <cstdlib>
#include <sstream>

namespace bdptref {

namespace {

DiagnosisOutcome outcomeOf(SceneVerdict v) {
    switch (v) {
        case SceneVerdict::Consistent: return DiagnosisOutcome::Passed;
        case SceneVerdict::Inconsistent: return DiagnosisOutcome::Failed;
        default: return DiagnosisOutcome::Untested;
    }
}

// A layer black in the test and the reference (every pixel equal with zero variance) agrees with
// a zero-width interval: it carries no light, so it says nothing about any factor.
bool carriesEvidence(bool hasVerdict, bool consistent, double low, double high) {
    return hasVerdict && !(consistent && low == high);
}

// The layers hold the relative bias b = mean(t - r) / mean(r); the diagnosis reasons in ratios 1 + b.
DiagnosisLayer layerOf(const LayerOutcome& l) {
    return {l.depth, carriesEvidence(l.hasVerdict, l.consistent, l.relativeBiasLow, l.relativeBiasHigh), l.consistent,
            1 + l.relativeBias, 1 + l.relativeBiasLow, 1 + l.relativeBiasHigh};
}

// "depth<d>.<class>": the class (nothing for another name).
std::optional<StrategyClass> classOfLayerName(const std::string& name) {
    const size_t dot = name.find('.');
    return dot == std::string::npos ? std::nullopt : parseStrategyClass(name.substr(dot + 1));
}

// A saved layer: {"layer", "verdict", "relativeBias", "relativeBias95": [low, high]}.
DiagnosisLayer layerOfJson(const nlohmann::json& l, int depth) {
    const std::string v = l.at("verdict").get<std::string>();
    const double b = l.at("relativeBias").get<double>(), low = l.at("relativeBias95").at(0).get<double>(),
                 high = l.at("relativeBias95").at(1).get<double>();
    return {depth, carriesEvidence(v != "no verdict", v == "consistent", low, high), v == "consistent", 1 + b, 1 + low, 1 + high};
}

std::string htmlText(const std::string& s) { return htmlEscaped(s); }

// "units.photometric_683 + diffuse.burley_vs_lambert" for a joint explanation, else the one term.
std::string sceneTerms(const SceneDiagnosis& d) {
    std::string s;
    for (const std::string& t : d.joint) s += (s.empty() ? "" : " + ") + t;
    return s.empty() ? d.best.term : s;
}

std::string percent(double v) {
    char b[32];
    std::snprintf(b, sizeof b, "%.0f%%", 100 * v);
    return b;
}

// A joint explanation's confidence is not the scene-alone ranking's share of its first term (that
// term can rank low on the scene alone: it is the other scenes that name it), so it says whence it is.
std::string sceneConfidence(const SceneDiagnosis& d) {
    return d.joint.empty() ? percent(d.best.confidence) : "named by other scenes";
}

}  // namespace

DiagnosisInput diagnosisInput(const ValidateReport& r) {
    DiagnosisInput in;
    in.estimator = r.options.estimator;
    in.signatures = r.signatures;
    for (const SceneOutcome& o : r.scenes) {
        if (!o.scene) continue;
        DiagnosisScene s;
        s.name = o.scene->name;
        s.outcome = o.layers.empty() ? DiagnosisOutcome::Untested : outcomeOf(o.verdict);
        // A low-power pass could hide an error of a few percent: it speaks against no term.
        if (s.outcome == DiagnosisOutcome::Passed && passPower(o).low) s.outcome = DiagnosisOutcome::Untested;
        s.terms = o.scene->terms;
        s.ior = o.scene->ior;
        s.lightShares = o.scene->lightShares;
        s.strategyShares = o.scene->strategyShares;
        s.emitterShares = o.scene->emitterShares;
        s.maxDepth = o.scene->maxDepth;
        for (const LayerOutcome& l : o.layers) {
            if (l.depth < 0) {
                const DiagnosisLayer b = layerOf(l);
                s.ratio = b.ratio, s.low = b.low, s.high = b.high;
                s.hasMean = l.hasMeanBias;
                s.meanRatio = 1 + l.meanRelativeBias, s.meanLow = 1 + l.meanRelativeBiasLow, s.meanHigh = 1 + l.meanRelativeBiasHigh;
            } else {
                s.depths.push_back(layerOf(l));
            }
        }
        for (const LayerOutcome& l : o.strategyClassLayers)
            if (const std::optional<StrategyClass> c = classOfLayerName(l.layer)) s.classLayers.push_back({*c, layerOf(l)});
        in.scenes.push_back(std::move(s));
    }
    return in;
}

nlohmann::ordered_json diagnosisJson(const ValidateReport& r) { return diagnosisJson(diagnosisInput(r)); }

nlohmann::ordered_json diagnosisJson(const DiagnosisInput& in) {
    nlohmann::ordered_json list = nlohmann::ordered_json::array();
    for (const DiagnosisEntry& e : diagnose(in)) {
        const Term* t = findTerm(e.term);
        list.push_back({{"term", e.term},
                        {"confidence", e.confidence},
                        {"score", e.score},
                        {"description", t ? t->description : ""},
                        {"evidence", e.evidence}});
    }
    return list;
}

// A saved report.json: its scenes' verdicts and layers, with the suite's terms (docs/diagnosis.md,
// "Diagnosing a saved report").
DiagnosisInput diagnosisInputFromJson(const nlohmann::json& report, const Suite& suite) {
    auto scene = [&](const std::string& name) -> const SuiteScene* {
        for (const SuiteScene& s : suite.scenes)
            if (s.name == name) return &s;
        return nullptr;
    };
    DiagnosisInput in;
    in.estimator = parsePortEstimator(report.at("estimator").get<std::string>());
    in.signatures = suite.signatures;
    for (const nlohmann::json& o : report.at("scenes")) {
        const SuiteScene* sc = scene(o.at("name").get<std::string>());
        if (!sc) throw InputError("the report's scene '" + o.at("name").get<std::string>() + "' is not in the suite " + suite.path);
        DiagnosisScene s;
        s.name = sc->name, s.terms = sc->terms, s.ior = sc->ior, s.maxDepth = sc->maxDepth, s.lightShares = sc->lightShares;
        s.strategyShares = sc->strategyShares;
        s.emitterShares = sc->emitterShares;
        const std::string verdict = o.at("verdict").get<std::string>();
        const bool hasLayers = o.contains("layers") && o["layers"].is_array() && !o["layers"].empty();
        s.outcome = !hasLayers ? DiagnosisOutcome::Untested
                    : verdict == sceneVerdictName(SceneVerdict::Inconsistent) ? DiagnosisOutcome::Failed
                    : verdict == sceneVerdictName(SceneVerdict::Consistent) && !o.value("lowPower", false) ? DiagnosisOutcome::Passed
                    : DiagnosisOutcome::Untested;
        for (const nlohmann::json& l : hasLayers ? o["layers"] : nlohmann::json::array()) {
            const std::string name = l.at("layer").get<std::string>();
            if (name != "beauty" && name.rfind("depth", 0) != 0) continue;  // a layer the diagnosis does not read
            const DiagnosisLayer layer = layerOfJson(l, name == "beauty" ? -1 : std::atoi(name.c_str() + 5));
            if (layer.depth >= 0) {
                s.depths.push_back(layer);
                continue;
            }
            s.ratio = layer.ratio, s.low = layer.low, s.high = layer.high;
            if (l.contains("meanRelativeBias") && l.contains("meanRelativeBias95")) {
                s.hasMean = true;
                s.meanRatio = 1 + l["meanRelativeBias"].get<double>();
                s.meanLow = 1 + l["meanRelativeBias95"].at(0).get<double>(), s.meanHigh = 1 + l["meanRelativeBias95"].at(1).get<double>();
            }
        }
        if (hasLayers && o.contains("strategyClassLayers") && o["strategyClassLayers"].is_array())
            for (const nlohmann::json& l : o["strategyClassLayers"]) {
                const std::string name = l.at("layer").get<std::string>();
                if (const std::optional<StrategyClass> c = classOfLayerName(name); c && name.rfind("depth", 0) == 0)
                    s.classLayers.push_back({*c, layerOfJson(l, std::atoi(name.c_str() + 5))});
            }
        in.scenes.push_back(std::move(s));
    }
    return in;
}

std::string diagnosisText(const DiagnosisInput& in) {
    const std::vector<DiagnosisEntry> d = diagnose(in);
    if (d.empty()) return "";
    std::ostringstream s;
    s << "diagnosis (the terms that best explain the failing scenes; docs/diagnosis.md):\n";
    for (size_t i = 0; i < d.size(); ++i) {
        const Term* t = findTerm(d[i].term);
        s << "  " << i + 1 << ". " << d[i].term << " (" << percent(d[i].confidence) << ")"
          << (t ? std::string(": ") + t->description : "") << "\n     " << d[i].evidence << "\n";
    }
    const std::vector<SceneDiagnosis> each = diagnosePerScene(in);
    if (each.size() > 1) {
        s << "  each failing scene alone (several independent differences, e.g. a foreign renderer's conventions):\n";
        for (const SceneDiagnosis& e : each)
            s << "     " << e.scene << ": " << sceneTerms(e) << " (" << sceneConfidence(e) << ")\n";
    }
    return s.str();
}

std::string diagnosisSummaryText(const ValidateReport& r) { return diagnosisText(diagnosisInput(r)); }

std::string diagnosisHtml(const ValidateReport& r) {
    const std::vector<DiagnosisEntry> d = diagnose(diagnosisInput(r));
    if (d.empty()) return "";
    std::ostringstream h;
    h << "<h2>Diagnosis</h2>\n<p>The terms of the estimator that best explain the failing scenes, best first "
         "(docs/diagnosis.md: the score and the term catalogue).</p>\n"
         "<table><tr><th>term</th><th>confidence</th><th>what it is</th><th>evidence</th></tr>\n";
    for (const DiagnosisEntry& e : d) {
        const Term* t = findTerm(e.term);
        h << "<tr><td><code>" << htmlText(e.term) << "</code></td><td>" << percent(e.confidence) << "</td><td>"
          << htmlText(t ? t->description : "") << "</td><td>" << htmlText(e.evidence) << "</td></tr>\n";
    }
    h << "</table>\n";
    const std::vector<SceneDiagnosis> each = diagnosePerScene(diagnosisInput(r));
    if (each.size() > 1) {
        h << "<p>Each failing scene alone (several independent differences, e.g. a foreign renderer's "
             "conventions):</p>\n<table><tr><th>scene</th><th>term</th><th>confidence</th><th>evidence</th></tr>\n";
        for (const SceneDiagnosis& e : each)
            h << "<tr><td>" << htmlText(e.scene) << "</td><td><code>" << htmlText(sceneTerms(e)) << "</code></td><td>"
              << sceneConfidence(e) << "</td><td>" << htmlText(e.best.evidence) << "</td></tr>\n";
        h << "</table>\n";
    }
    return h.str();
}

nlohmann::ordered_json diagnosisPerSceneJson(const ValidateReport& r) { return diagnosisPerSceneJson(diagnosisInput(r)); }

nlohmann::ordered_json diagnosisPerSceneJson(const DiagnosisInput& in) {
    nlohmann::ordered_json list = nlohmann::ordered_json::array();
    for (const SceneDiagnosis& d : diagnosePerScene(in)) {
        nlohmann::ordered_json e = {{"scene", d.scene}, {"term", d.best.term}, {"confidence", d.best.confidence},
                                    {"evidence", d.best.evidence}};
        if (!d.joint.empty()) e["joint"] = d.joint;  // the terms that explain it together, d.best.term first
        list.push_back(std::move(e));
    }
    return list;
}

}  // namespace bdptref
