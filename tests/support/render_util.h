// Helpers for tests that render: load a shipped scene, render it with the library, pool
// statistics over all pixel samples, run the command-line tool.
#pragma once

#include "bdptref/exr_io.h"
#include "bdptref/film.h"
#include "bdptref/scene.h"

#include <functional>
#include <string>

namespace bdptref::test {

std::string sourcePath(const std::string& relative);  // path inside the repository
Scene loadTestScene(const std::string& relative, int width, int height, const Rgb& env = Rgb(0.f));
// The same scene seen through an orthographic camera at the file camera's position and
// orientation, with a film of half-height ymag (world units).
Scene loadTestSceneOrthographic(const std::string& relative, int width, int height, float ymag, const Rgb& env = Rgb(0.f));
Film renderFilm(const Scene& scene, const std::string& integrator, int spp, int maxDepth, uint32_t seed, int threads = 0);

// Mean over every sample of every pixel, with its standard error (the samples are independent;
// the scenes these are used on have the same expected value in every pixel).
struct PooledMean {
    DVec3 mean{0.0};
    DVec3 standardError{0.0};
    uint64_t samples = 0;
};
PooledMean pooledMean(const Film& film);

// The repository root and the bdptref executable of this build (absolute paths; test_paths.cpp).
const char* sourceDir();
const char* bdptrefBinary();

// Runs the bdptref executable with arguments (a shell string); returns its exit code and
// captures stderr+stdout into `output`.
int runCli(const std::string& args, std::string* output = nullptr);
// Runs `bdptref ARGS` and checks the bad-input contract: exit code 2, a message containing
// `expect` (the file or option and the problem), and no crash.
void checkInputError(const std::string& args, const std::string& expect);

// Every channel of two image files (EXR: the first part) equal, value for value (REQUIREs the same
// channel names).
void checkSameImageChannels(const std::string& a, const std::string& b);

// A fresh empty folder under the system temp dir for one test's files; removed when the test
// process exits (BDPTREF_KEEP_TEST_FILES=1 keeps it).
std::string makeTempDir(const std::string& tag);

// A grey size x size image whose every pixel is the mean of `spp` values of sample(x, y) (drawn row
// by row, x inner, the samples of a pixel in turn); with `stats` also variance.R/G/B (of the mean)
// and count: hand-made test inputs for compare.
ExrImage greyImageOfSamples(int size, int spp, bool stats, const std::function<double(int, int)>& sample);

// Writes every channel of `img` to an EXR (no metadata): hand-made test inputs for compare.
void writeImageChannels(const std::string& path, const ExrImage& img);

}  // namespace bdptref::test
