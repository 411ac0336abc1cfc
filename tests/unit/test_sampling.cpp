// Every sampling warp against its density: chi-square goodness of fit (family-wise alpha 1%
// over the kChi2Tests tests of this file, Šidák-corrected), and every pdf integrates to 1.
#include "bdptref/sampling.h"
#include "support/chi2.h"

#include <catch2/catch.hpp>

using namespace bdptref;
using namespace bdptref::test;

namespace {
constexpr int kChi2Tests = 8;
const double kAlpha = sidakAlpha(0.01, kChi2Tests);
constexpr uint64_t kSamples = 400000;

// Integral of a direction pdf over the sphere by a fine midpoint rule in (cos theta, phi).
double integrateOverSphere(const std::function<double(const Vec3&)>& pdf) {
    const int nt = 800, np = 400;
    double s = 0;
    for (int i = 0; i < nt; ++i)
        for (int j = 0; j < np; ++j) {
            const double z = -1.0 + 2.0 * (i + 0.5) / nt, phi = 2.0 * kPi * (j + 0.5) / np;
            const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
            s += pdf(Vec3(float(r * std::cos(phi)), float(r * std::sin(phi)), float(z)));
        }
    return s * (2.0 / nt) * (2.0 * kPi / np);
}
}  // namespace

TEST_CASE("Uniform sphere warp", "[sampling][chi2]") {
    const auto r = chi2DirectionTest(
        [](uint64_t i, Vec3* d) { *d = squareToUniformSphere(TestRng(1, i).uniform2D()); return true; },
        [](const Vec3&) { return double(uniformSpherePdf()); }, kSamples, 10, 20);
    INFO(r.report);
    CHECK(r.pValue > kAlpha);
    CHECK(integrateOverSphere([](const Vec3&) { return double(uniformSpherePdf()); }) == Approx(1.0).epsilon(1e-6));
}

TEST_CASE("Cosine hemisphere warp", "[sampling][chi2]") {
    auto pdf = [](const Vec3& d) { return double(cosineHemispherePdf(d.z)); };
    const auto r = chi2DirectionTest(
        [](uint64_t i, Vec3* d) { *d = squareToCosineHemisphere(TestRng(2, i).uniform2D()); return true; }, pdf,
        kSamples, 10, 20);
    INFO(r.report);
    CHECK(r.pValue > kAlpha);
    CHECK(integrateOverSphere(pdf) == Approx(1.0).epsilon(1e-4));
}

TEST_CASE("Uniform cone warp (wide and narrow)", "[sampling][chi2]") {
    // Tested in coordinates where its density is smooth: a = (1 - cos theta) / (1 - cosMax) and
    // b = phi / (2 pi) are uniform on the unit square exactly when the density in solid angle is
    // the constant 1 / (2 pi (1 - cosMax)) on the cone (dw = (1 - cosMax) 2 pi da db).
    for (float cosMax : {0.3f, 0.995f}) {
        const auto r = chi2Test2D(
            [cosMax](uint64_t i, Vec2* p) {
                const Vec3 d = squareToUniformCone(TestRng(3, i).uniform2D(), cosMax);
                float phi = std::atan2(d.y, d.x);
                if (phi < 0.f) phi += 2.f * kPi;
                *p = Vec2((1.f - d.z) / (1.f - cosMax), phi / (2.f * kPi));
                return true;
            },
            [cosMax](const Vec2&) { return double(uniformConePdf(cosMax)) * (1.0 - cosMax) * 2.0 * kPi; }, kSamples,
            16, 16);
        INFO("cosMax " << cosMax << "\n" << r.report);
        CHECK(r.pValue > kAlpha);
    }
    // The cone's density integrates to 1: solid angle 2 pi (1 - cosMax) times 1 / that.
    CHECK(2.0 * kPi * (1.0 - 0.3) * uniformConePdf(0.3f) == Approx(1.0).epsilon(1e-6));
}

TEST_CASE("Concentric disk warp is uniform on the unit disk", "[sampling][chi2]") {
    const auto r = chi2Test2D(
        [](uint64_t i, Vec2* p) { *p = squareToConcentricDisk(TestRng(4, i).uniform2D()); return true; },
        [](const Vec2& p) { return glm::dot(p, p) <= 1.f ? double(kInvPi) : 0.0; }, kSamples, 16, 16, Vec2(-1.f),
        Vec2(1.f));
    INFO(r.report);
    CHECK(r.pValue > kAlpha);
}

TEST_CASE("Uniform triangle warp: barycentrics uniform over the triangle", "[sampling][chi2]") {
    // (b0, b1) uniform on {b0, b1 >= 0, b0 + b1 <= 1} (density 2) is, in the smooth coordinates
    // (b0, s = b1 / (1 - b0)) on the unit square, the density 2 (1 - b0).
    const auto r = chi2Test2D(
        [](uint64_t i, Vec2* p) {
            const Vec2 b = squareToUniformTriangle(TestRng(5, i).uniform2D());
            if (!(b.x >= 0.f && b.y >= 0.f && b.x + b.y <= 1.f + 1e-6f)) return false;
            *p = Vec2(b.x, b.x < 1.f ? std::min(b.y / (1.f - b.x), 1.f) : 0.f);
            return true;
        },
        [](const Vec2& p) { return 2.0 * (1.0 - p.x); }, kSamples, 16, 16);
    INFO(r.report);
    CHECK(r.pValue > kAlpha);
}

TEST_CASE("Distribution1D: frequencies follow the weights, zero weights are never chosen", "[sampling][chi2]") {
    const std::vector<double> w = {1.0, 0.0, 3.5, 0.25, 7.0, 0.0, 2.0};
    const Distribution1D d(w);
    double total = 0;
    for (double x : w) total += x;
    std::vector<double> pmf;
    for (double x : w) pmf.push_back(x / total);
    const auto r = chi2DiscreteTest(
        [&](uint64_t i, size_t* k) {
            float p, remapped;
            *k = d.sample(TestRng(6, i).uniform(), &p, &remapped);
            return p > 0.f && remapped >= 0.f && remapped < 1.f;
        },
        pmf, kSamples);
    INFO(r.report);
    CHECK(r.pValue > kAlpha);
    for (size_t k = 0; k < w.size(); ++k) CHECK(d.pmf(k) == Approx(pmf[k]).epsilon(1e-6));
    // The extremes of u never pick a zero-weight bucket.
    float p;
    CHECK(w[d.sample(0.f, &p)] > 0);
    CHECK(w[d.sample(0x1.fffffep-1f, &p)] > 0);
}

TEST_CASE("Distribution1D's remapped number is uniform within the chosen bucket", "[sampling][chi2]") {
    const Distribution1D d({2.0, 1.0, 5.0});
    const auto r = chi2Test2D(
        [&](uint64_t i, Vec2* p) {
            float pmf, u2;
            const size_t k = d.sample(TestRng(7, i).uniform(), &pmf, &u2);
            if (k != 2) return false;  // lost mass: the other buckets
            *p = Vec2(u2, 0.5f);
            return true;
        },
        [](const Vec2&) { return 5.0 / 8.0; }, kSamples, 20, 1);
    INFO(r.report);
    CHECK(r.pValue > kAlpha);
}
