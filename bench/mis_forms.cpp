// The two production MIS forms side by side on one scene (bench/README.md, "Recursive MIS"): the
// BDPT integrator's per-sample loop (src/render/bdpt_integrator.cpp: subpaths, evaluateConnection,
// the shadow ray) ending either in the recursive weight (connectionDensities + misWeightRecursive,
// what finishConnection does now) or in the ratio walk (misWeight, what it did before), or in no
// weight at all (the rest of the loop's cost). The loops run interleaved in one process on one
// thread; each reports the CPU seconds of its passes and a checksum of the weighted contributions
// (walk and recursive agree to rounding). Both subpath generators fill dVCM/dVC in every form.
//
//   mis_forms SCENE [--width W] [--height H] [--spp N] [--reps R]
#include "bdptref/bdpt.h"
#include "bdptref/gltf_loader.h"
#include "bdptref/scene.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <string>
#include <vector>

using namespace bdptref;

namespace {

double cpuSeconds() { return double(std::clock()) / CLOCKS_PER_SEC; }

// One pass over every pixel at `spp` samples; returns the sum of the weighted contributions.
enum class Form { None, Walk, Recursive };
const char* const kFormNames[3] = {"no weight", "walk", "recursive"};

double pass(const Scene& scene, int spp, Form form) {
    BdptSettings settings;
    std::vector<PathVertex> camera(size_t(settings.maxCameraVertices())), light(size_t(settings.maxLightVertices()));
    std::vector<Bsdf> cameraBsdfs(camera.size()), lightBsdfs(light.size());
    const SubpathBsdfs bsdfs{lightBsdfs.data(), cameraBsdfs.data()};
    const int w = scene.camera.width(), h = scene.camera.height();
    double sum = 0.0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int k = 0; k < spp; ++k) {
                const PixelSampler sampler(1u, uint32_t(y * w + x), uint64_t(k));
                const Vec2 raster = Vec2(float(x), float(y)) + sampler.get2D(RngStream::Camera, dim::kFilm);
                const int nc = generateCameraSubpath(scene, sampler, raster, settings, camera.data(), cameraBsdfs.data());
                const int nl = generateLightSubpath(scene, sampler, settings, light.data(), lightBsdfs.data());
                for (int t = 1; t <= nc; ++t)
                    for (int s = 0; s <= lastLightStrategy(nl, t); ++s) {
                        if (strategyStatus(s, t, settings.maxDepth, false) != StrategyStatus::Evaluated) continue;
                        PendingConnection p;
                        if (!evaluateConnection(scene, light.data(), s, camera.data(), t, sampler, &p, settings.mis.lightSampler, bsdfs)) continue;
                        if (p.needsShadowRay && !traceShadowRay(scene, p.shadow)) continue;
                        double weight = 1.0;
                        if (form == Form::Recursive) {
                            const ConnectionDensities d = connectionDensities(scene, light.data(), s, camera.data(), t, p.sampled, settings.mis, bsdfs);
                            weight = misWeightRecursive(scene, light.data(), s, camera.data(), t, p.sampled, d, settings.mis);
                        } else if (form == Form::Walk) {
                            weight = misWeight(scene, light.data(), s, camera.data(), t, p.sampled, settings.mis, bsdfs);
                        }
                        sum += double(p.unweighted.x + p.unweighted.y + p.unweighted.z) * weight;
                    }
            }
    return sum;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: mis_forms SCENE [--width W] [--height H] [--spp N] [--reps R]\n");
        return 2;
    }
    LoadOptions lo;
    lo.width = 64;
    lo.height = 64;
    int spp = 4, reps = 3;
    for (int i = 2; i + 1 < argc; i += 2) {
        const std::string k = argv[i];
        const int v = std::atoi(argv[i + 1]);
        if (k == "--width") lo.width = v;
        else if (k == "--height") lo.height = v;
        else if (k == "--spp") spp = v;
        else if (k == "--reps") reps = v;
        else {
            std::fprintf(stderr, "mis_forms: unknown option %s\n", k.c_str());
            return 2;
        }
    }
    Scene scene;
    try {
        scene = loadGltfScene(argv[1], lo);
        scene.finalize();
    } catch (const std::exception& e) {
        std::fprintf(stderr, "mis_forms: %s\n", e.what());
        return 2;
    }
    std::vector<double> seconds[3];
    double checksum[3] = {0.0, 0.0, 0.0};
    for (int r = 0; r < reps; ++r)
        for (int f = 0; f < 3; ++f) {  // interleaved: the machine's load hits every form alike
            const double t0 = cpuSeconds();
            checksum[f] = pass(scene, spp, Form(f));
            seconds[f].push_back(cpuSeconds() - t0);
        }
    std::printf("%dx%d, %d spp, %d reps, CPU seconds per pass (median, min):\n", lo.width, lo.height, spp, reps);
    for (int f = 0; f < 3; ++f) {
        std::sort(seconds[f].begin(), seconds[f].end());
        std::printf("  %-10s %.3f %.3f  checksum %.9g\n", kFormNames[f], seconds[f][seconds[f].size() / 2], seconds[f].front(),
                    checksum[f]);
    }
    return 0;
}
