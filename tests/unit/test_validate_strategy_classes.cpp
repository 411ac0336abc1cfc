// Strategy classes (docs/validate.md and docs/diagnosis.md, "Strategy classes"): a bidirectional
// port's unweighted strategy layers averaged per class and compared with the reference's depth
// layers, and what the diagnosis reads from them. What is proven:
//  - the classes of (s,t) and their names; a suite naming an unknown class is refused;
//  - on synthetic renders (no rendering): the class whose strategies are off by 10% is
//    inconsistent with a ratio whose interval holds 0.9, the others are consistent, a class that
//    is zero in every render or whose layers are malformed is not compared (with the reason), and
//    a scene that lists no classes gets none;
//  - the diagnosis: every class agreeing while the beauty grows with depth puts the MIS weights
//    first (every scene of a bidirectional port exercises them); the next events alone failing add kClassMatch to a next-event term and take kClassAgainst
//    from a light-tracing one, on each failing scene that exercises them;
//  - a path tracer's port: only its emitter hits and next events are compared and read; its next
//    events failing alone speak for a next-event term and against the MIS weights, both agreeing
//    while the beauty fails for the weights and against a BSDF term;
//  - the report: JSON, summary and HTML list the class layers, and a live or saved report's class
//    layers reach the diagnosis (bdptref diagnose).
#include "support/diagnosis_fixtures.h"
#include "support/render_util.h"
#include "verify/validate_diagnosis.h"

#include "bdptref/bdptref.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <fstream>
#include <functional>
#include <random>

using namespace bdptref;
using namespace bdptref::test;

namespace {

constexpr int kSide = 16;

std::string unweighted(int s, int t, const char* ch) {
    return "s" + std::to_string(s) + "t" + std::to_string(t) + ".unweighted." + ch;
}

// A reference whose depth-0 and depth-1 layers are 0.5 everywhere, known to a variance of the mean of 1e-8.
ExrImage referenceImage() {
    ExrImage r;
    r.width = r.height = kSide;
    const size_t n = size_t(kSide) * kSide;
    for (const char* ch : {"R", "G", "B"}) {
        r.channels[ch] = std::vector<float>(n, 0.5f);
        for (const std::string layer : {"depth0.", "depth1."}) {
            r.channels[layer + ch] = std::vector<float>(n, 0.5f);
            r.channels[layer + "variance." + ch] = std::vector<float>(n, 1e-8f);
        }
    }
    return r;
}

// Render k of a port whose depth-1 strategies (s0t3: emitter hit, s1t2: next event, s2t1: light
// tracing) each estimate 0.5 with 5% noise per pixel, the next events scaled by `nextEventScale`,
// and s3t0-like layers absent; a zero layer s0t2 (depth 0) as a class with no light.
ExrImage portRender(uint32_t seed, double nextEventScale) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0.0, 0.05);
    ExrImage r;
    r.width = r.height = kSide;
    const size_t n = size_t(kSide) * kSide;
    for (const char* ch : {"R", "G", "B"}) {
        r.channels[ch] = std::vector<float>(n, 0.5f);
        r.channels[unweighted(0, 2, ch)] = std::vector<float>(n, 0.f);
        for (const auto& [s, t, scale] : {std::tuple{0, 3, 1.0}, std::tuple{1, 2, nextEventScale}, std::tuple{2, 1, 1.0}}) {
            std::vector<float>& v = r.channels[unweighted(s, t, ch)];
            v.resize(n);
            for (float& x : v) x = float(0.5 * scale * (1 + noise(rng)));
        }
    }
    return r;
}

// Eight renders of that port (seeds firstSeed, firstSeed + 1, ...).
std::vector<ExrImage> portRenders(uint32_t firstSeed, double nextEventScale) {
    std::vector<ExrImage> renders;
    for (uint32_t k = 0; k < 8; ++k) renders.push_back(portRender(firstSeed + k, nextEventScale));
    return renders;
}

// A scene of the synthetic suite that compares all four classes.
SuiteScene everyClassScene() {
    SuiteScene scene;
    scene.name = "synthetic";
    scene.strategyClasses = {"emitterHit", "nextEvent", "lightTracing", "connections"};
    return scene;
}

const LayerOutcome* layerNamed(const SceneOutcome& o, const std::string& name) {
    for (const LayerOutcome& l : o.strategyClassLayers)
        if (l.layer == name) return &l;
    return nullptr;
}

// The class layers of a scene the suite compares them on: every listed class at depths 1..3, with
// ratio `ratioOf(class, depth)` known to +-0.5%.
void addClassLayers(DiagnosisScene& d, const SuiteScene& s, const std::function<double(StrategyClass, int)>& ratioOf) {
    for (const std::string& name : s.strategyClasses)
        for (int depth = 1; depth <= 3; ++depth) {
            const StrategyClass c = *parseStrategyClass(name);
            if (c == StrategyClass::Connections && depth < 2) continue;
            d.classLayers.push_back({c, layerAt(depth, ratioOf(c, depth), 0.005)});
        }
}

// A failing scene's result: beauty ratio `beauty`, depth k at atDepth(k), and with `withClasses`
// its class layers at classRatio(class, depth).
std::function<DiagnosisScene(const SuiteScene&)> failing(bool withClasses, double beauty, std::function<double(int)> atDepth,
                                                         std::function<double(StrategyClass, int)> classRatio) {
    return [=](const SuiteScene& s) {
        DiagnosisScene d = result(s, beauty, atDepth);
        if (withClasses) addClassLayers(d, s, classRatio);
        return d;
    };
}

double agreeing(StrategyClass, int) { return 1.0; }

double scoreOf(const DiagnosisInput& in, const std::string& term) { return entryOf(in, term).score; }

}  // namespace

TEST_CASE("strategy classes: the class of each (s,t) and the names", "[validate][strategy-classes]") {
    CHECK(strategyClassOf(0, 2) == StrategyClass::EmitterHit);
    CHECK(strategyClassOf(0, 5) == StrategyClass::EmitterHit);
    CHECK(strategyClassOf(1, 2) == StrategyClass::NextEvent);
    CHECK(strategyClassOf(1, 1) == StrategyClass::LightTracing);
    CHECK(strategyClassOf(4, 1) == StrategyClass::LightTracing);
    CHECK(strategyClassOf(2, 2) == StrategyClass::Connections);
    for (int c = 0; c < kStrategyClassCount; ++c) CHECK(parseStrategyClass(strategyClassName(StrategyClass(c))) == StrategyClass(c));
    CHECK(!parseStrategyClass("nee"));
    // Every scene's classes load (the loader refuses unknown names), and only bidirectional scenes list them.
    for (const SuiteScene& s : shippedSuite().scenes)
        if (!s.strategyClasses.empty()) CHECK(renders(s, PortEstimator::Bidirectional));
    const std::string dir = makeTempDir("validate-classes");
    std::ofstream(dir + "/s.gltf") << "{}";
    std::ofstream(dir + "/r.exr") << "x";
    std::ofstream(dir + "/suite.json") << R"({"scenes": [{"name": "a", "scene": "s.gltf", "reference": "r.exr", "estimators": ["bidirectional"], "strategyClasses": ["nextEvent", "nee"]}]})";
    CHECK_THROWS_WITH(loadSuite(dir + "/suite.json"), Catch::Contains("strategyClasses") && Catch::Contains("'nee'"));
}

TEST_CASE("strategy classes: a class off by 10% is inconsistent, the others consistent, an empty one not compared", "[validate][strategy-classes]") {
    const SuiteScene scene = everyClassScene();
    const std::vector<ExrImage> renders = portRenders(7, 0.9);
    SceneOutcome o;
    o.scene = &scene;
    compareStrategyClasses(renders, referenceImage(), {0, 1}, 0.01, o);
    const LayerOutcome* hit = layerNamed(o, "depth1.emitterHit");
    const LayerOutcome* nee = layerNamed(o, "depth1.nextEvent");
    const LayerOutcome* lt = layerNamed(o, "depth1.lightTracing");
    const LayerOutcome* empty = layerNamed(o, "depth0.emitterHit");
    REQUIRE(hit);
    REQUIRE(nee);
    REQUIRE(lt);
    REQUIRE(empty);
    CHECK(!layerNamed(o, "depth1.connections"));  // no s >= 2, t >= 2 strategy at depth 1
    INFO(hit->sentence << "\n" << nee->sentence << "\n" << lt->sentence << "\n" << empty->sentence);
    CHECK((hit->hasVerdict && hit->consistent));
    CHECK((lt->hasVerdict && lt->consistent));
    CHECK((nee->hasVerdict && !nee->consistent));
    CHECK(nee->relativeBiasLow < -0.1);
    CHECK(nee->relativeBiasHigh > -0.1);
    CHECK(!empty->hasVerdict);
    // A render with a class layer's R but not its G: that class is not compared, with the reason.
    std::vector<ExrImage> broken = renders;
    broken[3].channels.erase(unweighted(1, 2, "G"));
    compareStrategyClasses(broken, referenceImage(), {1}, 0.01, o);
    const LayerOutcome* unread = layerNamed(o, "depth1.nextEvent");
    REQUIRE(unread);
    CHECK(!unread->hasVerdict);
    CHECK(unread->sentence.find("s1t2.unweighted.G") != std::string::npos);
    CHECK((layerNamed(o, "depth1.lightTracing") && layerNamed(o, "depth1.lightTracing")->hasVerdict));
    // A scene that lists no classes, or renders without strategy layers: nothing compared.
    SuiteScene none;
    o.scene = &none;
    compareStrategyClasses(renders, referenceImage(), {1}, 0.01, o);
    CHECK(o.strategyClassLayers.empty());
    o.scene = &scene;
    compareStrategyClasses(std::vector<ExrImage>(2, referenceImage()), referenceImage(), {1}, 0.01, o);
    CHECK(o.strategyClassLayers.empty());
}

TEST_CASE("strategy classes: every class agreeing while the beauty fails names the MIS weights", "[validate][diagnosis][strategy-classes]") {
    // A BDPT weight error grows with depth (docs/diagnosis.md): per-bounce terms fit that shape as
    // well. The unweighted classes hold no weight: all agreeing, to +-0.5%, with depth layers off
    // by 10% per bounce leaves the weights alone. The failing scenes: every scene that compares all
    // four classes (a wrong weight fails most scenes: the library's MIS bugs fail 16 of 17).
    auto growing = [](bool withClasses) { return failing(withClasses, 1.3, [](int k) { return std::pow(1.1, k); }, agreeing); };
    std::vector<std::string> allFour;
    for (const SuiteScene& s : shippedSuite().scenes)
        if (s.strategyClasses.size() == size_t(kStrategyClassCount)) allFour.push_back(s.name);
    REQUIRE(allFour.size() >= 3);
    auto input = [&](bool withClasses) {
        std::map<std::string, std::function<DiagnosisScene(const SuiteScene&)>> failures;
        for (const std::string& name : allFour) failures[name] = growing(withClasses);
        return run(PortEstimator::Bidirectional, failures);
    };
    const std::vector<DiagnosisEntry> with = diagnose(input(true));
    INFO(ranking(with));
    REQUIRE(!with.empty());
    CHECK(with.front().term == "mis.weights");
    CHECK(with.front().evidence.find("no strategy class fails") != std::string::npos);
    // Every scene of a bidirectional port exercises mis.weights: +2 on each failing scene;
    // lambert.eval (it moves any class, and every class cleared) -2 on each.
    const double n = double(allFour.size());
    CHECK(scoreOf(input(true), "mis.weights") - scoreOf(input(false), "mis.weights") == Approx(2.0 * n));
    CHECK(scoreOf(input(true), "lambert.eval") - scoreOf(input(false), "lambert.eval") == Approx(-2.0 * n));
}

TEST_CASE("strategy classes: a class empty in the scene hides no error, compared or not", "[validate][diagnosis][strategy-classes]") {
    // mis-delta-light-as-area (a BDPT port weighing a point light as an area light): sphere-point-
    // light x0.875 at every depth, its next events, light tracing and connections agreeing. A ray
    // cannot hit a point light: the emitter hits, not compared there, hold nothing (strategyShares
    // "emitterHit" 0), so every class that holds light cleared, as the MIS weights predict.
    const SuiteScene& spl = suiteScene("sphere-point-light");
    REQUIRE(spl.strategyShares.count("emitterHit") == 1);
    CHECK(spl.strategyShares.at("emitterHit") == 0.0);
    CHECK(std::count(spl.strategyClasses.begin(), spl.strategyClasses.end(), "emitterHit") == 0);
    auto off = [](bool withClasses) { return failing(withClasses, 0.875, [](int) { return 0.875; }, agreeing); };
    auto input = [&](bool withClasses) { return run(PortEstimator::Bidirectional, {{"sphere-point-light", off(withClasses)}}); };
    CHECK(scoreOf(input(true), "mis.weights") - scoreOf(input(false), "mis.weights") == Approx(2.0));
    const DiagnosisEntry weights = entryOf(input(true), "mis.weights");
    CHECK(weights.evidence.find("emitterHit empty in this scene") != std::string::npos);
    // A term of the light subpaths (lightTracing, connections) cleared as before: against.
    CHECK(scoreOf(input(true), "light.point.emission_pdf") - scoreOf(input(false), "light.point.emission_pdf") == Approx(-2.0));
    // Where the connections hold light but are not compared (ortho-rough-glass), they may carry it.
    REQUIRE(suiteScene("ortho-rough-glass").strategyShares.at("connections") > 0.01);
}

TEST_CASE("strategy classes: where the suite compares some classes only, agreeing ones clear only the terms they hold", "[validate][diagnosis][strategy-classes]") {
    // ortho-rough-glass compares emitter hits, next events and light tracing, not the connections,
    // which may carry the error: no evidence for the MIS weights or a term that moves any class;
    // against camera.importance, whose only class (light tracing) cleared.
    auto off = [](bool withClasses) { return failing(withClasses, 0.85, [](int k) { return k == 0 ? 1.0 : 0.85; }, agreeing); };
    auto input = [&](bool withClasses) { return run(PortEstimator::Bidirectional, {{"ortho-rough-glass", off(withClasses)}}); };
    REQUIRE(suiteScene("ortho-rough-glass").strategyClasses.size() == 3);
    CHECK(scoreOf(input(true), "mis.weights") - scoreOf(input(false), "mis.weights") == Approx(0.0));
    CHECK(scoreOf(input(true), "lambert.eval") - scoreOf(input(false), "lambert.eval") == Approx(0.0));
    CHECK(scoreOf(input(true), "camera.importance") - scoreOf(input(false), "camera.importance") == Approx(-2.0));
}

TEST_CASE("strategy classes: the next events alone failing speak for next-event terms, against light-tracing ones", "[validate][diagnosis][strategy-classes]") {
    auto neeOff = [](bool withClasses) {
        return failing(withClasses, 0.93, [](int k) { return k == 0 ? 1.0 : 0.9; },
                       [](StrategyClass c, int) { return c == StrategyClass::NextEvent ? 0.9 : 1.0; });
    };
    auto input = [&](bool withClasses) {
        return run(PortEstimator::Bidirectional, {{"cornell-box", neeOff(withClasses)}, {"lights-room", neeOff(withClasses)}});
    };
    const DiagnosisInput with = input(true), without = input(false);
    // Both scenes list the area light's next-event Jacobian and the camera's importance.
    CHECK(scoreOf(with, "light.area.nee_jacobian") - scoreOf(without, "light.area.nee_jacobian") == Approx(4.0));
    CHECK(scoreOf(with, "camera.importance") - scoreOf(without, "camera.importance") == Approx(-4.0));
    // A term that moves any class gets no evidence from the classes that fail.
    CHECK(scoreOf(with, "lambert.eval") - scoreOf(without, "lambert.eval") == Approx(0.0));
    const std::vector<DiagnosisEntry> d = diagnose(with);
    INFO(ranking(d));
    REQUIRE(!d.empty());
    CHECK(scoreOf(with, "light.area.nee_jacobian") > scoreOf(with, "camera.importance"));
}

TEST_CASE("strategy classes: a path tracer's port compares its emitter hits and next events only", "[validate][strategy-classes]") {
    CHECK(estimatorHasClass(PortEstimator::Path, StrategyClass::EmitterHit));
    CHECK(estimatorHasClass(PortEstimator::Path, StrategyClass::NextEvent));
    CHECK_FALSE(estimatorHasClass(PortEstimator::Path, StrategyClass::LightTracing));
    CHECK_FALSE(estimatorHasClass(PortEstimator::Path, StrategyClass::Connections));
    CHECK(strategyClassesOfEstimator(PortEstimator::Light) == strategyClassBit(StrategyClass::LightTracing));
    CHECK(strategyClassesOfEstimator(PortEstimator::Bidirectional) == kAllStrategyClasses);
    // The synthetic port's renders hold a light-tracing layer too (s2t1): a path port's is not read.
    const SuiteScene scene = everyClassScene();
    const std::vector<ExrImage> renders = portRenders(31, 0.9);
    SceneOutcome o;
    o.scene = &scene;
    compareStrategyClasses(renders, referenceImage(), {1}, 0.01, o, PortEstimator::Path);
    REQUIRE(layerNamed(o, "depth1.emitterHit"));
    REQUIRE(layerNamed(o, "depth1.nextEvent"));
    CHECK(layerNamed(o, "depth1.emitterHit")->consistent);
    CHECK_FALSE(layerNamed(o, "depth1.nextEvent")->consistent);
    CHECK_FALSE(layerNamed(o, "depth1.lightTracing"));
    compareStrategyClasses(renders, referenceImage(), {1}, 0.01, o, PortEstimator::Light);  // light tracing alone
    REQUIRE(o.strategyClassLayers.size() == 1);
    CHECK(o.strategyClassLayers[0].layer == "depth1.lightTracing");
}

TEST_CASE("strategy classes: a path port's next events failing alone speak for next-event terms, both agreeing for the MIS weights",
          "[validate][diagnosis][strategy-classes]") {
    // cornell-box and mirror-room list both the area light's next-event Jacobian and the weights.
    const std::vector<std::string> scenes = {"cornell-box", "mirror-room"};
    for (const std::string& name : scenes) {
        const SuiteScene& s = suiteScene(name);
        REQUIRE(renders(s, PortEstimator::Path));
        for (const char* term : {"light.area.nee_jacobian", "mis.weights"})
            REQUIRE(std::find(s.terms.begin(), s.terms.end(), term) != s.terms.end());
    }
    auto input = [&](bool withClasses, std::function<double(StrategyClass, int)> classRatio) {
        std::map<std::string, std::function<DiagnosisScene(const SuiteScene&)>> failures;
        for (const std::string& name : scenes)
            failures[name] = failing(withClasses, 0.93, [](int k) { return k == 0 ? 1.0 : 0.9; }, classRatio);
        return run(PortEstimator::Path, failures);
    };
    // The next events off by 10%, the emitter hits agreeing (the light-tracing and connection
    // layers the fixture adds are not a path tracer's, and count for nothing).
    auto neeOff = [](StrategyClass c, int) { return c == StrategyClass::NextEvent ? 0.9 : 1.0; };
    const double n = double(scenes.size());
    CHECK(scoreOf(input(true, neeOff), "light.area.nee_jacobian") - scoreOf(input(false, neeOff), "light.area.nee_jacobian") == Approx(2.0 * n));
    CHECK(scoreOf(input(true, neeOff), "mis.weights") - scoreOf(input(false, neeOff), "mis.weights") == Approx(-2.0 * n));
    CHECK(scoreOf(input(true, neeOff), "lambert.sample") - scoreOf(input(false, neeOff), "lambert.sample") == Approx(0.0));
    // Both agreeing to +-0.5% while every depth is off by 10%: the weights, and against a BSDF term.
    CHECK(scoreOf(input(true, agreeing), "mis.weights") - scoreOf(input(false, agreeing), "mis.weights") == Approx(2.0 * n));
    CHECK(scoreOf(input(true, agreeing), "lambert.sample") - scoreOf(input(false, agreeing), "lambert.sample") == Approx(-2.0 * n));
}

TEST_CASE("strategy classes: a saved report's class layers reach the diagnosis", "[validate][diagnosis][strategy-classes]") {
    const nlohmann::json report = nlohmann::json::parse(R"({
      "estimator": "bidirectional",
      "scenes": [{"name": "cornell-box", "verdict": "INCONSISTENT",
                  "layers": [{"layer": "beauty", "verdict": "inconsistent", "relativeBias": -0.07, "relativeBias95": [-0.08, -0.06]}],
                  "strategyClassLayers": [
                    {"layer": "depth1.nextEvent", "verdict": "inconsistent", "relativeBias": -0.1, "relativeBias95": [-0.12, -0.08]},
                    {"layer": "depth2.connections", "verdict": "consistent", "relativeBias": 0.001, "relativeBias95": [-0.004, 0.006]},
                    {"layer": "depth2.unknownClass", "verdict": "consistent", "relativeBias": 0, "relativeBias95": [0, 0]}]}]})");
    const DiagnosisInput in = diagnosisInputFromJson(report, shippedSuite());
    REQUIRE(in.scenes.size() == 1);
    REQUIRE(in.scenes[0].classLayers.size() == 2);
    const DiagnosisClassLayer& nee = in.scenes[0].classLayers[0];
    CHECK(nee.strategyClass == StrategyClass::NextEvent);
    CHECK(nee.layer.depth == 1);
    CHECK(!nee.layer.consistent);
    CHECK(nee.layer.ratio == Approx(0.9));
    CHECK(in.scenes[0].classLayers[1].strategyClass == StrategyClass::Connections);
    CHECK(in.scenes[0].classLayers[1].layer.depth == 2);
}

TEST_CASE("strategy classes: the report's JSON, summary and HTML carry them, and the diagnosis reads them", "[validate][diagnosis][strategy-classes]") {
    const SuiteScene& cornell = suiteScene("cornell-box");
    ValidateReport rep;
    rep.options.estimator = PortEstimator::Bidirectional;
    rep.exitCode = 1;
    SceneOutcome o;
    o.scene = &cornell;
    o.verdict = SceneVerdict::Inconsistent;
    auto layer = [](const std::string& name, int depth, double bias, bool consistent) {
        LayerOutcome l;
        l.layer = name, l.depth = depth, l.hasVerdict = true, l.consistent = consistent;
        l.relativeBias = bias, l.relativeBiasLow = bias - 0.005, l.relativeBiasHigh = bias + 0.005;
        l.tested = l.compared = 4000;
        return l;
    };
    o.layers = {layer("beauty", -1, -0.07, false), layer("depth1", 1, -0.1, false)};
    o.strategyClassLayers = {layer("depth1.nextEvent", 1, -0.1, false), layer("depth2.nextEvent", 2, -0.1, false),
                             layer("depth1.lightTracing", 1, 0.0, true)};
    rep.scenes.push_back(o);

    const nlohmann::json j = nlohmann::json::parse(validateReportJson(rep));
    REQUIRE(j["scenes"][0]["strategyClassLayers"].size() == 3);
    CHECK(j["scenes"][0]["strategyClassLayers"][0]["layer"] == "depth1.nextEvent");
    CHECK(j["scenes"][0]["strategyClassLayers"][0]["verdict"] == "inconsistent");
    const std::string summary = validateSummaryText(rep);
    INFO(summary);
    CHECK(summary.find("strategy classes: nextEvent (depths 1, 2) fails, lightTracing agrees") != std::string::npos);
    CHECK(validateReportHtml(rep).find("depth2.nextEvent") != std::string::npos);
    const DiagnosisInput in = diagnosisInput(rep);
    REQUIRE(in.scenes.size() == 1);
    REQUIRE(in.scenes[0].classLayers.size() == 3);
    CHECK(in.scenes[0].classLayers[1].strategyClass == StrategyClass::NextEvent);
    CHECK(in.scenes[0].classLayers[1].layer.depth == 2);
    CHECK(in.scenes[0].classLayers[2].strategyClass == StrategyClass::LightTracing);
    CHECK(in.scenes[0].classLayers[2].layer.consistent);
}
