// Normal maps through every estimator (docs/materials.md, "Normal maps"): on a small scene with a
// normal-mapped Lambert floor and a normal-mapped glossy metal wall lit by an area light,
//  * PT, LT, BDPT-balance and BDPT-power agree per pixel (Welch's t-test per pixel, alpha 0.01,
//    binomial bound at 1 - 1e-4: tests/support/image_stats.h), and each comparison detects a
//    uniform 10% error in either image (power check);
//  * the MIS weights of >= 1e4 sampled full paths sum to 1 (1e-9) for the balance, power and
//    uniform heuristics, and the production weight equals the definition (the float32 bound of
//    tests/support/mis_tolerance.h);
//  * the wavefront mode renders the same films as the megakernel, bit for bit.
#include "support/estimators.h"
#include "support/gltf_builder.h"
#include "support/mis_paths.h"
#include "support/render_util.h"

#include "bdptref/gltf_loader.h"

#include <catch2/catch.hpp>

using namespace bdptref;
using namespace bdptref::test;

namespace {

// A quad p0..p3 (counter-clockwise from its front) with flat normals and uv (0,1) (1,1) (1,0)
// (0,0) at its corners, on a root node.
void mappedQuad(Doc& d, const std::array<float, 12>& p, int mat) {
    const Vec3 a(p[0], p[1], p[2]), b(p[3], p[4], p[5]), c(p[6], p[7], p[8]);
    const Vec3 n = glm::normalize(glm::cross(b - a, c - a));
    const int pos = d.floats(std::vector<float>(p.begin(), p.end()), "VEC3");
    const int nrm = d.floats({n.x, n.y, n.z, n.x, n.y, n.z, n.x, n.y, n.z, n.x, n.y, n.z}, "VEC3");
    const int uv = d.floats({0, 1, 1, 1, 1, 0, 0, 0}, "VEC2");
    const int idx = d.indices(std::vector<uint16_t>{0, 1, 2, 0, 2, 3});
    d.node({{"mesh", d.mesh(Doc::prim(pos, idx, nrm, uv, 4, mat))}});
}

// Floor z = 0 (normal-mapped Lambert), back wall y = 1 (normal-mapped GGX metal, roughness 0.4),
// a 0.6 x 0.6 area light at z = 1.6 facing down.
Scene normalMapScene(int size) {
    Doc d;
    // A 4x4 normal map of varied tilts (bilinear): every texel differs. The scales (0.4 floor, 0.3
    // wall: tilts up to ~20 degrees) keep light tracing's variance finite enough for a per-pixel
    // t-test: at scale 1 / 0.8 (tilts up to ~60 degrees) LT's estimates in a few wall pixels were
    // 3-4 standard errors low at 1024 spp and still 1.5-4 at 16384 spp, converging upwards (a
    // heavy tail: the adjoint factor |wo.ns| / |wo.ng| is unbounded for light arriving grazing to
    // ng; docs/materials.md, "Normal maps"), while PT and BDPT agreed (1 rejected pixel of 234).
    std::vector<uint16_t> texels;
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) texels.insert(texels.end(), {uint16_t(40 + 50 * i), uint16_t(220 - 45 * j), uint16_t(200 + 10 * ((i + j) % 4))});
    d.j["images"] = json::array({json{{"uri", "data:image/png;base64," + base64(makePng(4, 4, 3, 8, texels))}}});
    d.j["textures"] = json::array({json{{"source", 0}}});
    const int floor = d.lambert({0.6, 0.6, 0.6});
    d.j["materials"][size_t(floor)]["normalTexture"] = {{"index", 0}, {"scale", 0.4}};
    const int wall = d.metal({0.9, 0.7, 0.5}, 0.4);
    d.j["materials"][size_t(wall)]["normalTexture"] = {{"index", 0}, {"scale", 0.3}};
    const int light = d.lambert({0, 0, 0}, {1, 1, 1}, 8.0);
    mappedQuad(d, {-2, -1, 0, 2, -1, 0, 2, 1, 0, -2, 1, 0}, floor);
    mappedQuad(d, {-2, 1, 0, 2, 1, 0, 2, 1, 1.6f, -2, 1, 1.6f}, wall);
    d.quad({-0.3, -0.3, 1.6}, {-0.3, 0.3, 1.6}, {0.3, 0.3, 1.6}, {0.3, -0.3, 1.6}, light);
    // Rotated 60 degrees about x: looking along (0, sin 60, -cos 60), i.e. 30 degrees down, at
    // (0, 0.2, 0.4) from 2.6 away; every pixel sees the floor or the wall, none the light.
    d.j["cameras"] = json::array({json{{"type", "perspective"}, {"perspective", {{"yfov", 0.75}, {"znear", 0.01}}}}});
    d.node({{"camera", 0}, {"translation", {0, -2.0517, 1.7}}, {"rotation", {0.5, 0, 0, 0.8660254037844386}}});
    LoadOptions o;
    o.width = o.height = size;
    Scene s = loadGltfScene(d.write("normal-map-scene.gltf"), o);
    s.finalize();
    return s;
}

// The normal maps must matter in this scene: the share of visible surface hits whose shading
// normal differs from the interpolated (here: geometric) one.
double perturbedFraction(const Scene& scene) {
    int hits = 0, perturbed = 0;
    for (int y = 0; y < scene.camera.height(); ++y)
        for (int x = 0; x < scene.camera.width(); ++x) {
            const Ray ray = scene.camera.generateRay(Vec2(float(x) + 0.5f, float(y) + 0.5f));
            SurfaceHit h;
            if (!scene.intersect(ray, &h)) continue;
            ++hits;
            perturbed += glm::dot(h.ns, h.ng) < 0.999f;
        }
    return hits ? double(perturbed) / hits : 0.0;
}

}  // namespace

TEST_CASE("Normal maps: PT LT BDPT-balance and BDPT-power agree per pixel", "[normalmap][agreement]") {
    const Scene scene = normalMapScene(16);
    CHECK(perturbedFraction(scene) > 0.9);
    // Seeds 100..103: independent estimates per pixel.
    checkPairwiseAgreement(momentsOfEach(renderEveryEstimator(scene, {1024, 1024, 512, 512}, 100, 1)), 0.10);
}

TEST_CASE("Normal maps: MIS weights of sampled paths sum to 1 and equal the definition", "[normalmap][mis]") {
    const Scene scene = normalMapScene(16);
    long perturbedPaths = 0;
    const MisPathCheck r = checkSampledPathWeights(scene, 6000, 4242u, 5, [&](const std::vector<PathVertex>& x, int) {
        bool perturbed = false;
        for (const PathVertex& v : x) perturbed = perturbed || (v.isOnSurface() && glm::dot(v.ns, v.ng) < 0.999f);
        perturbedPaths += perturbed;
    });
    INFO(r.summary() << "; through a perturbed normal: " << perturbedPaths);
    CHECK(r.paths >= 10000);
    CHECK(perturbedPaths >= 10000);
    CHECK(r.passed());
}

TEST_CASE("Normal maps: wavefront equals megakernel bit for bit", "[normalmap][wavefront]") {
    EstimatorSetup s;
    s.spp = 2;
    s.threads = 2;
    s.seed = 7;
    checkWavefrontIdenticalEveryEstimator(normalMapScene(16), s);
}
