#include "support/render_util.h"

#include "bdptref/exr_io.h"
#include "bdptref/gltf_loader.h"
#include "bdptref/integrator.h"
#include "bdptref/renderer.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <vector>
#include <sys/wait.h>
#include <unistd.h>

namespace bdptref::test {

std::string sourcePath(const std::string& relative) { return std::string(sourceDir()) + "/" + relative; }

Scene loadTestScene(const std::string& relative, int width, int height, const Rgb& env) {
    LoadOptions o;
    o.width = width;
    o.height = height;
    Scene s = loadGltfScene(sourcePath(relative), o);
    s.camera = s.camera.withResolution(width, height);
    if (!isBlack(env)) s.setEnvironment(env);
    s.finalize();
    return s;
}

Scene loadTestSceneOrthographic(const std::string& relative, int width, int height, float ymag, const Rgb& env) {
    LoadOptions o;
    o.width = width;
    o.height = height;
    Scene s = loadGltfScene(sourcePath(relative), o);
    const Camera& c = s.camera;
    s.camera = Camera::orthographicLookAt(c.position(), c.position() + c.forward(), c.up(), ymag, width, height);
    if (!isBlack(env)) s.setEnvironment(env);
    s.finalize();
    return s;
}

Film renderFilm(const Scene& scene, const std::string& integrator, int spp, int maxDepth, uint32_t seed, int threads) {
    IntegratorSettings is;
    is.maxDepth = maxDepth;
    const auto integ = makeIntegrator(integrator, is);
    RenderOptions ro;
    ro.spp = spp;
    ro.seed = seed;
    ro.threads = threads;
    Film film(scene.camera.width(), scene.camera.height());
    renderImage(scene, *integ, ro, film);
    return film;
}

PooledMean pooledMean(const Film& film) {
    DVec3 s(0.0), s2(0.0);
    uint64_t n = 0;
    for (int y = 0; y < film.height(); ++y)
        for (int x = 0; x < film.width(); ++x) {
            s += film.sum(x, y);
            s2 += film.sumSquares(x, y);
            n += film.count(x, y);
        }
    PooledMean r;
    r.samples = n;
    r.mean = s / double(n);
    const DVec3 var = glm::max(DVec3(0.0), (s2 - double(n) * r.mean * r.mean) / double(n - 1));
    r.standardError = glm::sqrt(var / double(n));
    return r;
}

int runCli(const std::string& args, std::string* output) {
    const std::string cmd = std::string(bdptrefBinary()) + " " + args + " 2>&1";
    FILE* p = ::popen(cmd.c_str(), "r");
    if (!p) return -1;
    std::array<char, 4096> buf;
    std::string out;
    size_t k;
    while ((k = std::fread(buf.data(), 1, buf.size(), p)) > 0) out.append(buf.data(), k);
    const int status = ::pclose(p);
    if (output) *output = out;
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

namespace {
// The folders makeTempDir made, removed when the test process exits (a suite run left ~1500 of
// them in /tmp). BDPTREF_KEEP_TEST_FILES=1 keeps them, to look at a failing test's files.
struct TempDirRegistry {
    std::vector<std::filesystem::path> dirs;
    ~TempDirRegistry() {
        const char* keep = std::getenv("BDPTREF_KEEP_TEST_FILES");
        if (keep && *keep && std::string(keep) != "0") return;
        for (const auto& d : dirs) {
            std::error_code ec;
            std::filesystem::remove_all(d, ec);
        }
    }
};
TempDirRegistry& tempDirRegistry() {
    static TempDirRegistry registry;
    return registry;
}
}  // namespace

std::string makeTempDir(const std::string& tag) {
    namespace fs = std::filesystem;
    const fs::path dir = fs::temp_directory_path() / ("bdptref-test-" + tag + "-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    auto& dirs = tempDirRegistry().dirs;
    if (std::find(dirs.begin(), dirs.end(), dir) == dirs.end()) dirs.push_back(dir);
    return dir.string();
}

void checkInputError(const std::string& args, const std::string& expect) {
    std::string out;
    const int rc = runCli(args, &out);
    INFO(args << "\n" << out);
    CHECK(rc == 2);
    CHECK(out.find(expect) != std::string::npos);
    CHECK(out.find("Segmentation") == std::string::npos);
}

void checkSameImageChannels(const std::string& a, const std::string& b) {
    INFO(a << " vs " << b);
    const ExrImage ia = readImage(a), ib = readImage(b);
    REQUIRE(ia.channels.size() == ib.channels.size());
    for (const auto& [name, pixels] : ia.channels) {
        INFO(name);
        REQUIRE(ib.channels.count(name) == 1);
        CHECK(pixels == ib.channels.at(name));
    }
}

ExrImage greyImageOfSamples(int size, int spp, bool stats, const std::function<double(int, int)>& sample) {
    ExrImage img;
    img.width = img.height = size;
    img.window = FilmWindow::full(size, size);
    const size_t n = size_t(size) * size_t(size);
    std::vector<float> mean(n), var(n);
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            double s1 = 0, s2 = 0;
            for (int k = 0; k < spp; ++k) {
                const double v = sample(x, y);
                s1 += v;
                s2 += v * v;
            }
            const size_t i = size_t(y) * size_t(size) + size_t(x);
            mean[i] = float(s1 / spp);
            var[i] = float((s2 - s1 * s1 / spp) / (spp - 1) / spp);
        }
    for (const char* c : {"R", "G", "B"}) {
        img.channels[c] = mean;
        if (stats) img.channels[std::string("variance.") + c] = var;
    }
    if (stats) img.channels["count"].assign(n, float(spp));
    return img;
}

void writeImageChannels(const std::string& path, const ExrImage& img) {
    std::vector<ExrLayer> layers;
    for (const auto& [name, pixels] : img.channels) layers.push_back({name, pixels});
    writeLayersExr(path, img.width, img.height, layers, ExrMetadata{});
}

}  // namespace bdptref::test
