// The light tree's walk cost on one scene (bench/README.md, "Many lights: the light tree"):
//
//     light_tree_micro scene.gltf [points] [rounds]
//
// Shading points = the first hits of camera rays through random pixels (those the path tracer
// shades first). Prints the build time, the tree's size and depth, and ns per sample() and per
// pmf() (of the light sample returned), best of `rounds` passes over the points (thread CPU time).
#include "bdptref/bdptref.h"
#include "bdptref/light_tree.h"
#include "bdptref/scene.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <random>
#include <vector>

using namespace bdptref;

namespace {

// Thread CPU time: the machine may be shared (wall time would count the other processes' turns).
double cpuSeconds() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

struct Point {
    Vec3 p, n;
    float u;
};

std::vector<Point> shadingPoints(const Scene& scene, size_t count) {
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> uni(0.f, 1.f);
    std::vector<Point> points;
    for (size_t tries = 0; points.size() < count && tries < 20 * count; ++tries) {
        const Ray ray = scene.camera.generateRay(Vec2(uni(rng) * 256.f, uni(rng) * 256.f));
        SurfaceHit hit;
        if (scene.intersect(ray, &hit)) points.push_back(Point{hit.p, hit.ng, uni(rng)});
    }
    return points;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: light_tree_micro scene.gltf [points] [rounds]\n");
        return 2;
    }
    const size_t count = argc > 2 ? size_t(std::atol(argv[2])) : 20000;
    const int rounds = argc > 3 ? std::atoi(argv[3]) : 5;
    const Scene scene = loadSceneFile(argv[1]);
    double t0 = cpuSeconds();
    const LightTree tree(scene.lights);
    const double buildS = (cpuSeconds() - t0);
    const std::vector<Point> points = shadingPoints(scene, count);
    double bestSample = 1e30, bestPmf = 1e30, checksum = 0;
    std::vector<int> chosen(points.size());
    for (int r = 0; r < rounds; ++r) {
        t0 = cpuSeconds();
        for (size_t i = 0; i < points.size(); ++i) {
            float pmf = 0.f;
            chosen[i] = tree.sample(points[i].p, points[i].n, points[i].u, &pmf);
            checksum += pmf;
        }
        bestSample = std::min(bestSample, (cpuSeconds() - t0));
        t0 = cpuSeconds();
        for (size_t i = 0; i < points.size(); ++i)
            if (chosen[i] >= 0) checksum += tree.pmf(points[i].p, points[i].n, chosen[i]);
        bestPmf = std::min(bestPmf, (cpuSeconds() - t0));
    }
    const double n = double(std::max<size_t>(points.size(), 1));
    std::printf("lights %zu  nodes %zu  depth %d  build %.1f ms  points %zu\n", scene.lights.size(), tree.nodeCount(),
                tree.depth(), buildS * 1e3, points.size());
    std::printf("sample %.0f ns  pmf %.0f ns  (checksum %.6g)\n", bestSample / n * 1e9, bestPmf / n * 1e9, checksum);
    return 0;
}
