// The report of `bdptref validate`: a summary for the terminal, JSON for scripts, and one HTML page
// with, per scene, what it exercises, the verdict, the bias with its interval, the heatmap, the
// first failing depth and the usual suspects (docs/validate.md, "The report").
#include "verify/validate.h"
#include "verify/validate_diagnosis.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace bdptref {

namespace {

std::string fmt(const char* f, double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, f, v);
    return buf;
}

std::string pText(double p) { return p <= 0 ? "< 1e-300" : fmt("%.3g", p); }
std::string pIs(double p) { return p <= 0 ? "p < 1e-300" : "p = " + fmt("%.3g", p); }

std::string percent(double v) { return fmt("%+.2f%%", 100.0 * v); }

std::string html(const std::string& s) { return htmlEscaped(s); }

nlohmann::ordered_json layersJson(const std::vector<LayerOutcome>& outcomes) {
    nlohmann::ordered_json layers = nlohmann::ordered_json::array();
    for (const LayerOutcome& l : outcomes) {
        nlohmann::ordered_json j = {{"layer", l.layer},
                                    {"p", l.p},
                                    {"verdict", !l.hasVerdict ? "no verdict" : l.consistent ? "consistent" : "inconsistent"},
                                    {"relativeBias", l.relativeBias},
                                    {"relativeBias95", {l.relativeBiasLow, l.relativeBiasHigh}}};
        if (l.hasMeanBias) {
            j["meanRelativeBias"] = l.meanRelativeBias;
            j["meanRelativeBias95"] = {l.meanRelativeBiasLow, l.meanRelativeBiasHigh};
        }
        j["pixelsTested"] = l.tested;
        j["sentence"] = l.sentence;
        layers.push_back(std::move(j));
    }
    return layers;
}

// Scenes that were not chosen or cannot be rendered by the port's estimator get no section.
bool hasSection(const SceneOutcome& o) { return o.verdict != SceneVerdict::Skipped || !o.layers.empty(); }

// "8 renders per scene", or "up to 8" when the budget gave scenes different counts.
std::string rendersPerScene(const ValidateReport& r, int* most) {
    int lo = r.options.renders, hi = 0;
    for (const SceneOutcome& o : r.scenes)
        if (o.renders > 0) {
            lo = std::min(lo, o.renders);
            hi = std::max(hi, o.renders);
        }
    if (hi == 0) hi = lo;  // nothing rendered
    *most = hi;
    return (lo == hi ? "" : "up to ") + std::to_string(hi) + " renders per scene";
}

// Said when the scenes' needs exceeded the budget (allocateSceneBudgets).
std::string budgetShortfall(const ValidateReport& r) {
    if (r.options.spp > 0 || r.budgetSufficient) return "";
    return "the budget (" + fmt("%.0f", r.options.budgetSeconds) +
           " s) was smaller than the scenes' verdicts need (about " + fmt("%.0f", std::ceil(r.budgetNeededSeconds)) +
           " s; docs/validate.md, \"Budget and samples\"): each scene got the same fraction of its need";
}

// "consistent — low power: 26% of pixels tested, bias ±1.3%" for a low-power pass, else the verdict.
std::string verdictText(const SceneOutcome& o) {
    const PassPower pw = passPower(o);
    if (!pw.low) return sceneVerdictName(o.verdict);
    return std::string(sceneVerdictName(o.verdict)) + " — low power: " + fmt("%.0f", 100.0 * pw.testedFraction) +
           "% of pixels tested, bias ±" + fmt("%.2g", 100.0 * pw.biasHalfWidth) + "%";
}

// Said when a scene passed with low power.
std::string lowPowerNote(const ValidateReport& r) {
    const long n = std::count_if(r.scenes.begin(), r.scenes.end(), [](const SceneOutcome& o) { return passPower(o).low; });
    if (n == 0) return "";
    return std::to_string(n) + (n == 1 ? " scene passed" : " scenes passed") +
           " with low power (fewer than " + fmt("%.0f", 100.0 * kLowPowerTestedFraction) +
           "% of the pixels with noise tested, or a bias 95% interval wider than ±" + fmt("%.2g", 100.0 * kLowPowerBiasHalfWidth) +
           "%): an error of a few percent could pass there; a larger --budget or --spp tests more (docs/validate.md, "
           "\"Low-power passes\")";
}

}  // namespace

PassPower passPower(const SceneOutcome& o) {
    PassPower p;
    if (o.layers.empty()) return p;
    const LayerOutcome& b = o.layers.front();
    const uint64_t noisy = b.compared > b.equal ? b.compared - b.equal : 0;
    p.testedFraction = noisy > 0 ? double(b.tested) / double(noisy) : 0.0;
    p.biasHalfWidth = 0.5 * (b.relativeBiasHigh - b.relativeBiasLow);
    p.low = o.verdict == SceneVerdict::Consistent &&
            (p.testedFraction < kLowPowerTestedFraction || p.biasHalfWidth > kLowPowerBiasHalfWidth);
    return p;
}

std::string validateReportJson(const ValidateReport& r) {
    nlohmann::ordered_json j;
    j["suite"] = r.suitePath;
    j["renderer"] = r.command;
    j["estimator"] = portEstimatorName(r.options.estimator);
    j["budgetSeconds"] = r.options.spp > 0 ? 0.0 : r.options.budgetSeconds;
    if (r.options.spp <= 0) {
        j["budgetNeededSeconds"] = r.budgetNeededSeconds;
        j["budgetSufficient"] = r.budgetSufficient;
    }
    j["rendersPerScene"] = r.options.renders;
    j["alpha"] = r.options.alpha;
    j["alphaPerScene"] = r.alphaPerScene;
    j["seedBase"] = r.options.seedBase;
    j["seconds"] = r.seconds;
    j["interrupted"] = r.interrupted;
    j["exitCode"] = r.exitCode;
    j["verdict"] = r.exitCode == 0 ? "consistent" : r.exitCode == 1 ? "inconsistent" : "no verdict";
    nlohmann::ordered_json scenes = nlohmann::ordered_json::array();
    for (const SceneOutcome& o : r.scenes) {
        nlohmann::ordered_json s;
        s["name"] = o.scene->name;
        s["verdict"] = sceneVerdictName(o.verdict);
        if (!o.message.empty()) s["message"] = o.message;
        s["exercises"] = o.scene->exercises;
        s["suspects"] = o.scene->suspects;
        if (o.spp > 0) {
            s["spp"] = o.spp;
            s["renders"] = o.renders;
            s["renderSeconds"] = o.renderSeconds;
            if (!o.testShape.empty()) s["testShape"] = o.testShape;
        }
        if (o.samplesNeeded > 0) {  // sized to the budget (docs/validate.md, "Budget and samples")
            s["budgetShareSeconds"] = o.budgetShareSeconds;
            s["samplesNeeded"] = o.samplesNeeded;
            s["referenceShape"] = o.referenceShape;
            s["pilotFixedSeconds"] = o.fixedSeconds;
            s["pilotSecondsPerSample"] = o.secondsPerSample;
            nlohmann::ordered_json pilots = nlohmann::ordered_json::array();
            for (const PilotTiming& t : o.pilots) pilots.push_back({{"spp", t.spp}, {"seconds", t.seconds}});
            s["pilots"] = pilots;
        }
        if (!o.layers.empty()) {
            const PassPower pw = passPower(o);
            s["lowPower"] = pw.low;
            s["pixelsTestedFraction"] = pw.testedFraction;
            s["biasHalfWidth95"] = pw.biasHalfWidth;
            s["p"] = o.p;
            s["firstFailingDepth"] = o.firstFailingDepth >= 0 ? nlohmann::ordered_json(o.firstFailingDepth) : nullptr;
            s["layers"] = layersJson(o.layers);
            if (!o.strategyClassLayers.empty()) s["strategyClassLayers"] = layersJson(o.strategyClassLayers);
            s["heatmap"] = o.heatmap;
        }
        scenes.push_back(s);
    }
    j["scenes"] = scenes;
    j["diagnosis"] = diagnosisJson(r);  // docs/diagnosis.md
    j["diagnosisPerScene"] = diagnosisPerSceneJson(r);
    return j.dump(2) + "\n";
}

namespace {

// "; strategy classes: nextEvent fails (depths 1, 2), lightTracing and connections agree": which
// kinds of BDPT strategy carry an inconsistent scene's error (docs/validate.md, "Strategy classes").
std::string strategyClassSummary(const SceneOutcome& o) {
    if (o.verdict != SceneVerdict::Inconsistent || o.strategyClassLayers.empty()) return "";
    std::vector<std::string> failing, agreeing;
    for (int c = 0; c < kStrategyClassCount; ++c) {
        const std::string name = strategyClassName(StrategyClass(c));
        std::string depths;
        bool tested = false;
        for (const LayerOutcome& l : o.strategyClassLayers) {
            if (l.layer.size() <= name.size() || l.layer.compare(l.layer.size() - name.size(), name.size(), name) != 0 ||
                !l.hasVerdict)
                continue;
            tested = true;
            if (!l.consistent) depths += (depths.empty() ? "" : ", ") + std::to_string(l.depth);
        }
        if (!depths.empty()) failing.push_back(name + " (depth" + (depths.find(',') == std::string::npos ? " " : "s ") + depths + ")");
        else if (tested) agreeing.push_back(name);
    }
    auto list = [](const std::vector<std::string>& v) {
        std::string t;
        for (size_t i = 0; i < v.size(); ++i) t += (i == 0 ? "" : i + 1 == v.size() ? " and " : ", ") + v[i];
        return t;
    };
    std::string out = "; strategy classes: ";
    if (!failing.empty()) out += list(failing) + (failing.size() == 1 ? " fails" : " fail");
    if (!agreeing.empty()) out += std::string(failing.empty() ? "" : ", ") + list(agreeing) + (agreeing.size() == 1 ? " agrees" : " agree");
    return out;
}

}  // namespace

std::string validateSummaryText(const ValidateReport& r) {
    std::ostringstream s;
    s << "suite " << r.suitePath << "\n";
    for (const SceneOutcome& o : r.scenes) {
        char line[160];
        const std::string verdict = verdictText(o) + (passPower(o).low ? "," : "");  // then the figures
        std::snprintf(line, sizeof line, "  %-22s %-16s", o.scene->name.c_str(), verdict.c_str());
        s << line;
        if (!o.layers.empty()) {
            const LayerOutcome& b = o.layers.front();
            s << " " << pIs(o.p) << ", bias " << percent(b.relativeBias) << " [" << percent(b.relativeBiasLow)
              << ", " << percent(b.relativeBiasHigh) << "], " << o.spp << " spp x " << o.renders;
            if (o.firstFailingDepth >= 0) s << ", first failing depth " << o.firstFailingDepth;
            s << strategyClassSummary(o);
        }
        if (!o.message.empty() && o.verdict != SceneVerdict::Consistent) s << " - " << o.message;
        s << "\n";
    }
    const std::string shortfall = budgetShortfall(r);
    if (!shortfall.empty()) s << "note: " << shortfall << "\n";
    const std::string lowPower = lowPowerNote(r);
    if (!lowPower.empty()) s << "note: " << lowPower << "\n";
    s << diagnosisSummaryText(r);
    s << (r.exitCode == 0   ? "CONSISTENT: every scene agrees with its reference"
          : r.exitCode == 1 ? "INCONSISTENT: at least one scene disagrees with its reference"
                            : "NO VERDICT: a scene could not be rendered or tested")
      << " (suite alpha " << r.options.alpha << ", per scene " << fmt("%.3g", r.alphaPerScene) << "; "
      << fmt("%.0f", r.seconds) << " s)" << (r.interrupted ? " - interrupted" : "") << "\n";
    return s.str();
}

std::string validateReportHtml(const ValidateReport& r) {
    std::ostringstream h;
    h << "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>bdptref validate</title><style>\n"
         "body{font-family:sans-serif;margin:2em;max-width:70em}table{border-collapse:collapse}"
         "td,th{border:1px solid #ccc;padding:4px 8px;vertical-align:top}.bad{color:#b00;font-weight:bold}"
         ".ok{color:#070}.nv{color:#a60}img{image-rendering:pixelated;width:192px}.scene{margin-top:2em}\n"
         "</style></head><body>\n<h1>bdptref validate</h1>\n";
    const char* cls = r.exitCode == 0 ? "ok" : r.exitCode == 1 ? "bad" : "nv";
    int most = 0;
    const std::string renders = rendersPerScene(r, &most);
    h << "<p class=\"" << cls << "\">"
      << html(r.exitCode == 0   ? "Consistent: every scene agrees with its reference."
              : r.exitCode == 1 ? "Inconsistent: at least one scene disagrees with its reference."
                                : "No verdict: a scene could not be rendered or tested.")
      << "</p>\n<p>Renderer: <code>" << html(r.command) << "</code><br>Suite: " << html(r.suitePath)
      << "<br>Estimator: " << portEstimatorName(r.options.estimator) << "; false-alarm rate of the suite "
      << r.options.alpha << " (per scene " << fmt("%.3g", r.alphaPerScene) << ", Šidák); " << renders
      << " (seeds " << r.options.seedBase << ", " << r.options.seedBase + kRenderSeedSpacing << ", …, "
      << r.options.seedBase + kRenderSeedSpacing * uint32_t(most - 1) << "); "
      << fmt("%.0f", r.seconds) << " s" << (r.interrupted ? " (interrupted)" : "") << ".</p>\n";
    const std::string shortfall = budgetShortfall(r);
    if (!shortfall.empty()) h << "<p class=\"nv\">Note: " << html(shortfall) << ".</p>\n";
    const std::string lowPower = lowPowerNote(r);
    if (!lowPower.empty()) h << "<p class=\"nv\">Note: " << html(lowPower) << ".</p>\n";
    h << "<table><tr><th>scene</th><th>verdict</th><th>p</th><th>bias (95% CI)</th><th>first failing depth</th>"
         "<th>spp × renders</th></tr>\n";
    for (const SceneOutcome& o : r.scenes) {
        const char* c = passPower(o).low                          ? "nv"
                        : o.verdict == SceneVerdict::Consistent   ? "ok"
                        : o.verdict == SceneVerdict::Inconsistent ? "bad"
                                                                  : "nv";
        h << "<tr><td><a href=\"#" << html(o.scene->name) << "\">" << html(o.scene->name) << "</a></td><td class=\"" << c
          << "\">" << html(verdictText(o)) << "</td>";
        if (!o.layers.empty()) {
            const LayerOutcome& b = o.layers.front();
            h << "<td>" << pText(o.p) << "</td><td>" << percent(b.relativeBias) << " (" << percent(b.relativeBiasLow)
              << ", " << percent(b.relativeBiasHigh) << ")</td><td>"
              << (o.firstFailingDepth >= 0 ? std::to_string(o.firstFailingDepth) : std::string("–")) << "</td><td>" << o.spp
              << " × " << o.renders << "</td>";
        } else {
            h << "<td colspan=\"4\">" << html(o.message) << "</td>";
        }
        h << "</tr>\n";
    }
    h << "</table>\n";
    h << diagnosisHtml(r);
    for (const SceneOutcome& o : r.scenes) {
        if (!hasSection(o)) continue;
        h << "<div class=\"scene\" id=\"" << html(o.scene->name) << "\"><h2>" << html(o.scene->name) << "</h2>\n";
        h << "<p>Exercises:</p><ul>";
        for (const std::string& e : o.scene->exercises) h << "<li>" << html(e) << "</li>";
        h << "</ul>\n";
        if (!o.message.empty()) h << "<p class=\"nv\">" << html(o.message) << "</p>\n";
        if (passPower(o).low) h << "<p class=\"nv\">" << html(verdictText(o)) << ".</p>\n";
        if (!o.layers.empty()) {
            h << "<table><tr><th>test (mean of the renders)</th><th>reference</th><th>z-scores (blue: darker, red: brighter)"
                 "</th></tr><tr><td><img src=\""
              << html(o.testPreview) << "\"></td><td><img src=\"" << html(o.referencePreview) << "\"></td><td><img src=\""
              << html(o.heatmap) << "\"></td></tr></table>\n";
            h << "<table><tr><th>layer</th><th>verdict</th><th>p</th><th>bias (95% CI)</th><th>pixels tested</th></tr>\n";
            auto rows = [&](const std::vector<LayerOutcome>& layers, bool imageMean) {
                for (const LayerOutcome& l : layers) {
                    const char* lc = !l.hasVerdict ? "nv" : l.consistent ? "ok" : "bad";
                    h << "<tr><td>" << l.layer << "</td><td class=\"" << lc << "\">"
                      << (!l.hasVerdict ? "no verdict" : l.consistent ? "consistent" : "inconsistent") << "</td><td>" << pText(l.p)
                      << "</td><td>" << percent(l.relativeBias) << " (" << percent(l.relativeBiasLow) << ", "
                      << percent(l.relativeBiasHigh) << ")</td><td>";
                    if (imageMean) h << "image mean";
                    else h << l.tested << " / " << l.compared;
                    h << "</td></tr>\n";
                }
            };
            rows(o.layers, false);
            rows(o.strategyClassLayers, true);  // docs/validate.md, "Strategy classes"
            h << "</table>\n";
            if (o.layers.size() == 1)
                h << "<p>No depth layers: a renderer that writes <code>depth&lt;d&gt;.R/G/B</code> (docs/validate.md) is told "
                     "at which path depth it goes wrong.</p>\n";
        }
        if (o.verdict == SceneVerdict::Inconsistent && !o.scene->suspects.empty()) {
            h << "<p>Usual suspects when this scene fails:</p><ul>";
            for (const std::string& s : o.scene->suspects) h << "<li>" << html(s) << "</li>";
            h << "</ul>\n";
        }
        h << "</div>\n";
    }
    h << "</body></html>\n";
    return h.str();
}

std::string htmlEscaped(const std::string& s) {
    std::string o;
    for (char c : s) {
        switch (c) {
            case '<': o += "&lt;"; break;
            case '>': o += "&gt;"; break;
            case '&': o += "&amp;"; break;
            case '"': o += "&quot;"; break;
            default: o += c;
        }
    }
    return o;
}

}  // namespace bdptref
