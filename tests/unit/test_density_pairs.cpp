// The MIS densities are evaluated in pairs (Bsdf::pdfBothWays, fillSubpathDensities,
// connectionDensities) and with f (Bsdf::evaluateBothWays, evaluateConnection) for speed; every
// density must keep the bits of its one-at-a-time definition (Bsdf::pdf, vertexPdf), or the MIS
// weights would no longer be those that the `mis` tool and the other two forms compute.
#include "bdptref/bdpt.h"
#include "bdptref/bsdf.h"
#include "bdptref/math.h"
#include "bdptref/scene.h"
#include "render/bdpt_vertex.h"
#include "support/render_util.h"

#include <catch2/catch.hpp>

#include <cstring>
#include <random>
#include <vector>

using namespace bdptref;

namespace {

bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }
bool sameBits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// A random unit direction; one in eight lies (up to rounding) in the geometric plane, where the
// side tests of the BSDF decide.
Vec3 randomDirection(std::mt19937& rng, const Vec3& ng) {
    std::normal_distribution<float> g;
    Vec3 d = glm::normalize(Vec3(g(rng), g(rng), g(rng)));
    if (rng() % 8u == 0u) d = glm::normalize(d - glm::dot(d, ng) * ng);
    return d;
}

}  // namespace

TEST_CASE("Bsdf::pdfBothWays, Bsdf::evaluate and Bsdf::evaluateBothWays give the bits of separate pdf and f calls", "[bsdf][mis]") {
    const Vec3 ng = glm::normalize(Vec3(0.3f, -0.5f, 0.8f));
    const Vec3 nsTilted = glm::normalize(Frame(ng).toWorld(Vec3(0.35f, 0.15f, 1.f)));
    struct Case {
        const char* name;
        MaterialParams p;
    };
    MaterialParams lambert;
    lambert.baseColor = Rgb(0.7f, 0.5f, 0.3f);
    lambert.specular = 0.f;  // the Lambertian fast path: only the diffuse lobe is active
    MaterialParams glossy;
    glossy.roughness = 0.4f;
    MaterialParams metal = glossy;
    metal.metallic = 1.f;
    MaterialParams sheen = lambert;
    sheen.sheenColor = Rgb(0.5f);
    sheen.sheenRoughness = 0.3f;
    MaterialParams coat = lambert;
    coat.clearcoat = 1.f;
    coat.clearcoatRoughness = 0.3f;
    MaterialParams roughGlass;
    roughGlass.transmission = 1.f;
    roughGlass.roughness = 0.5f;
    const Case cases[] = {{"lambert", lambert}, {"glossy", glossy}, {"metal", metal},
                          {"sheen over lambert", sheen}, {"coat over lambert", coat}, {"rough glass", roughGlass}};
    std::mt19937 rng(20261125u);
    for (const Case& c : cases)
        for (const Vec3& ns : {ng, nsTilted}) {
            INFO(c.name << (ns == ng ? "" : ", tilted shading normal"));
            const Bsdf bsdf(c.p, ns, ng);
            int mismatches = 0, nonZeroPairs = 0;
            for (int k = 0; k < 20000; ++k) {
                const Vec3 wa = randomDirection(rng, ng), wb = randomDirection(rng, ng);
                float ab = -1.f, ba = -1.f;
                bsdf.pdfBothWays(wa, wb, &ab, &ba);
                mismatches += !sameBits(ab, bsdf.pdf(wa, wb)) || !sameBits(ba, bsdf.pdf(wb, wa));
                nonZeroPairs += ab > 0.f && ba > 0.f;
                // Bsdf::evaluate: f and pdf of one pair in one evaluation, in both transport modes.
                for (TransportMode mode : {TransportMode::Radiance, TransportMode::Importance}) {
                    float pdf = -1.f;
                    const Rgb f = bsdf.evaluate(wa, wb, mode, &pdf);
                    const Rgb fRef = bsdf.f(wa, wb, mode);
                    mismatches += !sameBits(pdf, bsdf.pdf(wa, wb)) || !sameBits(f.r, fRef.r) || !sameBits(f.g, fRef.g) ||
                                  !sameBits(f.b, fRef.b);
                    // Bsdf::evaluateBothWays: f and both densities of a connection endpoint.
                    float pab = -1.f, pba = -1.f;
                    const Rgb fBoth = bsdf.evaluateBothWays(wa, wb, mode, &pab, &pba);
                    mismatches += !sameBits(pab, bsdf.pdf(wa, wb)) || !sameBits(pba, bsdf.pdf(wb, wa)) ||
                                  !sameBits(fBoth.r, fRef.r) || !sameBits(fBoth.g, fRef.g) || !sameBits(fBoth.b, fRef.b);
                }
            }
            CHECK(mismatches == 0);
            CHECK(nonZeroPairs > 2000);  // valid reflection pairs were compared, not only zeros
        }
}

TEST_CASE("Subpath and connection densities keep the bits of their vertexPdf definitions", "[bdpt][mis]") {
    struct Case {
        const char* scene;
        Rgb env;
    };
    const Case cases[] = {{"scenes/cornell-box.gltf", Rgb(0.f)}, {"scenes/mis-zoo.gltf", Rgb(0.f)},
                          {"scenes/gltf-features.gltf", Rgb(0.f)}, {"scenes/veach-mis.gltf", Rgb(0.f)}};
    for (const Case& c : cases) {
        INFO(c.scene);
        const Scene scene = test::loadTestScene(c.scene, 16, 16, c.env);
        BdptSettings settings;
        settings.maxDepth = 6;
        const size_t nCam = size_t(settings.maxCameraVertices()), nLight = size_t(settings.maxLightVertices());
        std::vector<PathVertex> cam(nCam), light(nLight);
        std::vector<Bsdf> camBsdf(nCam), lightBsdf(nLight);
        int mismatches = 0, innerDensities = 0, connections = 0;
        // pdfFwd of vertex i + 1 and pdfRev of vertex i - 1 as vertexPdf defines them.
        auto checkSubpath = [&](const std::vector<PathVertex>& path, int n) {
            for (int i = 1; i < n; ++i) {
                const PathVertex& from = path[size_t(i - 1)];
                const double fwd = from.delta ? 0.0 : vertexPdf(scene, from, i >= 2 ? &path[size_t(i - 2)] : nullptr, path[size_t(i)]);
                mismatches += !sameBits(path[size_t(i)].pdfFwd, fwd);
            }
            for (int i = 0; i + 2 < n; ++i) {
                const PathVertex& from = path[size_t(i + 1)];
                const double rev = from.delta ? 0.0 : vertexPdf(scene, from, &path[size_t(i + 2)], path[size_t(i)]);
                mismatches += !sameBits(path[size_t(i)].pdfRev, rev);
                innerDensities += rev > 0.0;
            }
        };
        for (uint32_t k = 0; k < 300; ++k) {
            const PixelSampler sampler(11u, k % 256u, k);
            const Vec2 raster = Vec2(float(k % 16u), float((k / 16u) % 16u)) + sampler.get2D(RngStream::Camera, dim::kFilm);
            const int nc = generateCameraSubpath(scene, sampler, raster, settings, cam.data(), camBsdf.data());
            const int nl = generateLightSubpath(scene, sampler, settings, light.data(), lightBsdf.data());
            checkSubpath(cam, nc);
            checkSubpath(light, nl);
            const SubpathBsdfs bsdfs{lightBsdf.data(), camBsdf.data()};
            // Connections between two stored surface vertices: all four densities.
            for (int t = 2; t <= nc; ++t)
                for (int s = 2; s <= nl; ++s) {
                    const PathVertex& pt = cam[size_t(t - 1)];
                    const PathVertex& qs = light[size_t(s - 1)];
                    if (pt.type != VertexType::Surface || qs.type != VertexType::Surface) continue;
                    const ConnectionDensities d = connectionDensities(scene, light.data(), s, cam.data(), t, PathVertex{}, settings.mis, bsdfs);
                    const PathVertex& ptPrev = cam[size_t(t - 2)];
                    const PathVertex& qsPrev = light[size_t(s - 2)];
                    mismatches += !sameBits(d.qsRev, vertexPdf(scene, pt, &ptPrev, qs));
                    mismatches += !sameBits(d.ptRev, vertexPdf(scene, qs, &qsPrev, pt));
                    mismatches += !sameBits(d.ptPrevRev, double(vertexBsdf(scene, pt).pdf(directionTo(pt, qs), directionTo(pt, ptPrev))));
                    mismatches += !sameBits(d.qsPrevRev, double(vertexBsdf(scene, qs).pdf(directionTo(qs, pt), directionTo(qs, qsPrev))));
                    connections += d.qsRev > 0.0 && d.ptRev > 0.0;
                }
        }
        CHECK(mismatches == 0);
        CHECK(innerDensities > 50);
        CHECK(connections > 50);
    }
}

TEST_CASE("The densities evaluateConnection finds with f are connectionDensities' bits, for every strategy", "[bdpt][mis]") {
    for (const char* path : {"scenes/cornell-box.gltf", "scenes/mis-zoo.gltf", "scenes/gltf-features.gltf"}) {
        INFO(path);
        const Scene scene = test::loadTestScene(path, 16, 16);
        BdptSettings settings;
        settings.maxDepth = 6;
        const size_t nCam = size_t(settings.maxCameraVertices()), nLight = size_t(settings.maxLightVertices());
        std::vector<PathVertex> cam(nCam), light(nLight);
        std::vector<Bsdf> camBsdf(nCam), lightBsdf(nLight);
        int mismatches = 0, bothSurfaceEnds = 0, nextEvents = 0, splats = 0;
        for (uint32_t k = 0; k < 300; ++k) {
            const PixelSampler sampler(12u, k % 256u, k);
            const Vec2 raster = Vec2(float(k % 16u), float((k / 16u) % 16u)) + sampler.get2D(RngStream::Camera, dim::kFilm);
            const int nc = generateCameraSubpath(scene, sampler, raster, settings, cam.data(), camBsdf.data());
            const int nl = generateLightSubpath(scene, sampler, settings, light.data(), lightBsdf.data());
            const SubpathBsdfs bsdfs{lightBsdf.data(), camBsdf.data()};
            for (int t = 1; t <= nc; ++t)
                for (int s = 0; s <= lastLightStrategy(nl, t); ++s) {
                    if (strategyStatus(s, t, settings.maxDepth, false) != StrategyStatus::Evaluated) continue;
                    PendingConnection p;
                    if (!evaluateConnection(scene, light.data(), s, cam.data(), t, sampler, &p, settings.mis.lightSampler, bsdfs))
                        continue;
                    const ConnectionDensities carried =
                        connectionDensities(scene, light.data(), s, cam.data(), t, p.sampled, settings.mis, p.cameraEnd, p.lightEnd);
                    const ConnectionDensities fresh = connectionDensities(scene, light.data(), s, cam.data(), t, p.sampled, settings.mis, bsdfs);
                    mismatches += !sameBits(carried.ptRev, fresh.ptRev) || !sameBits(carried.ptPrevRev, fresh.ptPrevRev) ||
                                  !sameBits(carried.qsRev, fresh.qsRev) || !sameBits(carried.qsPrevRev, fresh.qsPrevRev) ||
                                  !sameBits(carried.ptRevNextEvent, fresh.ptRevNextEvent);
                    bothSurfaceEnds += s >= 2 && t >= 2 && fresh.qsRev > 0.0 && fresh.ptRev > 0.0;
                    nextEvents += s == 1 && t >= 2 && fresh.qsRev > 0.0;
                    splats += t == 1 && s >= 2 && fresh.ptRev > 0.0;
                }
        }
        CHECK(mismatches == 0);
        CHECK(bothSurfaceEnds > 50);  // each kind of surface endpoint was compared with non-zero densities
        CHECK(nextEvents > 50);
        CHECK(splats > 20);
    }
}
