// The pinhole camera's importance We and its densities (docs/camera.md).
#include "bdptref/camera.h"
#include "bdptref/rng.h"
#include "bdptref/sampling.h"

#include <catch2/catch.hpp>

using namespace bdptref;

namespace {
Camera testCamera(int w, int h) {
    return Camera::lookAt(Vec3(1, 2, 3), Vec3(1.5f, 1.7f, -2.f), Vec3(0, 1, 0), 0.9f, w, h);
}

// Monte Carlo integral over the sphere of g(w) with uniform directions; returns mean and its
// standard error.
template <class F>
std::pair<double, double> sphereIntegral(F g, int n, uint32_t seed) {
    double s = 0, s2 = 0;
    for (int i = 0; i < n; ++i) {
        const Vec3 w = squareToUniformSphere(PixelSampler(seed, 0, uint64_t(i)).get2D(RngStream::Camera, 0));
        const double v = g(w) / double(uniformSpherePdf());
        s += v;
        s2 += v * v;
    }
    const double mean = s / n;
    return {mean, std::sqrt(std::max(0.0, s2 / n - mean * mean) / n)};
}
}  // namespace

TEST_CASE("We integrates to 1 over the image (integral of We cos dw)", "[camera]") {
    for (auto [w, h] : {std::pair{64, 64}, std::pair{96, 40}}) {
        const Camera cam = testCamera(w, h);
        const auto [mean, se] = sphereIntegral(
            [&](const Vec3& d) { return double(cam.We(d)) * std::max(0.f, glm::dot(d, cam.forward())); }, 400000, 11);
        INFO("integral " << mean << " +- " << se);
        CHECK(std::abs(mean - 1.0) < 5 * se);  // k = 5
        CHECK(se < 0.01);                      // the test can see a 5% error
    }
}

TEST_CASE("pdfWe's direction density integrates to 1 over the image", "[camera]") {
    const Camera cam = testCamera(80, 48);
    const auto [mean, se] = sphereIntegral(
        [&](const Vec3& d) {
            float pp, pd;
            cam.pdfWe(d, &pp, &pd);
            return double(pd);
        },
        400000, 12);
    CHECK(std::abs(mean - 1.0) < 5 * se);
    CHECK(se < 0.01);
}

TEST_CASE("generateRay, We and sampleWi agree on where a direction lands", "[camera]") {
    const Camera cam = testCamera(64, 32);
    for (int i = 0; i < 1000; ++i) {
        const Vec2 raster = PixelSampler(5, 0, uint64_t(i)).get2D(RngStream::Camera, 0) * Vec2(64, 32);
        const Ray r = cam.generateRay(raster);
        Vec2 back;
        REQUIRE(cam.We(r.dir, &back) > 0.f);
        CHECK(back.x == Approx(raster.x).margin(1e-3));
        CHECK(back.y == Approx(raster.y).margin(1e-3));
        // A point on that ray sees the camera at the same raster position, at the right distance.
        const Vec3 p = r.origin + 3.7f * r.dir;
        CameraImportanceSample s;
        REQUIRE(cam.sampleWi(p, &s));
        CHECK(s.dist == Approx(3.7f).epsilon(1e-5));
        CHECK(s.raster.x == Approx(raster.x).margin(1e-3));
        CHECK(s.raster.y == Approx(raster.y).margin(1e-3));
        const float cosCam = glm::dot(cam.forward(), r.dir);
        CHECK(s.pdf == Approx(3.7f * 3.7f / cosCam).epsilon(1e-4));
        CHECK(s.We == Approx(cam.We(r.dir)).epsilon(1e-5));
    }
    // Behind the camera or outside the frustum there is no importance.
    CHECK(cam.We(-cam.forward()) == 0.f);
    CameraImportanceSample s;
    CHECK_FALSE(cam.sampleWi(cam.position() - cam.forward(), &s));
}

TEST_CASE("Raster y grows downwards and x to the right", "[camera]") {
    const Camera cam = Camera::lookAt(Vec3(0), Vec3(0, 0, -1), Vec3(0, 1, 0), 1.f, 10, 10);
    CHECK(cam.generateRay(Vec2(0.5f, 0.5f)).dir.y > 0.f);  // top row looks up
    CHECK(cam.generateRay(Vec2(0.5f, 0.5f)).dir.x < 0.f);  // left column looks left
    CHECK(cam.generateRay(Vec2(5.f, 5.f)).dir.z == Approx(-1.f));
}
