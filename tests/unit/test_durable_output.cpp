// Durable output (issue 12, docs/exr.md "How files are written"), through the real binary:
// - disk full (a 300 KiB tmpfs, mounted as root): every output (EXR, PNG preview, --stats JSON,
//   compare --heatmap, merge -o, trace -o) exits 2 naming the file and "No space left on device",
//   the previous file is byte for byte untouched and no temp file is left;
// - a device node (our own, made with mknod; never /dev/null itself) or a FIFO is written into, not replaced;
//   a folder is refused; a symlink is followed and stays a link;
// - temp files of a killed run are removed, those of a live process are not;
// - the EXR's first part holds no exact-state channel, a part named "exact" does, with
//   chromaticities; an old single-part file is still read;
// - two outputs naming one file, or an output with the wrong extension: exit 2 before rendering.
// Where the machine does not allow mount or mknod the test prints [SKIPPED] and asserts nothing.
#include "bdptref/checkpoint.h"
#include "bdptref/exr_io.h"
#include "support/render_util.h"

#include <OpenImageIO/imageio.h>
#include <catch2/catch.hpp>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sys/stat.h>
#include <unistd.h>

using namespace bdptref;
using namespace bdptref::test;
namespace fs = std::filesystem;

namespace {

const std::string kCornell = sourcePath("scenes/cornell-box.gltf");
const std::string kSmall = " --width 32 --height 32 --spp 2 --max-depth 2 -q";

std::string slurp(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(f), {});
}
void spit(const std::string& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }

bool isCharDevice(const std::string& path) {
    struct stat st;
    return ::lstat(path.c_str(), &st) == 0 && S_ISCHR(st.st_mode);
}

int tempFilesIn(const std::string& dir) {
    int n = 0;
    for (const auto& e : fs::directory_iterator(dir)) n += e.path().filename().string().find(".tmp-") != std::string::npos;
    return n;
}

// A 300 KiB tmpfs, unmounted (and its folder removed) on destruction, even when a check failed.
struct SmallDisk {
    std::string dir, why;
    bool mounted = false;
    explicit SmallDisk(const std::string& tag) {
        dir = makeTempDir(tag) + "/disk";
        fs::create_directories(dir);
        const std::string cmd = "mount -t tmpfs -o size=300k tmpfs " + dir + " 2>&1";
        FILE* p = ::popen(cmd.c_str(), "r");
        char buf[256];
        while (p && std::fgets(buf, sizeof buf, p)) why += buf;
        mounted = p && ::pclose(p) == 0;
        if (!mounted && why.empty()) why = "mount failed";
    }
    ~SmallDisk() {
        if (mounted) std::system(("umount " + dir).c_str());
    }
    // Fills the disk so that about `leave` bytes stay free (one filler file, rewritten each call).
    void fill(size_t leave) const {
        const std::string filler = dir + "/filler";
        std::remove(filler.c_str());
        FILE* f = std::fopen(filler.c_str(), "wb");
        REQUIRE(f);
        std::vector<char> block(4096, 'x');
        size_t written = 0;
        while (std::fwrite(block.data(), 1, block.size(), f) == block.size() && std::fflush(f) == 0) written += block.size();
        std::fclose(f);
        REQUIRE(written > 0);
        fs::resize_file(filler, written > leave ? written - leave : 0);
    }
};

// `cmd` must fail on the full disk: exit 2, a message naming `target` and the reason, the
// previous content untouched, no temp file left.
void checkDiskFull(const SmallDisk& disk, const std::string& cmd, const std::string& target, size_t leave) {
    spit(target, "the previous output, which must survive\n");
    const std::string before = slurp(target);
    disk.fill(leave);
    std::string out;
    const int rc = runCli(cmd, &out);
    INFO(cmd << "\n" << out);
    CHECK(rc == 2);
    CHECK(out.find(target) != std::string::npos);
    CHECK(out.find("No space left on device") != std::string::npos);
    CHECK(slurp(target) == before);
    CHECK(tempFilesIn(disk.dir) == 0);
}

}  // namespace

TEST_CASE("Disk full: every output exits 2 naming the file, the previous file survives, no temp file remains", "[durable][cli]") {
    SmallDisk disk("durable-full");
    if (!disk.mounted) {
        std::printf("[SKIPPED] cannot mount a tmpfs (needs root): %s\n", disk.why.c_str());
        return;
    }
    const std::string d = disk.dir, elsewhere = makeTempDir("durable-full-ok");
    // A 32x32 EXR with its exact part is far larger than 8 KiB: the header fits, the pixels do not
    // (what used to leave a header-only EXR in place).
    SECTION("render -o") { checkDiskFull(disk, "render " + kCornell + " -o " + d + "/out.exr --no-preview" + kSmall, d + "/out.exr", 8192); }
    SECTION("render --preview") {
        checkDiskFull(disk, "render " + kCornell + " -o " + elsewhere + "/a.exr --preview " + d + "/prev.png" + kSmall, d + "/prev.png", 0);
    }
    SECTION("render --stats") {
        checkDiskFull(disk, "render " + kCornell + " -o " + elsewhere + "/a.exr --no-preview --stats " + d + "/stats.json" + kSmall,
                      d + "/stats.json", 0);
    }
    SECTION("merge -o and compare --heatmap") {
        const std::string a = elsewhere + "/p0.exr", b = elsewhere + "/p1.exr";
        REQUIRE(runCli("render " + kCornell + " -o " + a + " --sample-range 0:2 --no-preview --width 32 --height 32 --max-depth 2 -q") == 0);
        REQUIRE(runCli("render " + kCornell + " -o " + b + " --sample-range 2:4 --no-preview --width 32 --height 32 --max-depth 2 -q") == 0);
        checkDiskFull(disk, "merge " + a + " " + b + " -o " + d + "/merged.exr -q", d + "/merged.exr", 8192);
        checkDiskFull(disk, "compare " + a + " " + b + " --heatmap " + d + "/heat.png", d + "/heat.png", 0);
    }
    SECTION("trace -o") {
        checkDiskFull(disk, "trace " + kCornell + " --width 8 --height 8 --pixel 4,4 --max-depth 2 -o " + d + "/trace.json",
                      d + "/trace.json", 0);
    }
}

TEST_CASE("A device node is written into, never replaced, and a folder is refused", "[durable][cli]") {
    const std::string d = makeTempDir("durable-node");
    const std::string exr = d + "/sink.exr", png = d + "/sink.png";
    if (std::system(("mknod " + exr + " c 1 3 2>/dev/null && mknod " + png + " c 1 3 2>/dev/null").c_str()) != 0) {
        std::printf("[SKIPPED] mknod is not permitted here\n");
        return;
    }
    REQUIRE(isCharDevice(exr));
    std::string out;
    CHECK(runCli("render " + kCornell + " -o " + exr + " --preview " + png + kSmall, &out) == 0);
    INFO(out);
    CHECK(isCharDevice(exr));
    CHECK(isCharDevice(png));
    const std::string a = d + "/a.exr";
    REQUIRE(runCli("render " + kCornell + " -o " + a + " --no-preview" + kSmall) == 0);
    // 2 spp: "insufficient samples", exit 2 (docs/compare.md), after the heatmap is written.
    CHECK(runCli("compare " + a + " " + a + " --heatmap " + png, &out) == 2);
    CHECK(out.find("insufficient samples") != std::string::npos);
    CHECK(runCli("merge " + a + " -o " + exr + " --preview " + png + " -q", &out) == 0);
    CHECK(runCli("trace " + kCornell + " --width 8 --height 8 --pixel 4,4 --max-depth 2 -o " + exr, &out) == 0);
    CHECK(isCharDevice(exr));
    CHECK(isCharDevice(png));
    CHECK(tempFilesIn(d) == 0);
    // The same device for two outputs loses nothing, so it is not a clash.
    CHECK(runCli("render " + kCornell + " -o " + exr + " --preview " + png + " --stats " + exr + kSmall, &out) == 0);

    // A FIFO: the EXR streams through it to the reader on the other end.
    const std::string fifo = d + "/pipe.exr", got = d + "/got.exr";
    REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);
    const std::string both = "sh -c 'cat " + fifo + " > " + got + " & " + std::string(bdptref::test::bdptrefBinary()) + " render " + kCornell +
                             " -o " + fifo + " --no-preview" + kSmall + "; rc=$?; wait; exit $rc'";
    CHECK(std::system(both.c_str()) == 0);
    struct stat fst;
    CHECK((::lstat(fifo.c_str(), &fst) == 0 && S_ISFIFO(fst.st_mode)));
    CHECK(readImage(got).has("count"));

    fs::create_directories(d + "/folder.exr");
    checkInputError("render " + kCornell + " -o " + d + "/folder.exr --no-preview" + kSmall, "is a directory");
    checkInputError("merge " + a + " -o " + d + "/folder.exr", "is a directory");
}

TEST_CASE("A symlink as output stays a link and its target is replaced", "[durable][cli]") {
    const std::string d = makeTempDir("durable-link");
    const std::string real = d + "/real.exr", link = d + "/link.exr";
    REQUIRE(runCli("render " + kCornell + " -o " + real + " --no-preview --seed 1" + kSmall) == 0);
    fs::create_symlink("real.exr", link);
    REQUIRE(runCli("render " + kCornell + " -o " + link + " --no-preview --seed 7" + kSmall) == 0);
    CHECK(fs::is_symlink(fs::symlink_status(link)));
    CHECK(fs::read_symlink(link) == "real.exr");
    CHECK(readImage(real).attributes.at("bdptref:seed") == "7");
    CHECK(tempFilesIn(d) == 0);
    // /dev/stdout is a link to /proc/self/fd/1, a link to a pipe here: written into, as the kernel resolves it.
    std::string out;
    CHECK(runCli("render " + kCornell + " -o " + d + "/s.exr --no-preview --stats /dev/stdout" + kSmall, &out) == 0);
    CHECK(out.find("\"samplesPerSecond\"") != std::string::npos);
}

TEST_CASE("Temp files of a killed run are removed by the next run writing the same name", "[durable][cli]") {
    const std::string d = makeTempDir("durable-stale");
    const std::string dead = d + "/.out.exr.tmp-99999999.exr", deadProbe = d + "/.out.exr.tmp-99999998.probe";
    const std::string alive = d + "/.out.exr.tmp-" + std::to_string(::getpid()) + ".exr";  // this test process: alive
    const std::string other = d + "/.other.exr.tmp-99999999.exr";                            // another output's
    for (const std::string& f : {dead, deadProbe, alive, other}) spit(f, "partial");
    REQUIRE(runCli("render " + kCornell + " -o " + d + "/out.exr --no-preview" + kSmall) == 0);
    CHECK_FALSE(fs::exists(dead));
    CHECK_FALSE(fs::exists(deadProbe));
    CHECK(fs::exists(alive));
    CHECK(fs::exists(other));
    CHECK(fs::exists(d + "/out.exr"));
}

TEST_CASE("The EXR: image layers in the first part, the exact state in a part named 'exact', Rec.709 chromaticities", "[durable][cli][exr]") {
    const std::string d = makeTempDir("durable-exr");
    const std::string exr = d + "/bdpt.exr";
    REQUIRE(runCli("render " + kCornell + " -o " + exr + " --no-preview --integrator bdpt --strategies" + kSmall) == 0);
    auto in = OIIO::ImageInput::open(exr);
    REQUIRE(in);
    const OIIO::ImageSpec first = in->spec(0, 0);
    CHECK(first.channelindex("R") >= 0);
    CHECK(first.channelindex("count") >= 0);
    CHECK(first.channelindex("s1t2.weighted.R") >= 0);
    for (const std::string& c : first.channelnames) CHECK(c.rfind("exact.", 0) != 0);
    CHECK(first.get_string_attribute("bdptref:exact.format") == "1");
    const OIIO::ParamValue* chroma = first.find_attribute("chromaticities");
    REQUIRE(chroma);
    REQUIRE(chroma->type() == OIIO::TypeDesc(OIIO::TypeDesc::FLOAT, 8));
    const float* xy = static_cast<const float*>(chroma->data());
    const float rec709[8] = {0.64f, 0.33f, 0.30f, 0.60f, 0.15f, 0.06f, 0.3127f, 0.3290f};
    for (int k = 0; k < 8; ++k) CHECK(xy[k] == rec709[k]);
    REQUIRE(in->seek_subimage(1, 0));
    const OIIO::ImageSpec exact = in->spec();
    CHECK(exact.get_string_attribute("oiio:subimagename") == "exact");
    CHECK(exact.width == first.width);
    CHECK(exact.channelindex("exact.sum.R.hi") >= 0);
    for (int k = 0; k < exact.nchannels; ++k) {
        CHECK(exact.channelnames[size_t(k)].rfind("exact.", 0) == 0);
        CHECK(exact.channelformat(k) == OIIO::TypeDesc::UINT);
    }
    CHECK_FALSE(in->seek_subimage(2, 0));
    in->close();
    // What compare and viewers read: the first part only.
    CHECK_FALSE(readImage(exr).has("exact.sum.R.hi"));

    // A file of the previous version (one part holding everything) is still read, bit for bit.
    FilmFile now = readFilmExr(exr);
    const std::string old = d + "/old.exr";
    {
        auto rd = OIIO::ImageInput::open(exr);
        REQUIRE(rd);
        OIIO::ImageSpec a = rd->spec(0, 0), b = rd->spec(1, 0);
        std::vector<float> pa(a.image_pixels() * size_t(a.nchannels));
        std::vector<uint32_t> pb(b.image_pixels() * size_t(b.nchannels));
        REQUIRE(rd->read_image(0, 0, 0, a.nchannels, OIIO::TypeDesc::FLOAT, pa.data()));
        REQUIRE(rd->read_image(1, 0, 0, b.nchannels, OIIO::TypeDesc::UINT, pb.data()));
        OIIO::ImageSpec one = a;
        one.nchannels = a.nchannels + b.nchannels;
        one.channelformats.assign(size_t(a.nchannels), OIIO::TypeDesc::FLOAT);
        one.channelformats.resize(size_t(one.nchannels), OIIO::TypeDesc::UINT);
        for (const std::string& c : b.channelnames) one.channelnames.push_back(c);
        const size_t n = a.image_pixels(), c = size_t(one.nchannels);
        std::vector<uint32_t> px(n * c);
        for (size_t i = 0; i < n; ++i) {
            std::memcpy(&px[i * c], &pa[i * size_t(a.nchannels)], 4 * size_t(a.nchannels));
            std::memcpy(&px[i * c + size_t(a.nchannels)], &pb[i * size_t(b.nchannels)], 4 * size_t(b.nchannels));
        }
        auto wr = OIIO::ImageOutput::create(old);
        REQUIRE(wr);
        REQUIRE(wr->open(old, one));
        REQUIRE(wr->write_image(OIIO::TypeDesc::UNKNOWN, px.data()));
        REQUIRE(wr->close());
    }
    FilmFile was = readFilmExr(old);
    const Film::Accumulators x = was.film.accumulators(), y = now.film.accumulators();
    CHECK(x.sum == y.sum);
    CHECK(x.sumSquares == y.sumSquares);
    CHECK(x.count == y.count);
    CHECK(x.lightSum == y.lightSum);
    CHECK(was.film.strategies().sums(true) == now.film.strategies().sums(true));
}

TEST_CASE("Two outputs naming one file, or an output with the wrong extension: exit 2 before rendering", "[durable][cli]") {
    const std::string d = makeTempDir("durable-clash");
    const std::string x = d + "/x.exr";
    const std::string render = "render " + kCornell + kSmall;
    checkInputError(render + " -o " + x + " --preview " + x, "--preview");
    checkInputError(render + " -o " + x + " --no-preview --stats " + x, "name the same file");
    checkInputError(render + " -o " + x + " --no-preview --stats " + d + "/../" + fs::path(d).filename().string() + "/x.exr",
                    "name the same file");
    fs::create_symlink("x.png", d + "/alias.png");
    checkInputError(render + " -o " + x + " --preview " + d + "/alias.png --stats " + d + "/x.png", "name the same file");
    // -o x.png would also make the preview x.png: the EXR with the exact state would be lost.
    checkInputError(render + " -o " + d + "/x.png", "must end in '.exr'");
    checkInputError(render + " -o " + d + "/x.png --no-preview", "must end in '.exr'");
    checkInputError(render + " -o " + x + " --preview " + d + "/p.jpg", "must end in '.png'");
    int files = 0;
    for (const auto& e : fs::directory_iterator(d)) files += !fs::is_symlink(e.symlink_status());
    CHECK(files == 0);  // nothing was rendered or written

    const std::string a = d + "/a.exr";
    REQUIRE(runCli("render " + kCornell + " -o " + a + " --no-preview" + kSmall) == 0);
    checkInputError("merge " + a + " -o " + d + "/m.png", "must end in '.exr'");
    fs::create_symlink("m.exr", d + "/m-alias.png");
    checkInputError("merge " + a + " -o " + d + "/m.exr --preview " + d + "/m-alias.png", "name the same file");
    checkInputError("compare " + a + " " + a + " --heatmap " + d + "/h.exr", "must end in '.png'");
}
