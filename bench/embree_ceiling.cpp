// The Embree ceiling of a scene: how many rays per second Embree alone traces through the same
// BVH (same build settings as the renderer, src/scene/accel.cpp) when given rays distributed like
// a bidirectional path tracer's, with no shading, sampling or film work around them.
//
// Ray generation (untimed): subpaths of up to --depth bounces with cosine-weighted diffuse
// bounces, alternately from the camera (through uniformly random pixels) and from a point on a
// light chosen by power (cosine emission). Extension rays are their segments; shadow rays join a
// camera-subpath vertex to a light-subpath vertex of the same pair (as BDPT connections do) or to
// a point on a light (as next-event estimation does). The requested numbers of each kind are
// traced (the generated pool is reused cyclically when smaller), in parallel over --threads,
// with Embree's single-ray API, exactly as the renderer calls it. Output: one JSON object.
#include "bdptref/gltf_loader.h"
#include "bdptref/sampling.h"
#include "bdptref/scene.h"
#include "scene/accel.h"

#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

using namespace bdptref;

namespace {

struct ShadowRay {
    Vec3 origin, dir;  // dir unnormalised: the segment is t in (0, 1)
};

struct Args {
    std::string scene;
    int width = 64, height = 64, threads = 0, depth = 5;
    long long extension = 1000000, shadow = 1000000;
    long long pool = 2000000;
    unsigned seed = 1;
    int repeats = 3;
};

[[noreturn]] void usage(const char* msg) {
    std::fprintf(stderr,
                 "embree_ceiling: %s\n"
                 "usage: embree_ceiling SCENE.gltf [--width W --height H] [--extension N] [--shadow N]\n"
                 "       [--threads T] [--depth D] [--pool N] [--repeats R] [--seed S]\n"
                 "Traces N extension (closest-hit) and N shadow (occlusion) rays distributed like BDPT's\n"
                 "through Embree alone; prints JSON with the median rays/s of R repeats.\n",
                 msg);
    std::exit(2);
}

Args parseArgs(int argc, char** argv) {
    Args a;
    for (int i = 1; i < argc; ++i) {
        const std::string k = argv[i];
        auto next = [&]() -> std::string {
            if (i + 1 >= argc) usage(("missing value after " + k).c_str());
            return argv[++i];
        };
        try {
            if (k == "--width") a.width = std::stoi(next());
            else if (k == "--height") a.height = std::stoi(next());
            else if (k == "--threads") a.threads = std::stoi(next());
            else if (k == "--depth") a.depth = std::stoi(next());
            else if (k == "--extension") a.extension = std::stoll(next());
            else if (k == "--shadow") a.shadow = std::stoll(next());
            else if (k == "--pool") a.pool = std::stoll(next());
            else if (k == "--repeats") a.repeats = std::stoi(next());
            else if (k == "--seed") a.seed = unsigned(std::stoul(next()));
            else if (k == "-h" || k == "--help") usage("help");
            else if (!k.empty() && k[0] == '-') usage(("unknown option " + k).c_str());
            else a.scene = k;
        } catch (const std::exception&) {
            usage(("bad value for " + k).c_str());
        }
    }
    if (a.scene.empty()) usage("no scene given");
    if (a.width < 1 || a.height < 1 || a.threads < 0 || a.depth < 1 || a.extension < 0 || a.shadow < 0 || a.pool < 1 ||
        a.repeats < 1)
        usage("values out of range");
    return a;
}

struct Pools {
    std::vector<Ray> extension;
    std::vector<ShadowRay> shadow;
};

// One subpath from `ray`, diffuse bounces; appends its rays and returns its hit points/normals.
void walk(const Scene& scene, Ray ray, int depth, std::mt19937& rng, Pools& pools, std::vector<std::pair<Vec3, Vec3>>& hits) {
    std::uniform_real_distribution<float> U(0.f, 1.f);
    for (int d = 0; d < depth; ++d) {
        pools.extension.push_back(ray);
        SurfaceHit hit;
        if (!scene.intersect(ray, &hit)) return;
        hits.emplace_back(hit.p, hit.ng);
        const Vec3 n = glm::dot(hit.ng, ray.dir) < 0.f ? hit.ng : -hit.ng;
        const Vec3 local = squareToCosineHemisphere(Vec2(U(rng), U(rng)));
        ray.dir = glm::normalize(Frame(n).toWorld(local));
        ray.origin = offsetRayOrigin(hit.p, n);
        ray.tMax = kInfinity;
    }
}

Pools generate(const Scene& scene, const Args& a) {
    Pools pools;
    std::mt19937 rng(a.seed);
    std::uniform_real_distribution<float> U(0.f, 1.f);
    std::vector<std::pair<Vec3, Vec3>> camHits, lightHits;
    const size_t want = size_t(a.pool);
    size_t guard = 0;
    while ((pools.extension.size() < want || pools.shadow.size() < want) && ++guard < 100 * want) {
        camHits.clear();
        lightHits.clear();
        walk(scene, scene.camera.generateRay(Vec2(U(rng) * float(a.width), U(rng) * float(a.height))), a.depth, rng,
             pools, camHits);
        float pmf = 0.f;
        const int li = scene.lightSampler().sample(U(rng), &pmf);
        if (li >= 0) {
            LightLeSample le;
            const Light& l = scene.lights[size_t(li)];
            if (sampleLe(l, Vec2(U(rng), U(rng)), Vec2(U(rng), U(rng)), &le)) {
                Ray r = le.ray;
                if (l.type == LightType::Area) {
                    r.origin = offsetRayOrigin(r.origin, glm::dot(r.dir, le.nLight) > 0.f ? le.nLight : -le.nLight);
                    lightHits.emplace_back(le.ray.origin, le.nLight);
                }
                walk(scene, r, a.depth, rng, pools, lightHits);
            }
        }
        // Connections: every camera vertex to every light vertex (BDPT's full vertex connection).
        for (const auto& [pc, nc] : camHits)
            for (const auto& [pl, nl] : lightHits) {
                const Vec3 o = offsetRayOrigin(pc, glm::dot(nc, pl - pc) >= 0.f ? nc : -nc);
                const Vec3 e = offsetRayOrigin(pl, glm::dot(nl, pc - pl) >= 0.f ? nl : -nl);
                pools.shadow.push_back(ShadowRay{o, e - o});
            }
        // Light-subpath vertices to the pinhole (BDPT's t = 1 / light tracing).
        const Vec3 eye = scene.camera.position();
        for (const auto& [pl, nl] : lightHits) {
            const Vec3 o = offsetRayOrigin(pl, glm::dot(nl, eye - pl) >= 0.f ? nl : -nl);
            pools.shadow.push_back(ShadowRay{o, eye - o});
        }
    }
    if (pools.extension.empty() || pools.shadow.empty()) {
        std::fprintf(stderr, "embree_ceiling: the scene produced no rays (no lights or no geometry?)\n");
        std::exit(2);
    }
    return pools;
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace

int main(int argc, char** argv) {
    const Args a = parseArgs(argc, argv);
    Scene scene;
    try {
        LoadOptions lo;
        lo.width = a.width;
        lo.height = a.height;
        scene = loadGltfScene(a.scene, lo);
        scene.finalize();
    } catch (const std::exception& e) {
        std::fprintf(stderr, "embree_ceiling: %s\n", e.what());
        return 2;
    }
    const Pools pools = generate(scene, a);
    // A separate Accel with the renderer's build settings: only Embree's work is timed.
    const Accel accel(scene.mesh.positions, scene.mesh.indices);
    std::unique_ptr<tbb::global_control> limit;
    if (a.threads > 0)
        limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, size_t(a.threads));

    std::atomic<uint64_t> checksum{0};
    auto traceAll = [&](long long nExt, long long nShadow) {
        const auto t0 = std::chrono::steady_clock::now();
        const long long total = nExt + nShadow;
        tbb::parallel_for(tbb::blocked_range<long long>(0, total, 4096), [&](const tbb::blocked_range<long long>& r) {
            setFlushDenormals();
            uint64_t local = 0;
            for (long long i = r.begin(); i != r.end(); ++i) {
                if (i < nExt) {
                    EmbreeHit h;
                    local += accel.intersect(pools.extension[size_t(i) % pools.extension.size()], &h) ? h.triangle : 0u;
                } else {
                    const ShadowRay& s = pools.shadow[size_t(i - nExt) % pools.shadow.size()];
                    local += accel.occluded(s.origin, s.dir, 1.f) ? 1u : 0u;
                }
            }
            checksum += local;  // keeps the queries from being optimised away
        });
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    };
    std::vector<double> secs;
    for (int r = 0; r < a.repeats; ++r) secs.push_back(traceAll(a.extension, a.shadow));
    const double s = median(secs);
    const double total = double(a.extension + a.shadow);
    // Extension and shadow rays separately (their rates differ: occlusion stops at the first hit).
    const double sExt = a.extension > 0 ? traceAll(a.extension, 0) : 0.0;
    const double sSh = a.shadow > 0 ? traceAll(0, a.shadow) : 0.0;
    std::printf(
        "{\n \"scene\": \"%s\",\n \"triangles\": %zu,\n \"threads\": %d,\n \"extensionRays\": %lld,\n"
        " \"shadowRays\": %lld,\n \"poolExtension\": %zu,\n \"poolShadow\": %zu,\n \"repeats\": %d,\n"
        " \"seconds\": %.9g,\n \"raysPerSecond\": %.9g,\n \"extensionRaysPerSecond\": %.9g,\n"
        " \"shadowRaysPerSecond\": %.9g,\n \"checksum\": %llu\n}\n",
        a.scene.c_str(), scene.mesh.triangleCount(), a.threads, a.extension, a.shadow, pools.extension.size(),
        pools.shadow.size(), a.repeats, s, total / s, sExt > 0 ? double(a.extension) / sExt : 0.0,
        sSh > 0 ? double(a.shadow) / sSh : 0.0, static_cast<unsigned long long>(checksum.load()));
    return 0;
}
