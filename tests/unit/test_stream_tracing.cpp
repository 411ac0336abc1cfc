// Embree's stream API (docs/wavefront.md, "Stage graph": extend and shadow): Scene::intersectStream
// and Scene::occludedStream, which the wavefront mode's launches trace their chunks through, must
// answer exactly what Scene::intersect / visible / visibleToInfinity answer ray by ray (the
// megakernel's calls), bit for bit, including on alpha-tested (MASK / BLEND) surfaces, whose
// filter reads each ray's origin and direction from the ray Embree hands it. Rays: from random
// points towards random points and directions of the scene's bounds (fixed seed), in streams of
// 0, 1, 63, 64, 65 and 200 rays (the batches are 64 long).
#include "support/render_util.h"

#include "bdptref/sampling.h"
#include "bdptref/scene.h"

#include <catch2/catch.hpp>

#include <cstring>
#include <memory>
#include <random>
#include <vector>

using namespace bdptref;

namespace {

bool sameHit(const SurfaceHit& a, const SurfaceHit& b) {
    return std::memcmp(&a.p, &b.p, sizeof a.p) == 0 && std::memcmp(&a.ns, &b.ns, sizeof a.ns) == 0 &&
           std::memcmp(&a.ng, &b.ng, sizeof a.ng) == 0 && a.t == b.t && a.triangle == b.triangle && a.material == b.material &&
           a.bary == b.bary && a.light == b.light;
}

struct RandomRays {
    std::mt19937 rng{20261128u};
    const Scene* scene = nullptr;
    Vec3 lo, hi;
    // A random point of a random triangle: rays aimed through it cross the surfaces (alpha-tested
    // ones included) where random rays would mostly miss the small cut-out quads.
    Vec3 surfacePoint() {
        std::uniform_real_distribution<float> u(0.f, 1.f);
        const size_t tri = std::min(scene->mesh.triangleCount() - 1, size_t(u(rng) * float(scene->mesh.triangleCount())));
        const glm::uvec3 idx = scene->mesh.indices[tri];
        float b1 = u(rng), b2 = u(rng);
        if (b1 + b2 > 1.f) b1 = 1.f - b1, b2 = 1.f - b2;
        return (1.f - b1 - b2) * scene->mesh.positions[idx.x] + b1 * scene->mesh.positions[idx.y] + b2 * scene->mesh.positions[idx.z];
    }
    Vec3 point() {
        std::uniform_real_distribution<float> u(0.f, 1.f);
        return lo + Vec3(u(rng), u(rng), u(rng)) * (hi - lo);
    }
    Vec3 direction() {
        std::uniform_real_distribution<float> u(0.f, 1.f);
        return squareToUniformSphere(Vec2(u(rng), u(rng)));
    }
};

RandomRays raysIn(const Scene& scene) {
    RandomRays r;
    r.scene = &scene;
    r.lo = scene.boundsMin(), r.hi = scene.boundsMax();
    return r;
}

// body(scene, gen, n) for each test scene and each stream length (the batches are 64 long).
template <class Body>
void forEachSceneAndLength(Body body) {
    for (const char* name : {"scenes/gltf-features.gltf", "scenes/cornell-box.gltf", "scenes/mis-zoo.gltf"}) {
        INFO(name);
        const Scene scene = test::loadTestScene(name, 16, 16);
        RandomRays gen = raysIn(scene);
        for (uint32_t n : {0u, 1u, 63u, 64u, 65u, 200u}) body(scene, gen, n);
    }
}

}  // namespace

TEST_CASE("Stream tracing: intersectStream finds the hits of intersect, ray by ray, bit for bit", "[wavefront][stream]") {
    forEachSceneAndLength([](const Scene& scene, RandomRays& gen, uint32_t n) {
        std::vector<Ray> rays(n);
        for (uint32_t i = 0; i < n; ++i) {
            const Vec3 o = gen.point();
            rays[i] = Ray{o, i % 2 ? gen.direction() : glm::normalize(gen.surfacePoint() - o), kInfinity};
        }
        std::vector<const Ray*> rayPtrs;
        std::vector<SurfaceHit> streamed(n);
        std::vector<SurfaceHit*> hitPtrs;
        for (uint32_t i = 0; i < n; ++i) rayPtrs.push_back(&rays[i]), hitPtrs.push_back(&streamed[i]);
        std::unique_ptr<bool[]> found(new bool[n + 1]);
        scene.intersectStream(rayPtrs.data(), n, hitPtrs.data(), found.get());
        int hits = 0, differ = 0;
        for (uint32_t i = 0; i < n; ++i) {
            SurfaceHit single;
            const bool f = scene.intersect(rays[i], &single);
            hits += f;
            differ += f != found[i] || (f && !sameHit(single, streamed[i]));
        }
        CHECK(differ == 0);
        if (n >= 63) CHECK(hits > 0);  // the rays start inside the scene's bounds: most hit something
    });
}

TEST_CASE("Stream tracing: occludedStream answers visible and visibleToInfinity, ray by ray", "[wavefront][stream]") {
    forEachSceneAndLength([](const Scene& scene, RandomRays& gen, uint32_t n) {
        std::vector<Ray> queries(n);
        std::vector<bool> single(n);
        for (uint32_t i = 0; i < n; ++i) {
            const Vec3 p0 = gen.point(), n0 = i % 3 == 0 ? Vec3(0.f) : gen.direction();
            if (i % 4 == 1) {  // towards infinity
                const Vec3 d = gen.direction();
                queries[i] = Scene::infinityRay(p0, n0, d);
                single[i] = scene.visibleToInfinity(p0, n0, d);
            } else {
                // Every other segment ends beyond a surface point, so it crosses that surface.
                const Vec3 p1 = i % 2 ? gen.point() : p0 + 2.f * (gen.surfacePoint() - p0);
                const Vec3 n1 = i % 2 ? Vec3(0.f) : gen.direction();
                queries[i] = Scene::segmentRay(p0, n0, p1, n1);
                single[i] = scene.visible(p0, n0, p1, n1);
            }
        }
        std::unique_ptr<bool[]> occluded(new bool[n + 1]);
        scene.occludedStream(queries.data(), n, occluded.get());
        int blocked = 0, differ = 0;
        for (uint32_t i = 0; i < n; ++i) {
            blocked += occluded[i];
            differ += occluded[i] == single[i];  // occluded must be !visible
        }
        CHECK(differ == 0);
        if (n >= 63) CHECK(blocked > 0);
        if (n >= 63) CHECK(blocked < int(n));
    });
}
