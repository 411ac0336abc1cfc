// Ground-truth production as a user runs it: --time, checkpoints that survive SIGKILL, --resume
// giving the same pixels as an uninterrupted render, --sample-range + merge (directly, through
// the GNU parallel recipe and the Slurm array script of docs/distributed.md), and a header
// complete enough to re-run the image from it.
#include "bdptref/checkpoint.h"
#include "bdptref/exr_io.h"
#include "support/render_util.h"

#include <catch2/catch.hpp>

#include <cstdio>
#include <filesystem>

using namespace bdptref;
using namespace bdptref::test;
namespace fs = std::filesystem;

namespace {

const std::string kCornell = sourcePath("scenes/cornell-box.gltf");
const std::string kBin = bdptref::test::bdptrefBinary();
// Small, with splats (bdpt) so the light accumulators are exercised too.
std::string settings(int maxDepth, int seed) {
    return " --width 16 --height 12 --max-depth " + std::to_string(maxDepth) + " --integrator bdpt --seed " +
           std::to_string(seed) + " -q --no-preview";
}
const std::string kSettings = settings(4, 5);

// Runs a shell command line; returns its output (stdout + stderr) and puts the exit code in *rc.
std::string shell(const std::string& cmd, int* rc = nullptr) {
    FILE* p = ::popen(("(" + cmd + ") 2>&1").c_str(), "r");
    std::string out;
    char buf[512];
    while (p && std::fgets(buf, sizeof buf, p)) out += buf;
    const int status = p ? ::pclose(p) : -1;
    if (rc) *rc = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return out;
}

// Same pixels: every float channel equal, and the exact film state equal bit for bit.
void requireSamePixels(const std::string& a, const std::string& b) {
    checkSameImageChannels(a, b);
    FilmFile fa = readFilmExr(a), fb = readFilmExr(b);
    const Film::Accumulators x = fa.film.accumulators(), y = fb.film.accumulators();
    CHECK(x.sum == y.sum);
    CHECK(x.sumSquares == y.sumSquares);
    CHECK(x.count == y.count);
    CHECK(x.lightSum == y.lightSum);
    CHECK(fa.film.samples() == fb.film.samples());
    CHECK(fa.attribute(kAttrSettings) == fb.attribute(kAttrSettings));
}

}  // namespace

TEST_CASE("render --resume continues a render to the same pixels as an uninterrupted one", "[cli][groundtruth]") {
    const std::string dir = makeTempDir("cli-resume");
    std::string out;
    REQUIRE(runCli("render " + kCornell + " -o " + dir + "/whole.exr --spp 6" + kSettings + " --strategies", &out) == 0);
    REQUIRE(runCli("render " + kCornell + " -o " + dir + "/part.exr --spp 2" + kSettings + " --strategies", &out) == 0);
    REQUIRE(runCli("render " + kCornell + " -o " + dir + "/part.exr --resume " + dir + "/part.exr --spp 6" + kSettings +
                       " --strategies",
                   &out) == 0);
    requireSamePixels(dir + "/whole.exr", dir + "/part.exr");
    const ExrImage img = readImage(dir + "/part.exr");
    CHECK(img.attributes.at("bdptref:spp") == "6");
    CHECK(img.attributes.at("bdptref:resumedFrom") == dir + "/part.exr");
    // A checkpoint of other settings is refused, naming the setting.
    const int rc = runCli("render " + kCornell + " -o " + dir + "/x.exr --resume " + dir + "/part.exr --spp 8" + settings(5, 5) +
                              " --strategies",
                          &out);
    CHECK(rc == 2);
    CHECK(out.find("maxDepth: 4 vs 5") != std::string::npos);
}

TEST_CASE("render --resume FILE takes every setting from the header: only --spp is needed", "[cli][groundtruth][rendercli]") {
    const std::string dir = makeTempDir("cli-resume-header");
    // Settings far from the defaults, so that a setting not taken from the header changes the pixels.
    const std::string full = " --width 16 --height 12 --crop 2,1,14,11 --env 0.1,0.2,0.3 --camera-pos 278,273,-700 "
                             "--camera-target 278,273,0 --fov 35 --integrator bdpt --mis power --mis-beta 3 --max-depth 4 "
                             "--seed 11 --strategies -q --no-preview";
    std::string out;
    REQUIRE(runCli("render " + kCornell + " -o " + dir + "/whole.exr --spp 5" + full, &out) == 0);
    REQUIRE(runCli("render " + kCornell + " -o " + dir + "/run.exr --spp 2" + full, &out) == 0);
    INFO(out);
    // No scene, no settings: the header has them.
    REQUIRE(runCli("render --resume " + dir + "/run.exr -o " + dir + "/run.exr --spp 5 -q --no-preview", &out) == 0);
    requireSamePixels(dir + "/whole.exr", dir + "/run.exr");
    // The same values as the header's may be repeated (here: the scene and some settings).
    REQUIRE(runCli("render " + kCornell + " --resume " + dir + "/run.exr -o " + dir + "/more.exr --spp 6 --seed 11 "
                   "--max-depth 4 --integrator bdpt --crop 2,1,14,11 --width 16 -q --no-preview",
                   &out) == 0);
    CHECK(readFilmExr(dir + "/more.exr").film.samples().text() == "0:6");
    // A changed setting is refused, naming the option and both values.
    struct Case { std::string args, expect; };
    const std::string r = "render --resume " + dir + "/run.exr -o " + dir + "/x.exr --spp 8 -q";
    const Case cases[] = {
        {r + " --seed 7", "--seed conflicts with the checkpoint: it was rendered with seed=11, this command gives seed=7"},
        {r + " --max-depth 5", "--max-depth conflicts"},
        {r + " --crop 0,0,16,12", "crop=2,1,14,11"},
        {r + " --integrator path", "--integrator conflicts"},
        {r + " --env 1,1,1", "--env conflicts"},
        {r + " --width 32", "--width conflicts"},
        {"render " + sourcePath("scenes/veach-mis.gltf") + " --resume " + dir + "/run.exr -o " + dir + "/x.exr --spp 8",
         "sceneHash"},
    };
    for (const Case& c : cases) checkInputError(c.args, c.expect);
    CHECK_FALSE(fs::exists(dir + "/x.exr"));
}

TEST_CASE("render --resume without --spp continues to the samples the first run asked for", "[cli][groundtruth][rendercli]") {
    const std::string dir = makeTempDir("cli-resume-requested");
    // A run stopped by its time budget: its header asks for samples 0:1000000 and holds fewer.
    const std::string run = dir + "/run.exr";
    std::string out;
    REQUIRE(runCli("render " + kCornell + " -o " + run + " --spp 1000000 --time 0.2" + kSettings, &out) == 0);
    INFO(out);
    const uint64_t held = readFilmExr(run).film.samples().total();
    REQUIRE(held > 0);
    CHECK(readImage(run).attributes.at("bdptref:samplesRequested") == "0:1000000");
    // Resume asking for nothing but a time budget: it continues the same sample sequence.
    std::string o;
    REQUIRE(runCli("render --resume " + run + " -o " + dir + "/more.exr --time 0.3 -q --no-preview", &o) == 0);
    const uint64_t more = readFilmExr(dir + "/more.exr").film.samples().total();
    CHECK(more > held);
    REQUIRE(runCli("render " + kCornell + " -o " + dir + "/whole.exr --spp " + std::to_string(more) + kSettings) == 0);
    requireSamePixels(dir + "/whole.exr", dir + "/more.exr");
}

TEST_CASE("after SIGKILL the last checkpoint is intact and resumes to the uninterrupted pixels", "[cli][groundtruth][interrupt]") {
    const std::string dir = makeTempDir("cli-kill");
    const std::string ck = dir + "/ck.exr";
    const std::string out = shell(kBin + " render " + kCornell + " -o " + ck + " --spp 1000000 --checkpoint-every 0.05" +
                                  kSettings + " & pid=$!; for i in $(seq 1200); do [ -f " + ck +
                                  " ] && break; sleep 0.05; done; sleep 0.2; kill -KILL $pid; wait $pid; echo rc=$?");
    INFO(out);
    CHECK(out.find("rc=137") != std::string::npos);
    REQUIRE(fs::exists(ck));
    const FilmFile f = readFilmExr(ck);  // throws if the file were torn
    CHECK(f.attribute("bdptref:status") == "checkpoint");
    const uint64_t k = f.film.samples().total();
    REQUIRE(k > 0);
    CHECK(f.film.samples().text() == "0:" + std::to_string(k));
    const std::string target = std::to_string(k + 2);
    REQUIRE(runCli("render " + kCornell + " -o " + dir + "/resumed.exr --resume " + ck + " --spp " + target + kSettings) == 0);
    REQUIRE(runCli("render " + kCornell + " -o " + dir + "/whole.exr --spp " + target + kSettings) == 0);
    requireSamePixels(dir + "/whole.exr", dir + "/resumed.exr");
}

TEST_CASE("SIGTERM writes a final resumable checkpoint and exits 143", "[cli][groundtruth][interrupt]") {
    const std::string dir = makeTempDir("cli-term");
    const std::string exr = dir + "/t.exr";
    // TERM once the first pass is done (its progress line is on stderr): no fixed sleep.
    const std::string log = dir + "/stderr.txt";
    std::string loud = kSettings;
    loud.erase(loud.find(" -q"), 3);  // progress lines on
    const std::string out = shell(kBin + " render " + kCornell + " -o " + exr + " --spp 1000000" + loud + " 2>" + log +
                                  " & pid=$!; for i in $(seq 1200); do grep -q progress: " + log +
                                  " && break; sleep 0.05; done; kill -TERM $pid; wait $pid; echo rc=$?");
    INFO(out);
    CHECK(out.find("rc=143") != std::string::npos);
    const FilmFile f = readFilmExr(exr);
    CHECK(f.attribute("bdptref:status") == "interrupted");
    CHECK(f.film.samples().total() > 0);
    CHECK(f.film.minCount() == f.film.samples().total());
}

TEST_CASE("render --time stops at a pass boundary after the budget and records the real spp", "[cli][groundtruth]") {
    const std::string dir = makeTempDir("cli-time");
    std::string out;
    REQUIRE(runCli("render " + kCornell + " -o " + dir + "/t.exr --time 0.5" + kSettings, &out) == 0);
    const ExrImage img = readImage(dir + "/t.exr");
    const int spp = std::stoi(img.attributes.at("bdptref:spp"));
    CHECK(spp > 1);
    CHECK(img.attributes.at("bdptref:sampleRanges") == "0:" + std::to_string(spp));
    CHECK(img.attributes.at("bdptref:status") == "complete");
    CHECK(std::stod(img.attributes.at("bdptref:renderSecondsExact")) >= 0.5);
    CHECK(img.at("count", 3, 3) == float(spp));
    // With --spp as well, whichever comes first: here the spp.
    REQUIRE(runCli("render " + kCornell + " -o " + dir + "/u.exr --time 1000 --spp 3" + kSettings, &out) == 0);
    CHECK(readImage(dir + "/u.exr").attributes.at("bdptref:spp") == "3");
}

TEST_CASE("merge of --sample-range parts: exact, order-free, and refuses overlaps, gaps and other settings", "[cli][groundtruth][merge]") {
    const std::string dir = makeTempDir("cli-merge");
    std::string out;
    for (const char* r : {"0:3", "3:8", "8:10", "12:14"})
        REQUIRE(runCli("render " + kCornell + " -o " + dir + "/p" + std::string(r).substr(0, std::string(r).find(':')) +
                           ".exr --sample-range " + r + kSettings,
                       &out) == 0);
    REQUIRE(runCli("render " + kCornell + " -o " + dir + "/single.exr --spp 10" + kSettings, &out) == 0);
    REQUIRE(runCli("merge " + dir + "/p8.exr " + dir + "/p0.exr " + dir + "/p3.exr -o " + dir + "/m.exr -q", &out) == 0);
    FilmFile m = readFilmExr(dir + "/m.exr"), s = readFilmExr(dir + "/single.exr");
    CHECK(m.film.samples().text() == "0:10");
    CHECK(m.film.accumulators().count == s.film.accumulators().count);
    // Sums of 10 non-negative passes in two orders: within 2 * 9 * 2^-53 relative (test_ground_truth.cpp).
    const double bound = 18.0 * 0x1p-53;
    bool within = true;
    for (size_t i = 0; i < m.film.pixelCount(); ++i)
        for (int c = 0; c < 3; ++c)
            within = within && std::abs(m.film.accumulators().sum[i][c] - s.film.accumulators().sum[i][c]) <=
                                   bound * s.film.accumulators().sum[i][c];
    CHECK(within);
    const ExrImage mi = readImage(dir + "/m.exr");
    CHECK(mi.attributes.at("bdptref:status") == "complete");
    CHECK(mi.attributes.at("bdptref:spp") == "10");
    CHECK(mi.attributes.at("bdptref:commandLine").find("--sample-range 0:10") != std::string::npos);

    struct Case { std::string args, expect; };
    REQUIRE(runCli("render " + kCornell + " -o " + dir + "/seed6.exr --sample-range 10:12" + settings(4, 6), &out) == 0);
    REQUIRE(runCli("render " + sourcePath("scenes/cornell-small-light.gltf") + " -o " + dir + "/other.exr --sample-range 10:12" + kSettings, &out) == 0);
    const Case cases[] = {
        {dir + "/p0.exr " + dir + "/p0.exr", "overlapping"},
        {dir + "/p0.exr " + dir + "/p8.exr", "3:8"},            // the gap
        {dir + "/p3.exr " + dir + "/seed6.exr", "seed: 6 vs 5"},
        {dir + "/p8.exr " + dir + "/other.exr", "another scene"},
        {dir + "/p0.exr " + dir + "/missing.exr", "missing.exr"},
    };
    for (const Case& c : cases) checkInputError("merge " + c.args + " -o " + dir + "/bad.exr", c.expect);
    CHECK_FALSE(fs::exists(dir + "/bad.exr"));
    REQUIRE(runCli("merge " + dir + "/p0.exr " + dir + "/p3.exr " + dir + "/p12.exr --allow-gaps -o " + dir + "/g.exr -q", &out) == 0);
    CHECK(readImage(dir + "/g.exr").attributes.at("bdptref:sampleRanges") == "0:8,12:14");
    CHECK(readImage(dir + "/g.exr").attributes.at("bdptref:status") == "merged with gaps");
}

TEST_CASE("the GNU parallel recipe and the Slurm array script render parts that merge to the single render", "[cli][groundtruth][distributed]") {
    const std::string dir = makeTempDir("cli-distributed");
    std::string out;
    REQUIRE(runCli("render " + kCornell + " -o " + dir + "/single.exr --spp 12" + kSettings, &out) == 0);
    int rc = 0;
    // Four parts of 3 samples, two jobs at a time, on this machine (SSHLOGINS ":").
    out = shell("BDPTREF=" + kBin + " JOBS=2 SSHLOGINS=: " + sourcePath("tools/distributed/render-parallel.sh") + " " + dir +
                    "/par.exr 12 3 " + kCornell + kSettings,
                &rc);
    INFO(out);
    REQUIRE(rc == 0);
    CHECK(fs::exists(dir + "/par.exr.parts/part-4.exr"));
    // Three Slurm array tasks of 4 samples (bash ignores the #SBATCH lines), then the merge.
    for (int k = 0; k < 3; ++k) {
        out = shell("SLURM_ARRAY_TASK_ID=" + std::to_string(k) + " BDPTREF=" + kBin + " " +
                        sourcePath("tools/distributed/slurm-render.sbatch") + " " + dir + "/slurm 4 " + kCornell + kSettings,
                    &rc);
        INFO(out);
        REQUIRE(rc == 0);
    }
    REQUIRE(runCli("merge " + dir + "/slurm/part-0.exr " + dir + "/slurm/part-1.exr " + dir + "/slurm/part-2.exr -o " + dir +
                       "/slurm.exr -q",
                   &out) == 0);
    for (const std::string name : {"par", "slurm"}) {
        FilmFile m = readFilmExr(dir + "/" + name + ".exr"), s = readFilmExr(dir + "/single.exr");
        INFO(name);
        CHECK(m.film.samples().text() == "0:12");
        CHECK(m.film.accumulators().count == s.film.accumulators().count);
        const double bound = 22.0 * 0x1p-53;  // 2 (n - 1) u, n = 12
        bool within = true;
        for (size_t i = 0; i < m.film.pixelCount(); ++i)
            for (int c = 0; c < 3; ++c)
                within = within && std::abs(m.film.accumulators().sum[i][c] - s.film.accumulators().sum[i][c]) <=
                                       bound * s.film.accumulators().sum[i][c] &&
                         std::abs(m.film.accumulators().lightSum[i][c] - s.film.accumulators().lightSum[i][c]) <=
                             bound * s.film.accumulators().lightSum[i][c];
        CHECK(within);
    }
}

TEST_CASE("the header's commandLine re-renders the same pixels", "[cli][groundtruth]") {
    const std::string dir = makeTempDir("cli-reproduce");
    std::string out;
    REQUIRE(runCli("render " + kCornell + " -o " + dir + "/a.exr --spp 3 --env 0.1,0.2,0.3 --camera-pos 278,273,-700 "
                   "--camera-target 278,273,0 --fov 35 --crop 2,1,14,11 --width 16 --height 12 --integrator bdpt --mis power "
                   "--mis-beta 3 --max-depth 4 --seed 11 -q --no-preview",
                   &out) == 0);
    const ExrImage a = readImage(dir + "/a.exr");
    std::string cmd = a.attributes.at("bdptref:commandLine");
    REQUIRE(cmd.rfind("bdptref render ", 0) == 0);
    cmd = kBin + cmd.substr(7);
    cmd = cmd.substr(0, cmd.rfind(" -o ")) + " -o " + dir + "/b.exr -q --no-preview";
    int rc = 0;
    out = shell(cmd, &rc);
    INFO(cmd << "\n" << out);
    REQUIRE(rc == 0);
    requireSamePixels(dir + "/a.exr", dir + "/b.exr");
    for (const char* key : {"bdptref:sceneHash", "bdptref:seed", "bdptref:sampleRanges", "bdptref:spp", "bdptref:renderSeconds",
                            "bdptref:version", "bdptref:gitRevision", "bdptref:threads", "bdptref:settings", "bdptref:invocation"})
        CHECK(a.attributes.count(key) == 1);
}

TEST_CASE("ground-truth options: bad input exits with code 2 and names the problem", "[cli][groundtruth][errors]") {
    const std::string dir = makeTempDir("cli-gt-bad");
    const std::string r = "render " + kCornell + " -o " + dir + "/x.exr" + kSettings;
    struct Case { std::string args, expect; };
    const Case cases[] = {
        {r + " --spp 4 --sample-range 0:4", "--sample-range"},
        {r + " --sample-range 5:3", "--sample-range"},
        {r + " --sample-range 5", "--sample-range"},
        {r + " --time -1", "--time"},
        {r + " --checkpoint-every -2", "--checkpoint-every"},
        {r + " --time 0", "--time must be a positive"},
        {r + " --checkpoint-every 0", "--checkpoint-every must be a positive"},
        {r + " --resume " + dir + "/missing.exr", "missing.exr"},
        {r + " --resume " + sourcePath("scenes/cornell-box.gltf"), "cornell-box.gltf"},
        {"merge -o " + dir + "/x.exr", "parts"},
    };
    for (const Case& c : cases) checkInputError(c.args, c.expect);
    CHECK_FALSE(fs::exists(dir + "/x.exr"));
}
