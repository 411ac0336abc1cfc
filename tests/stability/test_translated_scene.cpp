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
#include "support/render_util.h"

#include "bdptref/errors.h"
#include "bdptref/integrator.h"
#include "bdptref/path_io.h"
#include "bdptref/renderer.h"
#include "bdptref/wavefront.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cstring>
#include <fstream>

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
    is.recordStrategies = true;
    const auto integ = makeIntegrator(integrator, is);
    std::unique_ptr<WavefrontScheduler> scheduler;
    RenderOptions ro;
    ro.spp = 32;
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
        for (auto member : {&Light::area, &Light::sceneRadius}) CHECK(sameBits(f.*member, n.*member));
        CHECK(sameBits(f.power, n.power));  // double
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

// What users see stays in world coordinates: `trace` writes world positions (double), `mis` reads
// them back into render space bit for bit, `info` prints world bounds and the render origin.
TEST_CASE("Translated by 1e5: trace, mis and info speak world coordinates", "[stability][trace][cli]") {
    const HardCase& hc = translatedCase();
    const std::string file = hc.build(kSize, kSize).info.path;  // the glTF the hard case wrote
    const std::string dir = makeTempDir("translated");
    // The hard case's camera (eye (0, -0.25, 3.5) + 1e5, target (0, -0.375, 0) + 1e5): exact floats.
    const std::string view = " --width 16 --height 16 --camera-pos 100000,99999.75,100003.5 --camera-target 100000,99999.625,100000 --fov 30";
    std::string out;
    REQUIRE(runCli("trace " + file + view + " --pixel 8,13 --sample 3 --seed 5 --max-depth 4 -o " + dir + "/t.json", &out) == 0);
    std::ifstream in(dir + "/t.json");
    const nlohmann::ordered_json j = nlohmann::ordered_json::parse(in);
    const nlohmann::ordered_json origin = nlohmann::ordered_json::array({100000.0, 99999.75, 100003.5});
    CHECK(j["settings"]["worldOrigin"] == origin);
    CHECK(j["cameraSubpath"][0]["p"] == origin);
    // Surface vertices lie in the room [1e5 - 1, 1e5 + 1]^3 (render coordinates would be near 0).
    int surfaces = 0;
    for (const char* sub : {"cameraSubpath", "lightSubpath"})
        for (const auto& v : j[sub]) {
            if (v["type"] != "surface" && !(v["type"] == "light" && v.value("lightType", "") == "area")) continue;
            ++surfaces;
            for (int c = 0; c < 3; ++c) {
                const double x = v["p"][size_t(c)].get<double>();
                CHECK(x >= 1e5 - 1.0);
                CHECK(x <= 1e5 + 1.0);
            }
        }
    CHECK(surfaces >= 3);
    // `mis` on every contributing connection: the scene form read back from world coordinates
    // gives the trace's definition weights bit for bit.
    int checked = 0;
    for (const auto& c : j["connections"]) {
        if (c["status"] != "contributed" || checked >= 3) continue;
        const std::string st = std::to_string(c["s"].get<int>()) + "," + std::to_string(c["t"].get<int>());
        REQUIRE(runCli("mis " + dir + "/t.json --strategy " + st + " --json > " + dir + "/w.json", &out) == 0);
        std::ifstream win(dir + "/w.json");
        const nlohmann::ordered_json w = nlohmann::ordered_json::parse(win);
        CHECK(w["form"] == "scene");
        REQUIRE(w["strategies"].size() == c["definitionWeights"].size());
        for (size_t k = 0; k < w["strategies"].size(); ++k)
            CHECK(w["strategies"][k]["weight"].get<double>() == c["definitionWeights"][k].get<double>());
        ++checked;
    }
    CHECK(checked >= 2);
    REQUIRE(runCli("info " + file + view, &out) == 0);
    CHECK(out.find("bounds:       (99999, 99999, 99999) - (100001, 100001, 100001)") != std::string::npos);
    CHECK(out.find("at (100000, 99999.75, 100003.5)") != std::string::npos);
    CHECK(out.find("render space: world minus (100000, 99999.75, 100003.5)") != std::string::npos);
}

// Render space subtracts the camera position: a float minus a float can exceed float's range,
// which must be an input error, never a silent infinity (or undefined behaviour).
TEST_CASE("Render space: a vertex out of float range relative to the camera is an input error", "[stability][errors]") {
    const float big = 3e38f;
    auto triangleAt = [&](const Vec3& eye, const Vec3& target) {
        Scene s;
        s.materials.push_back(Material{});
        for (const Vec3& p : {Vec3(big, 0, 0), Vec3(big, 1, 0), Vec3(big, 0, 1)}) {
            s.mesh.positions.push_back(p);
            s.mesh.normals.push_back(Vec3(1, 0, 0));
            s.mesh.vertexHasNormal.push_back(0);
        }
        s.mesh.indices.push_back(glm::uvec3(0, 1, 2));
        s.mesh.triangleMaterial.push_back(0);
        s.camera = Camera::lookAt(eye, target, Vec3(0, 1, 0), 1.f, 4, 4);
        return s;
    };
    Scene far = triangleAt(Vec3(-big, 0, 0), Vec3(0, 0, 0));
    CHECK_THROWS_WITH(far.finalize(), Catch::Contains("out of float range relative to the camera"));
    // The same triangle seen from near it is fine, and comes back in world coordinates.
    Scene near = triangleAt(Vec3(big, 0, -1), Vec3(big, 0, 0));
    near.finalize();
    CHECK(near.toWorld(near.mesh.positions[1]) == DVec3(double(big), 1.0, 0.0));
    CHECK_THROWS_AS(near.toRender(DVec3(-3e38, 0, 0)), InputError);
}
