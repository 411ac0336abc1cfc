// `bdptref trace --integrator path` (src/verify/trace_path.h, docs/trace-and-mis.md "Path tracing"):
//  * the traced samples rebuild a 1-spp path-traced render bit for bit (the trace runs the
//    renderer's own ptBegin / ptShade / traceShadowRay, so nothing may differ);
//  * what each bounce records is consistent: L is exactly the sum, in the renderer's order, of
//    the recorded emission and unoccluded next-event contributions; the MIS weights are the power
//    heuristic of the recorded densities; an emission found after a non-delta bounce carries the
//    density of that bounce's BSDF sample; the recorded random numbers are the PixelSampler's
//    draws at the dimensions docs/rng.md documents;
//  * the command prints that JSON and refuses options that have no meaning for path tracing.
#include "support/render_util.h"

#include "bdptref/integrator.h"
#include "bdptref/renderer.h"
#include "bdptref/rng.h"
#include "verify/trace_path.h"

#include <catch2/catch.hpp>

#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <string>

using namespace bdptref;
using namespace bdptref::test;

namespace {

const Rgb kZooEnv(0.3f, 0.35f, 0.4f);

// The power heuristic (beta 2) of the recorded densities, computed here in double.
double power2(double a, double b) { return a * a / (a * a + b * b); }
// The renderer computes the weight in double and rounds it to float once: 2^-23 relative
// covers that rounding; 4x that for the float products of the light density (pmf x pdf).
bool weightIs(float w, double expected) { return std::abs(double(w) - expected) <= 4.0 * 0x1p-23 * expected; }

}  // namespace

TEST_CASE("trace --integrator path: the traced samples rebuild a 1-spp path-traced render bit for bit", "[trace][path]") {
    struct Case {
        const char* file;
        Rgb env;
        int width, height, maxDepth;
    };
    const Case cases[] = {{"scenes/cornell-box.gltf", Rgb(0.f), 12, 9, 5}, {"scenes/mis-zoo.gltf", kZooEnv, 16, 12, 6}};
    long nonZero = 0, bounces = 0;
    for (const Case& c : cases) {
        const Scene scene = loadTestScene(c.file, c.width, c.height, c.env);
        IntegratorSettings is;
        is.maxDepth = c.maxDepth;
        for (uint64_t sample : {uint64_t(0), uint64_t(3)}) {
            const uint32_t seed = 11;
            // A render whose only pass is `sample`: the sample index is the pass number.
            const auto pt = makeIntegrator("path", is);
            RenderOptions ro;
            ro.spp = 1;
            ro.seed = seed;
            ro.firstSample = sample;
            Film film(c.width, c.height);
            renderImage(scene, *pt, ro, film);
            long mismatches = 0;
            for (int y = 0; y < c.height; ++y)
                for (int x = 0; x < c.width; ++x) {
                    const TracedPathSample t = tracePathSample(scene, seed, is, x, y, sample);
                    nonZero += !isBlack(t.L);
                    bounces += long(t.bounces.size());
                    if (film.sum(x, y) != DVec3(t.L)) ++mismatches;
                }
            INFO(c.file << " sample " << sample);
            CHECK(mismatches == 0);
        }
    }
    CHECK(nonZero > 200);  // not vacuous
    CHECK(bounces > 1000);
}

TEST_CASE("trace --integrator path: each bounce's record is consistent with L, the MIS rule and docs/rng.md", "[trace][path]") {
    // mis-zoo: delta BSDFs and lights, an environment; the Cornell box: area lights found by BSDF sampling.
    const Scene scenes[] = {loadTestScene("scenes/mis-zoo.gltf", 16, 16, kZooEnv), loadTestScene("scenes/cornell-box.gltf", 16, 16)};
    IntegratorSettings is;
    is.maxDepth = 8;
    long samples = 0, sumMismatch = 0, weightMismatch = 0, pdfMismatch = 0, randomMismatch = 0;
    long emissionsWeighted = 0, neeUnoccluded = 0, neeDelta = 0, roulette = 0, escapes = 0;
    for (int k = 0; k < 1200; ++k) {
        const Scene& scene = scenes[k % 2];
        const int x = (k * 7) % 16, y = (k * 5) % 16;
        const uint64_t sample = uint64_t(k / 256);
        const TracedPathSample t = tracePathSample(scene, 5, is, x, y, sample);
        ++samples;
        const PixelSampler sampler(5, pixelIndex(x, y, 16), sample);
        if (t.raster != Vec2(float(x), float(y)) + sampler.get2D(RngStream::Camera, dim::kFilm)) ++randomMismatch;
        Rgb L(0.f);
        for (size_t i = 0; i < t.bounces.size(); ++i) {
            const PtBounceRecord& r = t.bounces[i];
            escapes += r.escaped;
            const uint32_t b = uint32_t(r.bounce);
            if (r.emission) {
                L += r.emissionAdded;
                if (r.emissionLightPdf > 0.f) {
                    ++emissionsWeighted;
                    if (!weightIs(r.emissionWeight, power2(r.emissionBsdfPdf, r.emissionLightPdf))) ++weightMismatch;
                    // The density of the BSDF sample that found this emission, at the previous vertex.
                    if (i == 0 || r.emissionBsdfPdf != t.bounces[i - 1].bsdf.pdf) ++pdfMismatch;
                }
            }
            if (r.neeTried) {
                if (r.uNeeLight != sampler.get1D(RngStream::Camera, dim::vertex(b, dim::kNeeLight)) ||
                    r.uNeePosition != sampler.get2D(RngStream::Camera, dim::vertex(b, dim::kNeePosition)))
                    ++randomMismatch;
                if (r.neeShadowRay) {
                    const float lightPdf = r.neePmf * r.nee.pdf;
                    if (r.nee.delta) {
                        ++neeDelta;
                        if (r.neeWeight != 1.f) ++weightMismatch;
                    } else if (!weightIs(r.neeWeight, power2(lightPdf, r.neeBsdfPdf))) {
                        ++weightMismatch;
                    }
                    if (r.neeUnoccluded) {
                        ++neeUnoccluded;
                        L += r.neeContribution;
                    }
                }
            }
            if (r.bsdfDrawn && (r.uBsdfLobe != sampler.get1D(RngStream::Camera, dim::vertex(b, dim::kBsdfLobe)) ||
                                r.uBsdfDirection != sampler.get2D(RngStream::Camera, dim::vertex(b, dim::kBsdfDirection))))
                ++randomMismatch;
            if (r.rouletteTested) {
                ++roulette;
                if (r.uRoulette != sampler.get1D(RngStream::Camera, dim::vertex(b, dim::kRoulette))) ++randomMismatch;
                if (r.survived != (r.uRoulette < r.survive)) ++randomMismatch;
            }
            // A path continues exactly when the next record exists.
            if (r.continues != (i + 1 < t.bounces.size())) ++sumMismatch;
        }
        if (L != t.L) ++sumMismatch;
    }
    INFO(samples << " samples: weighted emissions " << emissionsWeighted << ", unoccluded NEE " << neeUnoccluded << " (delta lights "
                 << neeDelta << "), roulette tests " << roulette << ", escapes " << escapes);
    CHECK(sumMismatch == 0);
    CHECK(weightMismatch == 0);
    CHECK(pdfMismatch == 0);
    CHECK(randomMismatch == 0);
    // Not vacuous: every kind of record occurs.
    CHECK(emissionsWeighted > 50);
    CHECK(neeUnoccluded > 200);
    CHECK(neeDelta > 20);
    CHECK(roulette > 50);
    CHECK(escapes > 20);
}

TEST_CASE("trace --integrator path: the command prints every bounce as JSON and refuses options without meaning", "[trace][path][cli]") {
    const std::string scene = sourcePath("scenes/cornell-box.gltf");
    const std::string dir = makeTempDir("trace-path");
    const std::string common = "trace " + scene + " --width 16 --height 12 --pixel 8,6 --seed 3 --max-depth 4 --integrator path";
    std::string out;
    REQUIRE(runCli(common + " --compact -o " + dir + "/trace.json", &out) == 0);
    std::ifstream f(dir + "/trace.json");
    const nlohmann::json j = nlohmann::json::parse(f);
    CHECK(j.at("settings").at("integrator") == "path");
    REQUIRE(j.at("bounces").is_array());
    REQUIRE(!j.at("bounces").empty());
    CHECK(j.at("bounces")[0].at("bounce") == 0);
    CHECK(j.at("bounces")[0].contains("vertex"));
    CHECK(j.at("bounces")[0].at("nee").contains("pmf"));
    CHECK(j.at("bounces")[0].at("random").at("dimensionBase") == dim::vertex(0, dim::kBsdfLobe));
    // The same numbers as the library's trace.
    const Scene s = loadTestScene("scenes/cornell-box.gltf", 16, 12);
    IntegratorSettings is;
    is.maxDepth = 4;
    const TracedPathSample t = tracePathSample(s, 3, is, 8, 6, 0);
    CHECK(j.at("bounces").size() == t.bounces.size());
    CHECK(j.at("total").at("L")[0].get<double>() == double(t.L.x));

    checkInputError(common + " --path 1,2", "no (s,t) strategies");
    checkInputError(common + " --mode wavefront", "megakernel only");
    checkInputError("trace " + scene + " --pixel 1,1 --integrator photon", "--integrator");
}
