// The BSDF side arrays (SubpathBsdfs, bdpt.h) are a cache: subpaths, densities, connections and
// MIS weights computed with them must be bit-identical to those computed without them (each
// function then builds the BSDFs it needs). Scenes with glossy, delta and diffuse materials, and
// with area and point lights and an environment.
#include "bdptref/bdpt.h"
#include "bdptref/scene.h"
#include "support/render_util.h"

#include <catch2/catch.hpp>

#include <cstring>
#include <vector>

using namespace bdptref;

namespace {

template <class T>
bool sameBits(const T& a, const T& b) {
    return std::memcmp(&a, &b, sizeof(T)) == 0;
}
// Member by member: PathVertex has padding bytes, whose contents C++ leaves unspecified (a whole-
// struct memcmp passed in Release and failed in the -O1 sanitizer build).
bool sameBits(const PathVertex& a, const PathVertex& b) {
    return sameBits(a.p, b.p) && sameBits(a.ng, b.ng) && sameBits(a.ns, b.ns) && sameBits(a.wo, b.wo) &&
           sameBits(a.bary, b.bary) && sameBits(a.beta, b.beta) && sameBits(a.pdfFwd, b.pdfFwd) &&
           sameBits(a.pdfRev, b.pdfRev) && a.light == b.light && a.material == b.material && a.triangle == b.triangle &&
           a.type == b.type && a.delta == b.delta && a.infinite == b.infinite;
}

}  // namespace

TEST_CASE("BSDF side arrays give the same subpaths and connections and MIS weights bit for bit", "[bdpt][mis]") {
    struct Case {
        const char* scene;
        Rgb env;
    };
    const Case cases[] = {{"scenes/mis-zoo.gltf", Rgb(0.f)}, {"scenes/caustic-glass.gltf", Rgb(0.f)},
                          {"scenes/sphere-point-light.gltf", Rgb(0.f)}, {"scenes/env-sphere.glb", Rgb(0.5f)}};
    for (const Case& c : cases) {
        INFO(c.scene);
        const Scene scene = test::loadTestScene(c.scene, 16, 16, c.env);
        BdptSettings settings;
        settings.maxDepth = 6;
        settings.mis.heuristic = MisHeuristic::Power;
        const size_t nCam = size_t(settings.maxCameraVertices()), nLight = size_t(settings.maxLightVertices());
        std::vector<PathVertex> cam(nCam), light(nLight), camRef(nCam), lightRef(nLight);
        std::vector<Bsdf> camBsdf(nCam), lightBsdf(nLight);
        int connections = 0, mismatches = 0;
        for (uint32_t k = 0; k < 300; ++k) {
            const PixelSampler sampler(7u, k % 256u, k);
            const Vec2 raster = Vec2(float(k % 16u), float((k / 16u) % 16u)) + sampler.get2D(RngStream::Camera, dim::kFilm);
            const int nc = generateCameraSubpath(scene, sampler, raster, settings, cam.data(), camBsdf.data());
            const int nl = generateLightSubpath(scene, sampler, settings, light.data(), lightBsdf.data());
            REQUIRE(generateCameraSubpath(scene, sampler, raster, settings, camRef.data()) == nc);
            REQUIRE(generateLightSubpath(scene, sampler, settings, lightRef.data()) == nl);
            for (int i = 0; i < nc; ++i) mismatches += !sameBits(cam[size_t(i)], camRef[size_t(i)]);
            for (int i = 0; i < nl; ++i) mismatches += !sameBits(light[size_t(i)], lightRef[size_t(i)]);
            const SubpathBsdfs bsdfs{lightBsdf.data(), camBsdf.data()};
            for (int t = 1; t <= nc; ++t)
                for (int s = 0; s <= nl; ++s) {
                    if (s + t < 3 && !(s == 0 && t == 2)) continue;
                    Connection a, b;
                    PathVertex sa, sb;
                    const bool okA = connectStrategy(scene, light.data(), s, cam.data(), t, sampler, settings, &a, &sa, bsdfs);
                    const bool okB = connectStrategy(scene, light.data(), s, cam.data(), t, sampler, settings, &b, &sb);
                    if (okA != okB) {
                        ++mismatches;
                        continue;
                    }
                    if (!okA) continue;
                    ++connections;
                    mismatches += !sameBits(a.unweighted, b.unweighted) || a.weight != b.weight || !sameBits(sa, sb);
                    const double w = misWeight(scene, light.data(), s, cam.data(), t, sa, settings.mis, bsdfs);
                    mismatches += w != misWeight(scene, light.data(), s, cam.data(), t, sa, settings.mis);
                }
        }
        CHECK(mismatches == 0);
        CHECK(connections > 100);  // the comparison saw real contributions
    }
}
