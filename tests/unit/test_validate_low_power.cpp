// validate's low-power passes (docs/validate.md, "Low-power passes"): a scene that passes with few of
// its pixels tested or a wide bias interval says so in the summary, the HTML and the JSON.
#include "verify/validate.h"

#include <catch2/catch.hpp>

#include <nlohmann/json.hpp>

using namespace bdptref;

namespace {

SceneOutcome passed(const SuiteScene& s, uint64_t tested, uint64_t equal, double biasHalfWidth) {
    SceneOutcome o;
    o.scene = &s;
    o.verdict = SceneVerdict::Consistent;
    o.spp = 16;
    o.renders = 8;
    o.p = 0.4;
    LayerOutcome b;
    b.layer = "beauty";
    b.hasVerdict = true;
    b.p = 0.4;
    b.relativeBias = 0.002;
    b.relativeBiasLow = 0.002 - biasHalfWidth;
    b.relativeBiasHigh = 0.002 + biasHalfWidth;
    b.compared = 4096;
    b.tested = tested;
    b.equal = equal;
    o.layers.push_back(b);
    return o;
}

}  // namespace

// veach-mis passed with 1061 of 4096 pixels tested at 16 spp x 8, shown like any other pass.
TEST_CASE("validate: a pass with few pixels tested or a wide bias interval is shown as low power", "[validate]") {
    SuiteScene few, wide, sharp, dark, bad;
    few.name = "veach-mis", wide.name = "wide", sharp.name = "sharp", dark.name = "dark", bad.name = "bad";
    ValidateReport r;
    r.suitePath = "suite.json";
    r.scenes.push_back(passed(few, 1061, 0, 0.004));     // 26% tested
    r.scenes.push_back(passed(wide, 4000, 0, 0.013));    // 98% tested, bias +-1.3%
    r.scenes.push_back(passed(sharp, 4000, 0, 0.002));
    r.scenes.push_back(passed(dark, 1900, 2048, 0.002));  // a black half: 93% of the pixels with noise
    r.scenes.push_back(passed(bad, 500, 0, 0.05));
    r.scenes.back().verdict = SceneVerdict::Inconsistent;  // a failure is a failure, whatever its power

    CHECK(passPower(r.scenes[0]).low);
    CHECK(passPower(r.scenes[0]).testedFraction == Approx(1061.0 / 4096));
    CHECK(passPower(r.scenes[1]).low);
    CHECK(passPower(r.scenes[1]).biasHalfWidth == Approx(0.013));
    CHECK_FALSE(passPower(r.scenes[2]).low);
    CHECK_FALSE(passPower(r.scenes[3]).low);
    CHECK_FALSE(passPower(r.scenes[4]).low);

    const std::string text = validateSummaryText(r);
    CHECK_THAT(text, Catch::Contains("veach-mis              consistent — low power: 26% of pixels tested, bias ±0.4%, p = 0.4"));
    CHECK_THAT(text, Catch::Contains("wide                   consistent — low power: 98% of pixels tested, bias ±1.3%, p = 0.4"));
    CHECK_THAT(text, Catch::Contains("sharp                  consistent       p = 0.4"));
    CHECK_THAT(text, Catch::Contains("note: 2 scenes passed with low power"));

    const std::string html = validateReportHtml(r);
    CHECK_THAT(html, Catch::Contains("consistent — low power: 26% of pixels tested, bias ±0.4%"));
    CHECK_THAT(html, Catch::Contains("2 scenes passed with low power"));

    const nlohmann::json j = nlohmann::json::parse(validateReportJson(r));
    CHECK(j["scenes"][0]["lowPower"] == true);
    CHECK(j["scenes"][0]["pixelsTestedFraction"].get<double>() == Approx(1061.0 / 4096));
    CHECK(j["scenes"][1]["lowPower"] == true);
    CHECK(j["scenes"][1]["biasHalfWidth95"].get<double>() == Approx(0.013));
    CHECK(j["scenes"][2]["lowPower"] == false);
    CHECK(j["scenes"][3]["lowPower"] == false);
    CHECK(j["scenes"][4]["lowPower"] == false);
}
