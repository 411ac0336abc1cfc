// validate's pilots and processes (docs/validate.md, "Budget and samples", "All renders of a scene
// in one process"): the pilots tell a renderer's start-up from its cost per sample even when the
// start-up dwarfs the samples, and a {seeds} renderer gets all of a scene's renders in one process.
// The end-to-end cases use a fake renderer that sleeps a known start-up plus a known time per
// sample and copies a ready image, so their timings are the fake's, not the machine's load.
#include "support/render_util.h"
#include "verify/validate.h"

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>

using namespace bdptref;
using namespace bdptref::test;
namespace fs = std::filesystem;

namespace {

// The pilots a renderer costing fixed + perSample * spp seconds gets, each time moved by the
// jitter jitter(k) of pilot k.
std::vector<PilotTiming> runPilots(double fixed, double perSample, const std::function<double(int)>& jitter) {
    std::vector<PilotTiming> done;
    for (int spp = nextPilotSpp(done); spp > 0; spp = nextPilotSpp(done))
        done.push_back({spp, fixed + perSample * spp + jitter(int(done.size()))});
    return done;
}

}  // namespace

// Blender: a 2.6-6 s start-up, 0.02 s per spp. The pilots at 1 and 4 spp read 0.18-0.44 s per spp
// (their floor t4 / 16), so the scenes got a tenth of the samples their share paid for.
TEST_CASE("validate: the pilots separate a long start-up from a small cost per sample", "[validate]") {
    // The start-up's jitter up to +-0.3 s, in the worst direction for the fit (first pilot slow,
    // last fast) and the other: the second pilot ends 1 + 2 * 0.3 / 3 = 1.2 times off at most.
    for (const double sign : {1.0, -1.0}) {
        const auto jitter = [&](int k) { return k == 0 ? sign * 0.3 : -sign * 0.3; };
        const std::vector<PilotTiming> p = runPilots(3.0, 0.02, jitter);
        REQUIRE(p.size() >= 3);
        CHECK(p[0].spp == 1);
        CHECK(p[1].spp == 16);
        CHECK(p.back().spp <= 512);  // clear of the start-up at 3 s of samples: 256 or 512
        const PilotFit fit = fitPilotCost(p);
        CHECK(fit.secondsPerSample == Approx(0.02).epsilon(0.25));
        CHECK(fit.fixedSeconds == Approx(3.0).margin(0.35));
    }
    // A fast renderer: 50 ms per process, 0.1 ms per spp; the samples must add 0.1 s.
    const std::vector<PilotTiming> fast = runPilots(0.05, 1e-4, [](int) { return 0.0; });
    CHECK(fast.back().spp == 1024);
    CHECK(fitPilotCost(fast).secondsPerSample == Approx(1e-4).epsilon(0.01));
    // A renderer whose time does not grow with spp stops at the largest pilot with a small, non-zero
    // cost per sample.
    const std::vector<PilotTiming> flat = runPilots(1.0, 0.0, [](int) { return 0.0; });
    CHECK(flat.back().spp == kMaxPilotSpp);
    const PilotFit f = fitPilotCost(flat);
    CHECK(f.secondsPerSample > 0);
    CHECK(f.secondsPerSample < 1e-5);
    CHECK(f.fixedSeconds == Approx(1.0).margin(0.01));
}

TEST_CASE("validate: with {seeds} a scene's need pays the fixed cost once", "[validate]") {
    SceneCost c{2.0, 0.01, 8, 100};
    CHECK(c.neededSeconds() == Approx(8 * (2.0 + 1.0)));
    c.oneProcess = true;
    CHECK(c.neededSeconds() == Approx(2.0 + 8 * 1.0));
    CHECK(sppForShare(10.0, c) == 100);  // (10 - 2) / (8 * 0.01)
}

namespace {

// A folder with a one-scene suite (the Cornell box at 16 x 16, depth 3, its reference) and a fake
// renderer fake.sh SPP OUT SEEDS [SKIP]: it sleeps 0.2 s + 1 ms per spp per seed, then copies one of
// eight ready renders to OUT with {seed} replaced by each seed in the comma-separated SEEDS, except
// SKIP. It ignores the scene: only its timing and its files matter here.
struct FakeRenderer {
    std::string dir, suite;
    explicit FakeRenderer(const std::string& tag) : dir(makeTempDir(tag)) {
        const std::string scene = sourcePath("scenes/cornell-box.gltf");
        const std::string common = " --width 16 --height 16 --max-depth 3 --integrator path --no-preview -q";
        REQUIRE(runCli("render " + scene + " -o " + dir + "/ref.exr --spp 256 --seed 1000" + common) == 0);
        for (int k = 0; k < 8; ++k)  // compare refuses identical renders
            REQUIRE(runCli("render " + scene + " -o " + dir + "/img" + std::to_string(k) + ".exr --spp 4 --seed " +
                           std::to_string(k + 1) + common) == 0);
        std::ofstream(dir + "/fake.sh") << "spp=$1; out=$2; seeds=$(echo \"$3\" | tr , ' '); n=$(echo $seeds | wc -w)\n"
                                           "sleep $(awk \"BEGIN { print 0.2 + 0.001 * $spp * $n }\")\n"
                                           "for s in $seeds; do\n"
                                           "  [ \"$s\" = \"$4\" ] && continue\n"
                                           "  cp " << dir << "/img$((s % 8)).exr \"$(echo \"$out\" | sed \"s/{seed}/$s/g\")\" || exit 1\n"
                                           "done\n";
        std::ofstream(dir + "/suite.json") << R"({"width": 16, "height": 16, "scenes": [
            {"name": "box", "scene": ")" << scene << R"(", "reference": "ref.exr", "maxDepth": 3,
             "estimators": ["path"], "exercises": ["x"], "suspects": ["y"]}]})";
        suite = dir + "/suite.json";
    }
    ValidateOptions options(const std::string& args, double budget) const {
        ValidateOptions o;
        o.command = "sh '" + dir + "/fake.sh' " + args;
        o.estimator = PortEstimator::Path;
        o.budgetSeconds = budget;
        o.outDir = dir + "/out";
        return o;
    }
};

std::string progressText(const std::vector<std::string>& lines) {
    std::string t;
    for (const std::string& l : lines) t += l + "\n";
    return t;
}

}  // namespace

TEST_CASE("validate: a renderer with a 0.2 s start-up gets the samples its budget pays for", "[validate][cli]") {
    const FakeRenderer fake("validate-pilots");
    std::vector<std::string> lines;
    const ValidateReport r = runValidation(loadSuite(fake.suite), fake.options("{spp} {out} {seed} {scene}", 2.0),
                                           [&](const std::string& l) { lines.push_back(l); }, {});
    INFO(progressText(lines));
    REQUIRE(r.scenes.size() == 1);
    const SceneOutcome& o = r.scenes[0];
    INFO(o.message);
    REQUIRE(o.verdict != SceneVerdict::Failed);
    REQUIRE(o.pilots.size() >= 3);
    CHECK(o.pilots[1].spp == 16);
    // What the fake costs: 0.2 s per process (plus the shell's and cp's), 1 ms per spp. The 1- and
    // 4-spp pilots read 0.2 / 16 = 12 ms per spp.
    CHECK(o.fixedSeconds > 0.15);
    CHECK(o.fixedSeconds < 0.5);
    CHECK(o.secondsPerSample > 0.0005);
    CHECK(o.secondsPerSample < 0.002);
    // 4 or 5 renders (whose start-ups take at most half the share): 180-280 spp each, and the
    // renders take about the budget; at 12 ms per spp they got 16 spp and half the budget.
    CHECK(o.renders == rendersForBudget(2.0, o.fixedSeconds, 8));
    CHECK(o.spp > 100);
    CHECK(o.renderSeconds > 0.6 * 2.0);
    CHECK(o.renderSeconds < 1.6 * 2.0);
}

TEST_CASE("validate: a {seeds} renderer renders all of a scene's seeds in one process, one file per seed", "[validate][cli]") {
    const FakeRenderer fake("validate-seeds");
    std::vector<std::string> lines;
    const ValidateReport r = runValidation(loadSuite(fake.suite), fake.options("{spp} {out} {seeds} -- {scene}", 2.0),
                                           [&](const std::string& l) { lines.push_back(l); }, {});
    INFO(progressText(lines));
    REQUIRE(r.scenes.size() == 1);
    const SceneOutcome& o = r.scenes[0];
    INFO(o.message);
    REQUIRE(o.verdict != SceneVerdict::Failed);
    // The start-up is paid once, so every one of the 8 renders is kept and gets the samples.
    CHECK(o.renders == 8);
    CHECK(o.spp > 150);  // (2 - 0.2) / (8 x 1 ms) = 225
    const fs::path box = fs::path(fake.dir) / "out" / "box";
    for (int s = 1; s <= 8; ++s) CHECK(fs::is_regular_file(box / ("render-seed" + std::to_string(s) + ".exr")));
    CHECK(fs::is_regular_file(box / "renders.log"));
    CHECK_FALSE(fs::exists(box / "render-1.exr.log"));
    CHECK(progressText(lines).find("8 renders at " + std::to_string(o.spp) + " spp in one process") != std::string::npos);
    CHECK(o.renderSeconds < 1.6 * 2.0);

    // A renderer that leaves out a seed's file fails the scene, naming the file.
    ValidateOptions missing = fake.options("{spp} {out} {seeds} 5 {scene}", 0);
    missing.spp = 1;
    missing.outDir = fake.dir + "/out-missing";
    const ValidateReport m = runValidation(loadSuite(fake.suite), missing, {}, {});
    CHECK(m.scenes[0].verdict == SceneVerdict::Failed);
    CHECK_THAT(m.scenes[0].message, Catch::Contains("wrote no") && Catch::Contains("render-seed5.exr"));
}
