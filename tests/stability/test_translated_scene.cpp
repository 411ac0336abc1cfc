// The hard case "scene translated by 1e5" (docs/hard-cases.md), asserted exactly instead of
// statistically. The touching room and its camera moved by exactly (1e5, 1e5, 1e5) (every
// coordinate is a multiple of 1/64, the float spacing at 1e5 is 1/128) is, after
// Scene::finalize() moved it into camera-centred render space (docs/self-intersection.md), the
// SAME render-space scene as the room at the origin: same float positions, same camera. So every
// estimator must render bit-identical films from it with the same seed - a much stronger check
// than a statistical comparison, which would miss a bias smaller than the noise.
//
// Before render space existed, this case rendered LT and BDPT 5-10x too bright on the floor: the
// ray offset 2^-16 max|p| is ~1.5 units at 1e5 (most of the room).
#include "stability/hard_case_scenes.h"
#include "support/test_budget.h"

#include "bdptref/integrator.h"
#include "bdptref/renderer.h"
#include "bdptref/wavefront.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cstring>

using namespace bdptref;
using namespace bdptref::test;

namespace {

constexpr int kSize = 16;
constexpr int kMaxDepth = 6;

const HardCase& translatedCase() {
    static const std::vector<HardCase> all = hardCases();
    const auto it = std::find_if(all.begin(), all.end(), [](const HardCase& c) { return c.name == "scene translated by 1e5"; });
    REQUIRE(it != all.end());
    REQUIRE(it->referenceBuild);
    return *it;
}

// Bitwise equality (== would accept -0 for +0 and reject equal NaNs).
template <class T>
bool sameBits(const T& a, const T& b) {
    return std::memcmp(&a, &b, sizeof(T)) == 0;
}
template <class T>
int differingElements(const std::vector<T>& a, const std::vector<T>& b) {
    if (a.size() != b.size()) return -1;
    int n = 0;
    for (size_t i = 0; i < a.size(); ++i) n += !sameBits(a[i], b[i]);
    return n;
}

Film render(const Scene& scene, const std::string& integrator, MisHeuristic heuristic, bool wavefront) {
    IntegratorSettings is;
    is.maxDepth = kMaxDepth;
    is.mis.heuristic = heuristic;
    is.recordStrategies = integrator != "path";
    const auto integ = makeIntegrator(integrator, is);
    std::unique_ptr<WavefrontScheduler> scheduler;
    RenderOptions ro;
    ro.spp = scaledSamples(32);
    ro.seed = 4242;
    ro.tileSize = 8;
    if (wavefront) {
        scheduler = std::make_unique<WavefrontScheduler>(integrator, is, WavefrontOptions{});
        ro.scheduler = scheduler.get();
    }
    Film film(scene.camera.width(), scene.camera.height());
    if (is.recordStrategies) film.enableStrategies(kMaxDepth);
    renderImage(scene, *integ, ro, film);
    return film;
}

}  // namespace

TEST_CASE("Translated by 1e5: render space is the same scene as at the origin", "[stability]") {
    const HardCase& hc = translatedCase();
    const Scene far = hc.build(kSize, kSize), near = hc.referenceBuild(kSize, kSize);
    // worldOrigin is each camera's world position; they differ by exactly the translation.
    CHECK(far.worldOrigin - near.worldOrigin == DVec3(1e5));
    CHECK(far.camera.position() == Vec3(0.f));
    CHECK(near.camera.position() == Vec3(0.f));
    CHECK(sameBits(far.camera.forward(), near.camera.forward()));
    CHECK(sameBits(far.camera.up(), near.camera.up()));
    CHECK(differingElements(far.mesh.positions, near.mesh.positions) == 0);
    REQUIRE(far.lights.size() == near.lights.size());
    for (size_t i = 0; i < far.lights.size(); ++i) {
        const Light &f = far.lights[i], &n = near.lights[i];  // field by field: Light has padding
        CHECK(f.type == n.type);
        for (auto member : {&Light::position, &Light::direction, &Light::v0, &Light::v1, &Light::v2, &Light::normal, &Light::sceneCenter})
            CHECK(sameBits(f.*member, n.*member));
        for (auto member : {&Light::area, &Light::sceneRadius, &Light::power}) CHECK(sameBits(f.*member, n.*member));
        CHECK(sameBits(f.emission, n.emission));
    }
    CHECK(sameBits(far.boundsMin(), near.boundsMin()));
    CHECK(sameBits(far.boundsMax(), near.boundsMax()));
    // World coordinates come back exactly: a point of the ceiling light, 1/64 below the ceiling.
    CHECK(far.toWorld(far.lights[0].v0).y == 1e5 + 1 - 1.0 / 64);
    CHECK(near.toWorld(near.lights[0].v0).y == 1 - 1.0 / 64);
}

TEST_CASE("Translated by 1e5: every estimator renders bit-identical films", "[stability][wavefront]") {
    const HardCase& hc = translatedCase();
    const Scene far = hc.build(kSize, kSize), near = hc.referenceBuild(kSize, kSize);
    struct Mode {
        const char* name;
        const char* integrator;
        MisHeuristic heuristic;
        bool wavefront;
    };
    const Mode modes[] = {{"path", "path", MisHeuristic::Balance, false},
                          {"lt", "lt", MisHeuristic::Balance, false},
                          {"bdpt-balance", "bdpt", MisHeuristic::Balance, false},
                          {"bdpt-power", "bdpt", MisHeuristic::Power, false},
                          {"wavefront bdpt-balance", "bdpt", MisHeuristic::Balance, true}};
    for (const Mode& m : modes) {
        INFO("estimator " << m.name);
        Film a = render(far, m.integrator, m.heuristic, m.wavefront);
        Film b = render(near, m.integrator, m.heuristic, m.wavefront);
        const Film::Accumulators fa = a.accumulators(), fb = b.accumulators();
        CHECK(differingElements(fa.sum, fb.sum) == 0);
        CHECK(differingElements(fa.sumSquares, fb.sumSquares) == 0);
        CHECK(differingElements(fa.count, fb.count) == 0);
        CHECK(differingElements(fa.lightSum, fb.lightSum) == 0);
        CHECK(fa.nonFinite == 0);
        CHECK(fb.nonFinite == 0);
        for (bool w : {true, false}) {
            CHECK(differingElements(a.strategies().sums(w), b.strategies().sums(w)) == 0);
            CHECK(differingElements(a.strategies().sumSquares(w), b.strategies().sumSquares(w)) == 0);
        }
        // Not vacuous: the image is lit in most pixels (the light is in the room, the floor in view).
        int lit = 0;
        for (int y = 0; y < kSize; ++y)
            for (int x = 0; x < kSize; ++x) lit += a.sum(x, y).x > 0.0;
        CHECK(lit * 2 > kSize * kSize);
    }
}
