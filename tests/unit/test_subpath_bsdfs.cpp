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

TEST_CASE("Scene::bsdfAt: a material's BSDF built once by finalize gives the bits of one built at the point", "[bsdf]") {
    // Untextured materials without vertex colours or a coat take the copy (Scene::bsdfAt); the
    // others are built at the point. Both must answer f, pdf and sample exactly as a Bsdf built
    // from materialParams there.
    long uniform = 0, compared = 0, differ = 0;
    for (const char* name : {"scenes/cornell-box.gltf", "scenes/mis-zoo.gltf", "scenes/caustic-glass.gltf",
                             "scenes/gltf-features.gltf", "scenes/absorbing-glass.gltf"}) {
        INFO(name);
        const Scene scene = test::loadTestScene(name, 16, 16);
        const size_t nTri = scene.mesh.triangleCount();
        for (size_t tri = 0; tri < nTri; tri += std::max<size_t>(1, nTri / 300)) {
            const glm::uvec3 idx = scene.mesh.indices[tri];
            const Vec3 p0 = scene.mesh.positions[idx.x];
            const Vec3 ng = glm::normalize(glm::cross(scene.mesh.positions[idx.y] - p0, scene.mesh.positions[idx.z] - p0));
            if (!isFinite(Rgb(ng.x, ng.y, ng.z))) continue;
            const Vec3 ns = glm::normalize(ng + Vec3(0.1f, -0.05f, 0.07f));
            const uint32_t m = scene.mesh.triangleMaterial[tri];
            const Vec2 bary(0.3f, 0.25f);
            const Bsdf fast = scene.bsdfAt(m, uint32_t(tri), bary, ns, ng);
            const Bsdf slow(scene.materialParams(m, uint32_t(tri), bary), ns, ng);
            uniform += !scene.materials[m].baseColorTexture.valid() && scene.materials[m].clearcoat == 0.f;
            const Vec3 dirs[] = {glm::normalize(ng + Vec3(0.3f, 0.2f, 0.f)), glm::normalize(ng - Vec3(0.f, 0.4f, 0.3f)),
                                 glm::normalize(-ng + Vec3(0.2f, 0.f, 0.1f)), ns};
            for (const Vec3& wo : dirs)
                for (const Vec3& wi : dirs) {
                    ++compared;
                    for (TransportMode mode : {TransportMode::Radiance, TransportMode::Importance})
                        differ += !sameBits(fast.f(wo, wi, mode), slow.f(wo, wi, mode));
                    differ += !sameBits(fast.pdf(wo, wi), slow.pdf(wo, wi));
                    BsdfSample a, b;
                    const bool sa = fast.sample(wo, 0.37f, Vec2(0.61f, 0.13f), TransportMode::Radiance, &a);
                    const bool sb = slow.sample(wo, 0.37f, Vec2(0.61f, 0.13f), TransportMode::Radiance, &b);
                    differ += sa != sb || !sameBits(a.wi, b.wi) || !sameBits(a.f, b.f) || !sameBits(a.pdf, b.pdf) ||
                              a.delta != b.delta;
                }
        }
    }
    INFO(compared << " direction pairs, " << uniform << " triangles of untextured materials");
    CHECK(differ == 0);
    CHECK(uniform > 20);
    CHECK(compared > 1000);
}
