// alphaMode MASK and BLEND (docs/materials.md, "Alpha"; docs/rng.md, "Alpha coverage").
//
//  * Known answers under a constant environment L = 1 seen through a plane that fills the view:
//    a black MASK cut-out opaque on c = 3/4 of its area shows exactly 1 - c = 1/4 (every sample
//    is exactly 0 or 1: the cut-out is deterministic); a BLEND plane of coverage a shows
//    (1 - a) L + a rho L (rho L: a Lambert plane's own shading under the full hemisphere).
//    Tolerance: k = 5 standard errors of the image mean, the standard error from the spread of
//    the per-pass image means (passes are independent; pixels within a pass are not, for LT/BDPT).
//  * A box lit by an area light with a MASK and a BLEND quad casting shadows: PT, LT, BDPT balance
//    and BDPT power agree per pixel (Welch + binomial rule, tests/support/image_stats.h, with the
//    power check that a 5% error is detected); MIS definition weights of >= 1e4 sampled paths
//    through the alpha surfaces sum to 1 and the production weights equal them (tolerance of
//    tests/support/mis_tolerance.h); the wavefront renders the same films bit for bit.
//  * A MASK quad that is nowhere covered renders bit-identically to no quad at all (PT, LT, BDPT):
//    every ray kind passes through it exactly as through empty space.
#include "support/estimators.h"
#include "support/gltf_builder.h"
#include "support/image_stats.h"
#include "support/mis_paths.h"
#include "support/render_util.h"

#include "bdptref/bdpt.h"
#include "bdptref/errors.h"
#include "bdptref/exr_io.h"
#include "bdptref/gltf_loader.h"
#include "bdptref/integrator.h"
#include "bdptref/renderer.h"
#include "bdptref/wavefront.h"
#include "scene/alpha.h"

#include <catch2/catch.hpp>

#include <functional>
#include <memory>
#include <string>
#include <vector>

using namespace bdptref;
using namespace bdptref::test;

namespace {

constexpr double kSigmas = 5.0;

// Image mean (luminance-free: channel 0, the scenes below are grey) and its standard error from
// the per-pass image means.
struct Pooled {
    double mean = 0, standardError = 0;
    bool everySampleZeroOrOne = true;
};
Pooled passPooled(const Scene& scene, const EstimatorSetup& s) {
    double previous = 0, sum = 0, sumSq = 0;
    int n = 0;
    const Film film = renderEstimator(scene, s, [&](const Film& f, int) {
        double total = 0;
        for (int y = 0; y < f.height(); ++y)
            for (int x = 0; x < f.width(); ++x) total += f.sum(x, y).x;
        const double v = (total - previous) / double(f.pixelCount());
        previous = total;
        sum += v;
        sumSq += v * v;
        ++n;
    });
    CHECK(film.nonFiniteSamples() == 0);
    Pooled p;
    p.mean = sum / n;
    p.standardError = std::sqrt(std::max(0.0, (sumSq - n * p.mean * p.mean) / (n - 1)) / n);
    // With L = 1 and a black cut-out each camera sample is 0 or 1, so sum x^2 == sum x per pixel.
    for (int y = 0; y < film.height(); ++y)
        for (int x = 0; x < film.width(); ++x) p.everySampleZeroOrOne = p.everySampleZeroOrOne && film.sum(x, y) == film.sumSquares(x, y);
    return p;
}

// Adds alphaMode (and cutoff) and the coverage factor / texture to material `mat` of `d`.
void makeAlpha(Doc& d, int mat, const char* mode, double factor, int texture = -1, double cutoff = -1) {
    json& m = d.j["materials"][size_t(mat)];
    m["alphaMode"] = mode;
    m["pbrMetallicRoughness"]["baseColorFactor"][3] = factor;
    if (texture >= 0) m["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", texture}};
    if (cutoff >= 0) m["alphaCutoff"] = cutoff;
}

Scene loadWithCamera(const Doc& d, const std::string& name, const Camera& camera, const Rgb& env = Rgb(0.f)) {
    LoadOptions o;
    o.width = camera.width();
    o.height = camera.height();
    Scene s = loadGltfScene(d.write(name), o);
    s.camera = camera;
    if (!isBlack(env)) s.setEnvironment(env);
    s.finalize();
    return s;
}

// A 4 x 4 plane at z = 0 facing +z, seen from (0, 0, 1) with a 90 degree field of view: the
// 32 x 32 image spans x, y in [-1, 1], 1/16 per pixel. u = 16 x, so one texture period (u in
// [k, k + 1)) is exactly one pixel wide: every pixel sees the same covered fraction.
Scene planeScene(Doc& d, int mat, const std::string& name) {
    uvQuad(d, {{{-2, -2, 0}, {2, -2, 0}, {2, 2, 0}, {-2, 2, 0}}}, {{{-32, 0}, {32, 0}, {32, 1}, {-32, 1}}}, mat);
    return loadWithCamera(d, name, Camera::lookAt(Vec3(0, 0, 1), Vec3(0, 0, 0), Vec3(0, 1, 0), 0.5f * kPi, 32, 32), Rgb(1.f));
}

void checkKnownAnswer(const Scene& scene, double expected, bool exactSamples) {
    for (const char* integrator : {"path", "bdpt"}) {
        EstimatorSetup s;
        s.integrator = integrator;
        s.spp = 32;
        const Pooled p = passPooled(scene, s);
        INFO(integrator << ": image mean " << p.mean << " +- " << p.standardError << ", expected " << expected);
        CHECK(std::abs(p.mean - expected) <= kSigmas * p.standardError);
        CHECK(p.standardError < 0.01);  // not vacuous: 5 sigma < 0.05
        if (exactSamples && std::string(integrator) == "path") CHECK(p.everySampleZeroOrOne);
    }
}

}  // namespace

TEST_CASE("Alpha: a black MASK cut-out opaque on 3/4 of its area shows exactly 1/4 of a constant environment", "[alpha]") {
    Doc d;
    const int mat = d.lambert({0, 0, 0});
    // Texel alphas 0.10, 0.30, 0.60, 0.90 against cutoff 0.25: three of four texels are covered.
    const int tex = nearestTexture(d, 4, 1, {0, 0, 0, 26, 0, 0, 0, 77, 0, 0, 0, 153, 0, 0, 0, 230});
    makeAlpha(d, mat, "MASK", 1.0, tex, 0.25);
    const Scene scene = planeScene(d, mat, "alpha-mask-plane.gltf");
    REQUIRE(scene.materials.at(0).alphaMode == AlphaMode::Mask);
    checkKnownAnswer(scene, 0.25, true);
}

TEST_CASE("Alpha: a BLEND plane of coverage a shows (1 - a) of the environment plus a times its own shading", "[alpha]") {
    SECTION("black, coverage = factor 0.6 x texture alpha 128/255") {
        Doc d;
        const int mat = d.lambert({0, 0, 0});
        const int tex = nearestTexture(d, 1, 1, {255, 255, 255, 128});
        makeAlpha(d, mat, "BLEND", 0.6, tex);
        const Scene scene = planeScene(d, mat, "alpha-blend-black.gltf");
        const double a = double(0.6f * (128.f / 255.f));
        checkKnownAnswer(scene, 1.0 - a, false);
    }
    SECTION("black, coverage = COLOR_0 alpha 0.4 (vertex colours multiply the base colour's alpha)") {
        Doc d;
        const int mat = d.lambert({0, 0, 0});
        makeAlpha(d, mat, "BLEND", 1.0);
        const int node = uvQuad(d, {{{-2, -2, 0}, {2, -2, 0}, {2, 2, 0}, {-2, 2, 0}}}, {{{0, 0}, {1, 0}, {1, 1}, {0, 1}}}, mat);
        std::vector<float> colors;
        for (int k = 0; k < 6; ++k) colors.insert(colors.end(), {1.f, 1.f, 1.f, 0.4f});
        d.j["meshes"][size_t(d.j["nodes"][size_t(node)]["mesh"].get<int>())]["primitives"][0]["attributes"]["COLOR_0"] = d.floats(colors, "VEC4");
        const Scene scene = loadWithCamera(d, "alpha-blend-color0.gltf",
                                           Camera::lookAt(Vec3(0, 0, 1), Vec3(0, 0, 0), Vec3(0, 1, 0), 0.5f * kPi, 32, 32), Rgb(1.f));
        checkKnownAnswer(scene, 1.0 - double(0.4f), false);
    }
    SECTION("Lambert rho = 0.5, coverage 0.3") {
        Doc d;
        const int mat = d.lambert({0.5, 0.5, 0.5});
        makeAlpha(d, mat, "BLEND", 0.3);
        const Scene scene = planeScene(d, mat, "alpha-blend-grey.gltf");
        checkKnownAnswer(scene, 0.7 + 0.3 * 0.5, false);
    }
}

TEST_CASE("Alpha: the BLEND decision is a pure function of the ray and the triangle, uniform over rays", "[alpha]") {
    // Same ray, same triangle: same number; a different triangle, origin or direction bit: another.
    const Vec3 o(0.25f, -1.5f, 3.f), w = glm::normalize(Vec3(0.3f, 0.2f, -1.f));
    CHECK(blendDecisionNumber(o, w, 7) == blendDecisionNumber(o, w, 7));
    CHECK(blendDecisionNumber(o, w, 7) != blendDecisionNumber(o, w, 8));
    CHECK(blendDecisionNumber(o, w, 7) != blendDecisionNumber(Vec3(std::nextafter(o.x, 1.f), o.y, o.z), w, 7));
    CHECK(blendDecisionNumber(o, w, 7) != blendDecisionNumber(o, Vec3(w.x, std::nextafter(w.y, 1.f), w.z), 7));
    // The test vectors of docs/rng.md ("Alpha coverage"), computed there by the Python reference.
    CHECK(blendDecisionNumber(Vec3(0.25f, -1.5f, 3.f), Vec3(0.f, 0.f, -1.f), 7) == 0.20818054676055908f);
    CHECK(blendDecisionNumber(Vec3(0.f), Vec3(0.6f, 0.f, -0.8f), 0) == 0.10892736911773682f);
    // Over 1e5 rays differing in the last bits of one direction component the numbers are uniform:
    // the fraction below a is Binomial(n, a) / n, checked at 5 sigma for a few a.
    const int n = 100000;
    for (double a : {0.1, 0.5, 0.9}) {
        int below = 0;
        Vec3 dir = w;
        for (int i = 0; i < n; ++i) {
            dir.x = std::nextafter(dir.x, 1.f);
            below += blendDecisionNumber(o, dir, 3) < float(a);
        }
        CHECK(std::abs(double(below) / n - a) <= kSigmas * std::sqrt(a * (1 - a) / n));
    }
}

TEST_CASE("Alpha: an emissive MASK or BLEND material is refused with the reason", "[alpha]") {
    for (const char* mode : {"MASK", "BLEND"}) {
        Doc d;
        const int mat = d.lambert({0.5, 0.5, 0.5}, {1, 1, 1});
        makeAlpha(d, mat, mode, 0.5);
        d.triangles({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, mat);
        try {
            LoadOptions o;
            (void)loadGltfScene(d.write(std::string("alpha-emissive-") + mode + ".gltf"), o);
            FAIL("an emissive " << mode << " material was accepted");
        } catch (const InputError& e) {
            const std::string msg = e.what();
            INFO(msg);
            CHECK(msg.find("material 0") != std::string::npos);
            CHECK(msg.find(std::string("alphaMode ") + mode) != std::string::npos);
            CHECK(msg.find("emissive") != std::string::npos);
        }
    }
}

// ---- a box lit by an area light, with a MASK and a BLEND quad casting shadows ---------------------

namespace {

// Box [-1, 1] x [0, 2] x [-1, 1] (grey Lambert, open towards the camera at +z), a light quad under
// the ceiling, a green MASK quad (stripes of texel alphas 0.1 0.3 0.6 0.9, cutoff 0.5: half is
// there) at y = 1.2 over the left half and an orange BLEND quad (coverage 0.7 x texel alpha 1 or
// 128/255) at y = 0.7 over the right half. `invisibleQuad` adds, LAST (so every other triangle
// keeps its index), a MASK quad of alpha 0 across the middle of the box.
Scene alphaBox(int width, int height, bool withAlpha = true, bool invisibleQuad = false) {
    Doc d;
    const int wall = d.lambert({0.6, 0.6, 0.6});
    d.box({-1, 0, -1}, {1, 2, 1}, wall, true, {5});
    const int light = d.lambert({0, 0, 0}, {1, 1, 1}, 12.0);
    d.quad({-0.4, 1.98, -0.4}, {0.4, 1.98, -0.4}, {0.4, 1.98, 0.4}, {-0.4, 1.98, 0.4}, light);
    if (withAlpha) {
        const int green = d.lambert({0.2, 0.7, 0.3});
        makeAlpha(d, green, "MASK", 1.0, nearestTexture(d, 4, 1, {255, 255, 255, 26, 255, 255, 255, 77, 255, 255, 255, 153, 255, 255, 255, 230}), 0.5);
        uvQuad(d, {{{-0.8, 1.2, -0.6}, {-0.8, 1.2, 0.6}, {0, 1.2, 0.6}, {0, 1.2, -0.6}}}, {{{0, 0}, {0, 1}, {8, 1}, {8, 0}}}, green);
        const int orange = d.lambert({0.8, 0.4, 0.2});
        makeAlpha(d, orange, "BLEND", 0.7, nearestTexture(d, 2, 1, {255, 255, 255, 255, 255, 255, 255, 128}));
        uvQuad(d, {{{0.05, 0.7, -0.6}, {0.05, 0.7, 0.6}, {0.85, 0.7, 0.6}, {0.85, 0.7, -0.6}}}, {{{0, 0}, {0, 1}, {4, 1}, {4, 0}}}, orange);
    }
    if (invisibleQuad) {
        const int none = d.lambert({0.9, 0.9, 0.9});
        makeAlpha(d, none, "MASK", 0.0);
        d.quad({-0.9, 1.0, -0.9}, {-0.9, 1.0, 0.9}, {0.9, 1.0, 0.9}, {0.9, 1.0, -0.9}, none);
    }
    return loadWithCamera(d, std::string("alpha-box-") + (withAlpha ? "a" : "") + (invisibleQuad ? "i" : "") + ".gltf",
                          Camera::lookAt(Vec3(0, 1, 3.4), Vec3(0, 1, 0), Vec3(0, 1, 0), 0.75f, width, height));
}

}  // namespace

TEST_CASE("Alpha: PT LT BDPT-balance and BDPT-power agree per pixel on a box with MASK and BLEND quads casting shadows",
          "[alpha][agreement]") {
    const Scene scene = alphaBox(16, 16);
    checkPairwiseAgreement(momentsOfEach(renderEveryEstimator(scene, {1024, 1024, 512, 512}, 3000)), 0.05);
}

TEST_CASE("Alpha: the alpha quads change the image (shadows and their own shading are there)", "[alpha]") {
    // Not vacuous: with the quads the PT image differs from the box alone by many standard errors.
    EstimatorSetup s;
    s.integrator = "path";
    s.spp = 256;
    const ImageComparison c =
        compareImages(momentsOf(renderEstimator(alphaBox(16, 16), s)), momentsOf(renderEstimator(alphaBox(16, 16, false), s)));
    INFO(c.report);
    CHECK(c.rejected > 3 * c.bound);
}

TEST_CASE("Alpha: MIS definition weights sum to 1 and production weights equal them on paths through MASK and BLEND surfaces",
          "[alpha][mis]") {
    const Scene scene = alphaBox(16, 16);
    long throughMask = 0, throughBlend = 0;
    const MisPathCheck r = checkSampledPathWeights(scene, 6000, 20250401u, 5, [&](const std::vector<PathVertex>& x, int) {
        bool mask = false, blend = false;
        for (const PathVertex& v : x)
            if (v.type == VertexType::Surface) {
                mask = mask || scene.materials[v.material].alphaMode == AlphaMode::Mask;
                blend = blend || scene.materials[v.material].alphaMode == AlphaMode::Blend;
            }
        throughMask += mask;
        throughBlend += blend;
    });
    INFO(r.summary() << "; with a MASK vertex " << throughMask << ", with a BLEND vertex " << throughBlend);
    CHECK(r.paths >= 10000);
    CHECK(throughMask >= 1000);
    CHECK(throughBlend >= 1000);
    CHECK(r.passed());
}

TEST_CASE("Alpha: the wavefront renders the box with MASK and BLEND quads bit-identically to the megakernel", "[alpha][wavefront]") {
    const Scene scene = alphaBox(16, 16);
    for (int pool : {0, 37})  // automatic, and tiny pools and queues (as tests/scenes/test_wavefront.cpp)
        for (EstimatorSetup s : everyEstimator()) {
            s.spp = 4;
            s.threads = 2;
            s.layers = s.integrator != "path";
            s.wavefrontOptions.poolSize = pool;
            if (pool) {
                s.wavefrontOptions.shadowQueueCapacity = 16;
                s.wavefrontOptions.connectionQueueCapacity = 50;
            }
            checkWavefrontIdentical(scene, s);
        }
}

TEST_CASE("Alpha: a MASK quad covered nowhere renders bit-identically to no quad, for every estimator", "[alpha]") {
    // Every ray kind (camera and light extensions, next-event, connections, the t = 1 rays to the
    // camera) crosses the quad, which lies between the light and the floor, in front of the
    // camera: a filter that missed one ray kind would leave a shadow or a hole.
    const Scene without = alphaBox(16, 16);
    const Scene with = alphaBox(16, 16, true, true);
    for (EstimatorSetup s : everyEstimator()) {
        s.spp = 4;
        s.layers = s.integrator != "path";
        INFO(estimatorName(s));
        const Film a = renderEstimator(without, s);
        const Film b = renderEstimator(with, s);
        CHECK(filmDifference(a, b, s.maxDepth).total() == 0);
        CHECK(meanLuminance(a) > 1e-3);
    }
}

TEST_CASE("Alpha: a negative alphaCutoff is refused with the file and the material", "[alpha]") {
    Doc d;
    const int mat = d.lambert({0.5, 0.5, 0.5});
    makeAlpha(d, mat, "MASK", 1.0, -1, 0.5);
    d.j["materials"][0]["alphaCutoff"] = -0.25;
    d.triangles({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, mat);
    const std::string path = d.write("alpha-bad-cutoff.gltf");
    try {
        (void)loadGltfScene(path, LoadOptions{});
        FAIL("a negative alphaCutoff was accepted");
    } catch (const InputError& e) {
        const std::string msg = e.what();
        INFO(msg);
        CHECK(msg.find("alpha-bad-cutoff.gltf") != std::string::npos);
        CHECK(msg.find("material 0") != std::string::npos);
        CHECK(msg.find("alphaCutoff") != std::string::npos);
    }
}

TEST_CASE("Alpha: bdptref render of the MASK cut-out plane shows 1/4 of the environment, without warnings", "[alpha][cli]") {
    Doc d;
    const int mat = d.lambert({0, 0, 0});
    const int tex = nearestTexture(d, 4, 1, {0, 0, 0, 26, 0, 0, 0, 77, 0, 0, 0, 153, 0, 0, 0, 230});
    makeAlpha(d, mat, "MASK", 1.0, tex, 0.25);
    uvQuad(d, {{{-2, -2, 0}, {2, -2, 0}, {2, 2, 0}, {-2, 2, 0}}}, {{{-32, 0}, {32, 0}, {32, 1}, {-32, 1}}}, mat);
    const std::string scene = d.write("alpha-cli-mask.gltf");
    const std::string out = makeTempDir("alpha-cli") + "/mask.exr";
    std::string log;
    const int spp = 32;
    REQUIRE(runCli("render " + scene + " --env 1,1,1 --camera-pos 0,0,1 --camera-target 0,0,0 --fov 90 --width 32 --height 32 --spp " +
                       std::to_string(spp) + " --no-preview -o " + out,
                   &log) == 0);
    INFO(log);
    CHECK(log.find("alphaMode") == std::string::npos);  // implemented: no "not implemented" warning
    const ExrImage img = readImage(out);
    double mean = 0;
    for (float v : img.channels.at("R")) mean += double(v) / double(img.channels.at("R").size());
    // Each PT sample is 0 or 1 with P(1) = 1/4 (deterministic cut-out): standard error of the mean
    // sqrt(p (1 - p) / N) over N = 32 x 32 x spp samples.
    const double se = std::sqrt(0.25 * 0.75 / (32.0 * 32.0 * spp));
    CHECK(std::abs(mean - 0.25) <= kSigmas * se);
}
