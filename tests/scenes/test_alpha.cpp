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
#include "support/gltf_builder.h"
#include "support/image_stats.h"
#include "support/mis_tolerance.h"
#include "support/render_util.h"

#include "bdptref/bdpt.h"
#include "bdptref/errors.h"
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

struct Setup {
    std::string integrator = "path";
    MisHeuristic heuristic = MisHeuristic::Balance;
    int spp = 16, maxDepth = 5, threads = 0;
    uint32_t seed = 1;
    bool layers = false;
    bool wavefront = false;
};

Film render(const Scene& scene, const Setup& s, const std::function<void(const Film&)>& afterPass = {}) {
    IntegratorSettings is;
    is.maxDepth = s.maxDepth;
    is.mis.heuristic = s.heuristic;
    is.recordStrategies = s.layers;
    const auto integrator = makeIntegrator(s.integrator, is);
    RenderOptions ro;
    ro.spp = s.spp;
    ro.seed = s.seed;
    ro.threads = s.threads;
    std::unique_ptr<WavefrontScheduler> wavefront;
    if (s.wavefront) {
        WavefrontOptions wo;
        wavefront = std::make_unique<WavefrontScheduler>(s.integrator, is, wo);
        ro.scheduler = wavefront.get();
    }
    Film film(scene.camera.width(), scene.camera.height());
    if (s.layers) film.enableStrategies(s.maxDepth);
    std::function<void(const RenderProgress&)> progress;
    if (afterPass) progress = [&](const RenderProgress&) { afterPass(film); };
    renderImage(scene, *integrator, ro, film, nullptr, progress);
    return film;
}

// Image mean (luminance-free: channel 0, the scenes below are grey) and its standard error from
// the per-pass image means.
struct Pooled {
    double mean = 0, standardError = 0;
    bool everySampleZeroOrOne = true;
};
Pooled passPooled(const Scene& scene, const Setup& s) {
    double previous = 0, sum = 0, sumSq = 0;
    int n = 0;
    const Film film = render(scene, s, [&](const Film& f) {
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
        Setup s;
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
