// The diagnosis of an inconsistent validate run (docs/diagnosis.md), on synthetic per-scene results
// built over the shipped suite's `terms`: no renders, so it runs in milliseconds (and under ASan).
// What is proven: the term catalogue is well formed, the suite names only its ids and the doc's
// table is the catalogue's; each signature the doc lists ranks its term first on the suite
// (x1/683 on the scenes lit by punctual lights, x1/eta^2 behind refraction, a factor growing
// with depth on Lambert scenes, a decay from the depth roulette starts) and light added at depth 0
// is not taken for a per-bounce factor; a failure of one scene
// alone is put on one of that scene's terms, for every scene and every estimator that renders it;
// a consistent run has no diagnosis; the report's JSON and summary carry it.
#include "support/diagnosis_fixtures.h"
#include "support/render_util.h"
#include "verify/validate_diagnosis.h"

#include "bdptref/bdptref.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <map>
#include <regex>
#include <set>
#include <sstream>

using namespace bdptref;
using namespace bdptref::test;

namespace {

constexpr double kPiForTests = 3.14159265358979323846;

std::string readFile(const std::string& path) {
    std::ifstream in(path);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

}  // namespace

TEST_CASE("diagnosis: the term catalogue has unique, well-formed ids, each described, with estimators", "[validate][diagnosis]") {
    const std::regex idForm("[a-z0-9_]+(\\.[a-z0-9_]+)+");
    std::set<std::string> ids;
    for (const Term& t : termCatalogue()) {
        INFO(t.id);
        CHECK(std::regex_match(std::string(t.id), idForm));
        CHECK(ids.insert(t.id).second);
        CHECK(std::string(t.description).size() > 10);
        CHECK(std::string(t.signature).size() > 10);
        CHECK((t.estimators & ~unsigned(kUsedByAll)) == 0);
        CHECK(t.estimators != 0);
        CHECK(findTerm(t.id) == &t);
        for (const TermFactor& f : t.factors) CHECK(f.low <= f.high);
    }
    CHECK(findTerm("no.such_term") == nullptr);
    // The ids the issue and the doc name (a rename breaks reports and scripts keyed on them).
    for (const char* id : {"lambert.eval", "ggx.vndf_pdf", "light.area.nee_jacobian", "light.point.intensity_units",
                           "light.directional.emission_pdf", "camera.importance", "lt.splat_normalisation", "mis.weights",
                           "roulette.light_subpath", "refraction.eta2", "volume.attenuation_mapping", "subpath.length_limit",
                           "rng.dimensions", "units.photometric_683", "diffuse.burley_vs_lambert", "pixel.filter"})
        CHECK(findTerm(id) != nullptr);
}

TEST_CASE("diagnosis: the suite's terms are catalogue ids, and docs/diagnosis.md holds the catalogue's table", "[validate][diagnosis]") {
    const Suite& suite = shippedSuite();
    for (const SuiteScene& s : suite.scenes) {
        INFO(s.name);
        CHECK(!s.terms.empty());
        for (const std::string& t : s.terms) {
            INFO(t);
            CHECK(findTerm(t) != nullptr);
        }
    }
    // Every scene with glass says its ior (the eta^2 factors need it).
    for (const char* glass : {"camera-in-glass", "light-in-glass", "caustic-glass"}) CHECK(suiteScene(glass).ior == 1.5);
    // The lists are closed under what a material implies: a rough GGX lobe is sampled by its VNDF;
    // rough transmission has a Fresnel choice of reflection or refraction and the eta^2 scaling; a
    // smooth glass chooses its lobe by Fresnel.
    const std::vector<std::pair<std::vector<std::string>, std::vector<std::string>>> implies = {
        {{"ggx.eval"}, {"ggx.vndf_pdf"}},
        {{"ggx.rough_transmission"}, {"ggx.vndf_pdf", "dielectric.fresnel", "refraction.eta2", "bsdf.lobe_selection"}},
        {{"specular.delta", "dielectric.fresnel"}, {"bsdf.lobe_selection"}}};
    auto lists = [](const SuiteScene& s, const std::string& t) { return std::find(s.terms.begin(), s.terms.end(), t) != s.terms.end(); };
    // Except where no BSDF sample can carry light: one bounce at most (maxDepth <= 1) and only
    // delta lights, which no sampled direction hits (glossy-point-light: GGX's value alone).
    auto bsdfSamplesCarryLight = [](const SuiteScene& s) {
        if (s.maxDepth > 1 || !s.envMap.empty() || !s.envConstant.empty()) return true;
        const Scene scene = loadSceneFile(s.scene, 8, 8);
        return std::any_of(scene.lights.begin(), scene.lights.end(),
                           [](const Light& l) { return !isDeltaPosition(l) && !isDeltaDirection(l); });
    };
    for (const SuiteScene& s : suite.scenes)
        if (bsdfSamplesCarryLight(s))
        for (const auto& [ifAll, then] : implies)
            if (std::all_of(ifAll.begin(), ifAll.end(), [&](const std::string& t) { return lists(s, t); }))
                for (const std::string& t : then) {
                    INFO(s.name << " lists " << ifAll[0] << " but not " << t);
                    CHECK(lists(s, t));
                }
    // Roulette acts from the third bounce on (rouletteStartDepth = 3) on both subpaths.
    for (const SuiteScene& s : suite.scenes)
        if (s.maxDepth >= 3) {
            INFO(s.name);
            CHECK(lists(s, "roulette.camera_subpath"));
            CHECK(lists(s, "roulette.light_subpath"));
        }
    for (const SuiteScene& s : suite.scenes)
        if (lists(s, "refraction.eta2")) {
            INFO(s.name << ": the eta^2 factor needs the scene's ior");
            CHECK(s.ior > 1);
        }
    const std::string doc = readFile(sourcePath("docs/diagnosis.md"));
    const std::string table = termCatalogueMarkdown(&suite);
    // BDPTREF_WRITE_TERMS_TABLE=FILE writes the table there, to paste into the doc after a change.
    if (const char* out = std::getenv("BDPTREF_WRITE_TERMS_TABLE")) std::ofstream(out) << table;
    INFO("docs/diagnosis.md must hold, between its terms markers, exactly:\n" << table);
    const std::string begin = "<!-- terms:begin (termCatalogueMarkdown) -->\n", end = "<!-- terms:end -->";
    const size_t b = doc.find(begin), e = doc.find(end);
    REQUIRE(b != std::string::npos);
    REQUIRE(e != std::string::npos);
    CHECK(doc.substr(b + begin.size(), e - b - begin.size()) == table);
}

TEST_CASE("diagnosis: a consistent run has none", "[validate][diagnosis]") {
    for (PortEstimator e : {PortEstimator::Path, PortEstimator::Light, PortEstimator::Bidirectional}) {
        CHECK(diagnose(run(e, {})).empty());
    }
    CHECK(diagnose(DiagnosisInput{}).empty());
}

TEST_CASE("diagnosis: failing scenes that list no terms (a suite of one's own) get none", "[validate][diagnosis]") {
    DiagnosisInput in = run(PortEstimator::Path, {{"cornell-box", [](const SuiteScene& s) {
                                                       return result(s, 1.2, [](int d) { return d == 0 ? 1.0 : 1.2; });
                                                   }}});
    REQUIRE(!diagnose(in).empty());
    for (DiagnosisScene& s : in.scenes) s.terms.clear();
    CHECK(diagnose(in).empty());
}

TEST_CASE("diagnosis: x1/683 on the scenes lit by punctual lights names the photometric units", "[validate][diagnosis]") {
    const double f = 1.0 / 683.0;
    // Point light alone: every depth >= 1 at 1/683 (nothing is seen directly).
    auto sphere = [f](const SuiteScene& s) { return result(s, f, [f](int) { return f; }, false); };
    // Spots beside emissive meshes: the emitters seen directly agree, the rest is darker.
    auto room = [](const SuiteScene& s) { return result(s, 0.7, [](int d) { return d == 0 ? 1.0 : 0.65; }); };

    SECTION("a path port: sphere-point-light and lights-room fail, the other scenes pass") {
        const auto d = diagnose(run(PortEstimator::Path, {{"sphere-point-light", sphere}, {"lights-room", room}}));
        INFO(ranking(d));
        REQUIRE(!d.empty());
        CHECK(d[0].term == "units.photometric_683");
        CHECK(d[0].confidence > 0.5);
        CHECK(d[0].evidence.find("1/683") != std::string::npos);
    }
    SECTION("sphere-point-light alone (--scenes)") {
        const auto d = diagnose(run(PortEstimator::Path, {{"sphere-point-light", sphere}}, false));
        INFO(ranking(d));
        REQUIRE(!d.empty());
        CHECK(d[0].term == "units.photometric_683");
    }
    SECTION("a bidirectional port: every scene with a punctual light fails") {
        auto mixed = [](const SuiteScene& s) { return result(s, 0.8, [](int d) { return d == 0 ? 1.0 : 0.75; }); };
        const auto d = diagnose(run(PortEstimator::Bidirectional, {{"sphere-point-light", sphere},
                                                                   {"light-in-glass", sphere},
                                                                   {"lights-room", room},
                                                                   {"mis-zoo", mixed}}));
        INFO(ranking(d));
        REQUIRE(!d.empty());
        CHECK(d[0].term == "units.photometric_683");
    }
}

TEST_CASE("diagnosis: x1/eta^2 behind refraction only names the eta^2 scaling", "[validate][diagnosis]") {
    const double inv = 1 / (1.5 * 1.5);
    SECTION("exactly 1/eta^2 on camera-in-glass") {
        auto glass = [inv](const SuiteScene& s) { return result(s, inv, [inv](int) { return inv; }, false); };
        const auto d = diagnose(run(PortEstimator::Path, {{"camera-in-glass", glass}}));
        INFO(ranking(d));
        REQUIRE(!d.empty());
        CHECK(d[0].term == "refraction.eta2");
        CHECK(d[0].evidence.find("1/eta^2") != std::string::npos);
    }
    SECTION("Cycles' -49% (the rays that reflect inside the glass carry no factor)") {
        auto glass = [](const SuiteScene& s) { return result(s, 0.51, [](int) { return 0.51; }, false); };
        const auto d = diagnose(run(PortEstimator::Path, {{"camera-in-glass", glass}}));
        INFO(ranking(d));
        REQUIRE(!d.empty());
        CHECK(d[0].term == "refraction.eta2");
    }
}

TEST_CASE("diagnosis: a factor growing with depth on Lambert scenes names a per-bounce diffuse term", "[validate][diagnosis]") {
    const std::set<std::string> perBounceDiffuse = {"lambert.eval", "lambert.sample", "diffuse.burley_vs_lambert"};
    auto growing = [](double g) {
        return [g](const SuiteScene& s) {
            double beauty = 0, sum = 0;  // a beauty brighter by the growth, weighted to the first bounces
            for (int d = 0; d <= s.maxDepth; ++d) beauty += std::pow(0.6, d) * std::pow(g, d), sum += std::pow(0.6, d);
            return result(s, beauty / sum, [g](int d) { return std::pow(g, d); });
        };
    };
    SECTION("cornell-box and white-box alone (--scenes), a gain of 10% per bounce") {
        const auto d = diagnose(run(PortEstimator::Path, {{"cornell-box", growing(1.1)}, {"white-box", growing(1.06)}}, false));
        INFO(ranking(d));
        REQUIRE(!d.empty());
        CHECK(perBounceDiffuse.count(d[0].term) == 1);
        CHECK(d[0].term == "diffuse.burley_vs_lambert");  // 1.06 and 1.1 are in Burley's range, not pi's
    }
    SECTION("a missing 1/pi: x pi per bounce") {
        // The value and the sampling density of Lambert leave the same signature: both share the top.
        const auto d = diagnose(run(PortEstimator::Path, {{"cornell-box", growing(kPiForTests)}, {"white-box", growing(kPiForTests)}}, false));
        INFO(ranking(d));
        REQUIRE(d.size() >= 2);
        CHECK(std::set<std::string>{d[0].term, d[1].term} == std::set<std::string>{"lambert.eval", "lambert.sample"});
        CHECK(d[0].confidence == Approx(d[1].confidence));
        CHECK(d[0].confidence > 0.4);
        for (size_t i = 2; i < d.size(); ++i) CHECK(d[i].confidence < 0.05);
    }
    SECTION("Burley as Cycles renders it: every scene that lists it brighter with depth, the others pass") {
        std::map<std::string, std::function<DiagnosisScene(const SuiteScene&)>> fails;
        for (const SuiteScene& s : shippedSuite().scenes)
            if (std::count(s.terms.begin(), s.terms.end(), "diffuse.burley_vs_lambert")) fails[s.name] = growing(1.08);
        const auto d = diagnose(run(PortEstimator::Path, fails));
        INFO(ranking(d));
        REQUIRE(!d.empty());
        CHECK(d[0].term == "diffuse.burley_vs_lambert");
    }
}

TEST_CASE("diagnosis: light added at every depth, most at depth 0, is no per-bounce factor", "[validate][diagnosis]") {
    // Measured with a "port" that adds a dim constant environment on cornell-box (16 spp x 4):
    // depth 0 +2477%, then +52%, +19%, +10%: ratios above 1 that fall towards it with depth.
    const std::vector<double> measured = {25.77, 1.524, 1.188, 1.104, 1.047, 1.059, 1.087, 1.097, 1.062};
    auto added = [&](const SuiteScene& s) { return result(s, 1.22, [&](int d) { return measured[size_t(d)]; }); };
    const auto d = diagnose(run(PortEstimator::Path, {{"cornell-box", added}}, false));
    INFO(ranking(d));
    REQUIRE(!d.empty());
    for (const char* perBounce : {"lambert.eval", "lambert.sample", "roulette.camera_subpath", "diffuse.burley_vs_lambert"})
        CHECK(d[0].term != perBounce);
    CHECK((findTerm(d[0].term)->depthShapes & kUniform) != 0);
}

TEST_CASE("diagnosis: a decay from the depth roulette starts names roulette", "[validate][diagnosis]") {
    // Survivors not divided by their probability: every deep path loses weight from the third
    // bounce on. The library's three such bugs (path, lt, bdpt) fail every scene of maximum depth
    // >= 3 but veach-mis, most where paths go deep; here the four closed rooms.
    auto decaying = [](const SuiteScene& s) {
        return result(s, 0.8, [](int d) { return d < 3 ? 1.0 : std::pow(0.9, d - 2); });
    };
    const auto d = diagnose(run(PortEstimator::Path, {{"white-box", decaying}, {"cornell-box", decaying},
                                                      {"lights-room", decaying}, {"lobe-box", decaying}}));
    INFO(ranking(d));
    REQUIRE(!d.empty());
    CHECK(d[0].term == "roulette.camera_subpath");
}

TEST_CASE("diagnosis: a failure of one scene alone is put on one of that scene's terms", "[validate][diagnosis]") {
    // No factor the catalogue knows: +5% at every depth >= 1 (the volume bugs of absorbing-glass look so).
    auto off = [](const SuiteScene& s) { return result(s, 1.05, [](int d) { return d == 0 ? 1.0 : 1.05; }); };
    SECTION("absorbing-glass: the volume terms only it exercises") {
        const auto d = diagnose(run(PortEstimator::Path, {{"absorbing-glass", off}}));
        INFO(ranking(d));
        REQUIRE(!d.empty());
        CHECK(d[0].term.rfind("volume.", 0) == 0);
    }
    SECTION("every scene, every estimator that renders it") {
        for (const SuiteScene& s : shippedSuite().scenes)
            for (PortEstimator e : s.estimators) {
                const auto d = diagnose(run(e, {{s.name, off}}));
                INFO(s.name << " by a " << portEstimatorName(e) << " port\n" << ranking(d));
                REQUIRE(!d.empty());
                CHECK(std::count(s.terms.begin(), s.terms.end(), d[0].term) == 1);
                CHECK(d.size() <= 5);
                for (size_t i = 1; i < d.size(); ++i) CHECK(d[i].score <= d[i - 1].score);
                double sum = 0;
                for (const DiagnosisEntry& x : d) sum += x.confidence;
                CHECK(sum <= 1 + 1e-9);
            }
    }
}

TEST_CASE("diagnosis: validate's JSON and summary carry the ranking of its report", "[validate][diagnosis]") {
    const SuiteScene& sphere = suiteScene("sphere-point-light");
    const SuiteScene& cornell = suiteScene("cornell-box");
    ValidateReport rep;
    rep.options.estimator = PortEstimator::Path;
    rep.exitCode = 1;
    auto outcome = [](const SuiteScene& s, SceneVerdict v, double bias, double half, uint64_t tested = 4000) {
        SceneOutcome o;
        o.scene = &s;
        o.verdict = v;
        LayerOutcome b;
        b.layer = "beauty";
        b.hasVerdict = true;
        b.consistent = v == SceneVerdict::Consistent;
        b.relativeBias = bias, b.relativeBiasLow = bias - half, b.relativeBiasHigh = bias + half;
        b.tested = tested, b.compared = 4000;
        o.layers.push_back(b);
        return o;
    };
    rep.scenes.push_back(outcome(sphere, SceneVerdict::Inconsistent, 1.0 / 683.0 - 1, 0.0005));
    rep.scenes.push_back(outcome(cornell, SceneVerdict::Consistent, 0.001, 0.004));
    const DiagnosisInput in = diagnosisInput(rep);
    REQUIRE(in.scenes.size() == 2);
    CHECK(in.scenes[0].outcome == DiagnosisOutcome::Failed);
    CHECK(in.scenes[0].ratio == Approx(1.0 / 683.0));
    CHECK(in.scenes[0].terms == sphere.terms);
    CHECK(in.scenes[1].outcome == DiagnosisOutcome::Passed);
    // A low-power pass (few pixels tested) speaks against no term.
    rep.scenes.push_back(outcome(suiteScene("white-box"), SceneVerdict::Consistent, 0.0, 0.004, 100));
    REQUIRE(passPower(rep.scenes.back()).low);
    CHECK(diagnosisInput(rep).scenes[2].outcome == DiagnosisOutcome::Untested);
    rep.scenes.pop_back();

    const nlohmann::json j = nlohmann::json::parse(validateReportJson(rep));
    REQUIRE(j.contains("diagnosis"));
    REQUIRE(j["diagnosis"].is_array());
    REQUIRE(!j["diagnosis"].empty());
    CHECK(j["diagnosis"][0]["term"] == "units.photometric_683");
    CHECK(j["diagnosis"][0]["confidence"].get<double>() > 0);
    CHECK(j["diagnosis"][0]["evidence"].get<std::string>().find("sphere-point-light") != std::string::npos);
    CHECK(validateSummaryText(rep).find("1. units.photometric_683") != std::string::npos);
    CHECK(validateReportHtml(rep).find("<code>units.photometric_683</code>") != std::string::npos);

    rep.scenes[0] = outcome(sphere, SceneVerdict::Consistent, 0.0, 0.004);
    rep.exitCode = 0;
    CHECK(nlohmann::json::parse(validateReportJson(rep))["diagnosis"].empty());
    CHECK(validateSummaryText(rep).find("diagnosis") == std::string::npos);
}

TEST_CASE("diagnosis per scene: several independent conventions at once are each named for their scene", "[validate][diagnosis]") {
    // Blender Cycles with the importer's stock materials (docs/validate.md, "The port contract"):
    // Burley diffuse on the Lambert scenes (a gain growing with depth: every scene with a Lambert
    // surface fails), 1/683 on the point light, no eta^2 behind the glass, all in one run. The
    // single ranking names what explains most scenes; each scene alone must name its own
    // convention. (tests/unit/test_validate_diagnosis_joint.cpp does the same with the biases
    // Cycles measured.)
    auto growing = [](double g) {
        return [g](const SuiteScene& s) {
            double beauty = 0, sum = 0;
            for (int d = 0; d <= s.maxDepth; ++d) beauty += std::pow(0.6, d) * std::pow(g, d), sum += std::pow(0.6, d);
            return result(s, beauty / sum, [g](int d) { return std::pow(g, d); });
        };
    };
    const double f = 1.0 / 683.0;
    auto sphere = [f](const SuiteScene& s) { return result(s, f, [f](int) { return f; }, false); };
    auto glass = [](const SuiteScene& s) { return result(s, 0.51, [](int) { return 0.51; }, false); };
    std::map<std::string, std::function<DiagnosisScene(const SuiteScene&)>> cycles = {
        {"cornell-box", growing(1.1)}, {"white-box", growing(1.06)}, {"sphere-point-light", sphere}, {"camera-in-glass", glass}};
    for (const SuiteScene& s : shippedSuite().scenes)
        if (!cycles.count(s.name) && std::count(s.terms.begin(), s.terms.end(), "diffuse.burley_vs_lambert"))
            cycles[s.name] = growing(1.05);
    const DiagnosisInput in = run(PortEstimator::Path, cycles);
    const std::vector<SceneDiagnosis> each = diagnosePerScene(in);
    std::map<std::string, std::string> best;
    for (const SceneDiagnosis& e : each) best[e.scene] = e.best.term;
    INFO(ranking(diagnose(in)));
    CHECK(each.size() == size_t(std::count_if(in.scenes.begin(), in.scenes.end(), [](const DiagnosisScene& s) {
              return s.outcome == DiagnosisOutcome::Failed;
          })));
    CHECK(best["cornell-box"] == "diffuse.burley_vs_lambert");
    CHECK(best["white-box"] == "diffuse.burley_vs_lambert");
    CHECK(best["sphere-point-light"] == "units.photometric_683");
    CHECK(best["camera-in-glass"] == "refraction.eta2");
    // A run where one scene fails has one per-scene entry, the same as the single ranking's first.
    const DiagnosisInput one = run(PortEstimator::Path, {{"sphere-point-light", sphere}});
    const std::vector<SceneDiagnosis> single = diagnosePerScene(one);
    REQUIRE(single.size() == 1);
    CHECK(single[0].best.term == diagnose(one)[0].term);
}

TEST_CASE("diagnosis: the light subpath one vertex short names the length limit", "[validate][diagnosis]") {
    // Measured with bdptref's light subpaths limited to maxDepth vertices (a bidirectional port):
    // depth-limit-caustic (all of its light at depth 2 = maxDepth, depths 0 and 1 empty, so
    // untested) renders black; light-in-glass loses part of its deepest layer only.
    auto black = [](const SuiteScene& s) {
        DiagnosisScene d = result(s, 0.0, [](int) { return 1.0; });
        d.low = -0.0015, d.high = 0.0015;
        for (DiagnosisLayer& l : d.depths)
            if (l.depth < s.maxDepth) l = DiagnosisLayer{};
        d.depths.back() = layerAt(s.maxDepth, 0.0, 0.0);
        d.depths.back().low = -0.0015, d.depths.back().high = 0.0015, d.depths.back().consistent = false;
        return d;
    };
    auto deepestShort = [](const SuiteScene& s) {
        return result(s, 0.97, [&](int d) { return d == s.maxDepth ? 0.0 : 1.0; }, false);
    };
    SECTION("depth-limit-caustic black, light-in-glass passes") {
        const auto d = diagnose(run(PortEstimator::Bidirectional, {{"depth-limit-caustic", black}}));
        INFO(ranking(d));
        REQUIRE(!d.empty());
        CHECK(d[0].term == "subpath.length_limit");
    }
    SECTION("both fail") {
        const auto d = diagnose(run(PortEstimator::Bidirectional, {{"depth-limit-caustic", black}, {"light-in-glass", deepestShort}}));
        INFO(ranking(d));
        REQUIRE(!d.empty());
        CHECK(d[0].term == "subpath.length_limit");
    }
    SECTION("light-in-glass alone run (--scenes), its shallower layers agreeing") {
        const auto d = diagnose(run(PortEstimator::Light, {{"light-in-glass", deepestShort}}, false));
        INFO(ranking(d));
        REQUIRE(!d.empty());
        CHECK(d[0].term == "subpath.length_limit");
    }
    SECTION("a light port: light-in-glass's deepest layer short, its shallower layers agreeing; the scenes of maxDepth 1 and 2 black") {
        // As measured (lt-light-subpath-one-vertex-short): at maxDepth 1 a light subpath of one
        // vertex reaches no surface, so glossy-point-light and depth-limit-glossy go black too.
        const auto d = diagnose(run(PortEstimator::Light, {{"light-in-glass", deepestShort}, {"depth-limit-caustic", black},
                                                           {"glossy-point-light", black}, {"depth-limit-glossy", black}}));
        INFO(ranking(d));
        REQUIRE(!d.empty());
        CHECK(d[0].term == "subpath.length_limit");
    }
}

TEST_CASE("diagnosis: depth layers are no evidence for or against the camera and the pixel filter", "[validate][diagnosis]") {
    // Light tracing with importance ~ 1/cos^3 instead of 1/cos^4: the error grows away from the
    // image centre, so a layer whose light lands near the centre (emitters seen head-on at depth 0)
    // agrees while the others do not. Such a term's score must not depend on the layers' shape.
    auto scoreOf = [](const std::string& term, bool depth0Agrees) {
        std::map<std::string, std::function<DiagnosisScene(const SuiteScene&)>> failing;
        for (const char* name : {"cornell-box", "lights-room", "white-box"})
            failing[name] = [depth0Agrees](const SuiteScene& s) {
                return result(s, 0.93, [depth0Agrees](int d) { return d == 0 && depth0Agrees ? 1.0 : 0.93; });
            };
        DiagnosisInput in = run(PortEstimator::Light, failing);
        in.top = 100;
        for (const DiagnosisEntry& e : diagnose(in))
            if (e.term == term) return e.score;
        return std::nan("");
    };
    for (const char* term : {"camera.importance", "camera.generate", "pixel.filter"}) {
        INFO(term);
        const double uniform = scoreOf(term, false), centreAgrees = scoreOf(term, true);
        REQUIRE(std::isfinite(uniform));
        CHECK(uniform == centreAgrees);
    }
    // A term with a depth signature does move: the spot falloff never touches depth 0.
    CHECK(scoreOf("light.spot.falloff", true) > scoreOf("light.spot.falloff", false));
}

TEST_CASE("diagnosis: a ratio growing with depth is a MIS-weight shape in a bidirectional port only", "[validate][diagnosis]") {
    // BDPT's depth k has k + 2 strategies: a wrong weight (a dropped camera-side quantity) moves
    // deeper layers further. A path tracer's MIS weighs two strategies at every depth >= 1.
    auto misEvidence = [](PortEstimator e) {
        auto growing = [](const SuiteScene& s) {
            return result(s, 1.3, [](int d) { return std::pow(1.1, d); });
        };
        DiagnosisInput in = run(e, {{"cornell-box", growing}, {"white-box", growing}, {"veach-mis", growing}});
        in.top = 100;
        for (const DiagnosisEntry& entry : diagnose(in))
            if (entry.term == "mis.weights") return entry.evidence;
        return std::string();
    };
    const std::string bdpt = misEvidence(PortEstimator::Bidirectional), path = misEvidence(PortEstimator::Path);
    INFO("bidirectional: " << bdpt << "\npath: " << path);
    REQUIRE(!bdpt.empty());
    REQUIRE(!path.empty());
    auto against = [](const std::string& ev) { return ev.substr(std::min(ev.size(), ev.find("Against:"))); };
    CHECK(against(bdpt).find("per bounce") == std::string::npos);
    CHECK(against(path).find("per bounce") != std::string::npos);
}

TEST_CASE("diagnosis: every scene lit by emissive meshes lists their terms and the light choice", "[validate][diagnosis]") {
    // What an area light implies, from the scene as loaded: its emission seen directly, light
    // subpaths starting on it, next-event estimation towards it, and (two or more triangles) the
    // light choice's pmf. Sidedness is left to the hand-written lists: it needs the back face seen.
    for (const SuiteScene& s : shippedSuite().scenes) {
        const Scene scene = loadSceneFile(s.scene, 16, 16);
        const auto area = std::count_if(scene.lights.begin(), scene.lights.end(),
                                        [](const Light& l) { return l.type == LightType::Area; });
        INFO(s.name << ": " << area << " emissive triangles, " << scene.lights.size() << " lights");
        auto lists = [&](const char* t) { return std::find(s.terms.begin(), s.terms.end(), t) != s.terms.end(); };
        if (area > 0)
            for (const char* t : {"light.area.emission", "light.area.emission_sampling", "light.area.nee_jacobian"}) {
                INFO(t);
                CHECK(lists(t));
            }
        if (scene.lights.size() >= 2) CHECK(lists("light.selection"));
    }
}

TEST_CASE("diagnosis: a predicted factor held by a narrow interval weighs more than by a wide one", "[validate][diagnosis]") {
    // ortho-rough-glass x4 [3.98, 4.02] (importance from half extents: the film area 4 times too
    // small) against the same x4 known to +-30%: chance lands a ratio within +-0.5% of 4 far more
    // rarely, so the film-area factor of camera.importance must count for more.
    auto scoreAt = [](double relHalf) {
        DiagnosisInput in = run(PortEstimator::Light, {{"ortho-rough-glass", [relHalf](const SuiteScene& s) {
                                                            DiagnosisScene d = result(s, 4.0, [](int) { return 4.0; });
                                                            d.low = 4.0 * (1 - relHalf), d.high = 4.0 * (1 + relHalf);
                                                            return d;
                                                        }}});
        in.top = 100;
        for (const DiagnosisEntry& e : diagnose(in))
            if (e.term == "camera.importance") return e.score;
        return std::nan("");
    };
    const double narrow = scoreAt(0.005), wide = scoreAt(0.3);
    REQUIRE(std::isfinite(narrow));
    REQUIRE(std::isfinite(wide));
    // log(13.8 / 0.01) = 7.2, capped at 6, against the floor 3 for log(13.8 / 0.62) = 3.1.
    CHECK(narrow - wide == Approx(3.0).margin(0.2));
}

TEST_CASE("diagnosis: every depth off by one factor is a Lambert-value shape in a bidirectional port only", "[validate][diagnosis]") {
    // BDPT evaluates a BSDF once at each end of a connection: a wrong Lambert value there moves each
    // path by one factor, not one per bounce. A path tracer's Lambert value multiplies every bounce.
    auto lambertAgainst = [](PortEstimator e) {
        auto uniformOff = [](const SuiteScene& s) { return result(s, 0.7, [](int k) { return k == 0 ? 1.0 : 0.7; }); };
        DiagnosisInput in = run(e, {{"cornell-box", uniformOff}, {"white-box", uniformOff}});
        in.top = 100;
        for (const DiagnosisEntry& entry : diagnose(in))
            if (entry.term == "lambert.eval") return entry.evidence.substr(std::min(entry.evidence.size(), entry.evidence.find("Against:")));
        return std::string("(not ranked)");
    };
    const std::string bdpt = lambertAgainst(PortEstimator::Bidirectional), path = lambertAgainst(PortEstimator::Path);
    INFO("bidirectional: " << bdpt << "\npath: " << path);
    CHECK(bdpt.find("off by a similar factor") == std::string::npos);
    CHECK(path.find("off by a similar factor") != std::string::npos);
}
