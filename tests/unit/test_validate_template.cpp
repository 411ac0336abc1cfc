// validate's renderer command template (docs/validate.md, "What your renderer must do"): the
// {name:text} form that drops a flag with an empty value, {env_scale} without a map, malformed
// templates, and the {seeds} form that hands a renderer every render of a scene in one process.
#include "verify/validate.h"

#include "bdptref/errors.h"

#include <catch2/catch.hpp>

using namespace bdptref;

namespace {

SuiteScene plainScene() {
    SuiteScene s;
    s.name = "a";
    s.scene = "/scenes/a.gltf";
    s.reference = "/refs/a.exr";
    s.maxDepth = 5;
    s.estimators = {PortEstimator::Path};
    return s;
}

RenderRequest requestFor(const SuiteScene& s) {
    RenderRequest r;
    r.scene = &s;
    r.output = "/out/r.exr";
    r.spp = 4;
    r.seed = 7;
    return r;
}

}  // namespace

// The docs' own template once read `--envmap {env_map}`: a scene without a map left the flag
// without its value, and the renderer took the next flag for it.
TEST_CASE("validate: {name:text} puts text with the value for % where there is a value, nothing where it is empty", "[validate]") {
    SuiteScene s = plainScene();
    const RenderRequest r = requestFor(s);
    const std::string t = "r {scene} {out} {spp} {seed} {env_map:--envmap %} {env_scale:--env-scale %}{env:--env=%} -d{max_depth:%}";
    CHECK_NOTHROW(checkCommandTemplate(t));
    CHECK(expandCommand(t, r) == "r '/scenes/a.gltf' '/out/r.exr' 4 7   -d5");
    s.envMap = "/maps/it's.hdr";
    s.envScale = 2.5;
    s.envConstant = "1,1,1";
    CHECK(expandCommand(t, r) == "r '/scenes/a.gltf' '/out/r.exr' 4 7 --envmap '/maps/it'\\''s.hdr' --env-scale 2.5--env='1,1,1' -d5");
    // Every % is the value, %% a literal %; the text may hold ':' and spaces.
    CHECK(expandCommand("{spp:--spp=% (%%) a:b}", r) == "--spp=4 (%) a:b");
}

// It was 1 without a map, so `--env-scale {env_scale}` was always passed and {env_scale:...} could
// not drop it.
TEST_CASE("validate: {env_scale} is empty when the scene has no environment map", "[validate]") {
    SuiteScene s = plainScene();
    const RenderRequest r = requestFor(s);
    CHECK(expandCommand("[{env_scale}][{env_map}]", r) == "[][]");
    s.envMap = "/m.hdr";
    CHECK(expandCommand("[{env_scale}]", r) == "[1]");  // a map at its own scale
}

TEST_CASE("validate: unknown or malformed placeholders are refused with what is wrong", "[validate][errors]") {
    const std::string base = "r {scene} {out} {spp} {seed} ";
    CHECK_THROWS_WITH(checkCommandTemplate(base + "{envmap:--envmap %}"),
                      Catch::Contains("unknown placeholder {envmap}") && Catch::Contains("{name:text with %}"));
    CHECK_THROWS_WITH(checkCommandTemplate(base + "{env_map:--envmap}"), Catch::Contains("has no %"));
    CHECK_THROWS_WITH(checkCommandTemplate(base + "--envmap {env_map"), Catch::Contains("no closing '}'"));
    CHECK_THROWS_WITH(checkCommandTemplate(base + "{env_map:--e {env}}"), Catch::Contains("do not nest"));
    CHECK_THROWS_WITH(checkCommandTemplate(base + "{}"), Catch::Contains("unknown placeholder {}"));
    // The required placeholders count in either form.
    CHECK_NOTHROW(checkCommandTemplate("r {scene:-s %} {out:-o %} {spp:-n %} {seed:--seed %}"));
}

TEST_CASE("validate: {seeds} hands one process every seed of a scene, {out} then names a file per seed", "[validate]") {
    const SuiteScene s = plainScene();
    RenderRequest r = requestFor(s);
    r.output = "/out/render-seed{seed}.exr";
    r.seeds = {1, 2, 3};
    const std::string t = "r {scene} --out {out} --spp {spp} --seeds {seeds}";
    CHECK_NOTHROW(checkCommandTemplate(t));
    CHECK(commandTakesSeedList(t));
    CHECK_FALSE(commandTakesSeedList("r {scene} {out} {spp} {seed}"));
    CHECK(expandCommand(t, r) == "r '/scenes/a.gltf' --out '/out/render-seed{seed}.exr' --spp 4 --seeds 1,2,3");
    CHECK(outputForSeed(r.output, 12) == "/out/render-seed12.exr");
    CHECK(outputForSeed("/o/{seed}/x{seed}.exr", 3) == "/o/3/x3.exr");
    CHECK_THROWS_WITH(checkCommandTemplate("r {scene} {out} {spp} {seed} {seeds}"), Catch::Contains("not both"));
    CHECK_THROWS_WITH(checkCommandTemplate("r {scene} {out} {spp}"), Catch::Contains("{seed}") && Catch::Contains("{seeds}"));
}
