// The orthographic camera (docs/camera.md, "Orthographic cameras"): parallel rays from a film
// rectangle, importance 1/A per unit film area, the first vertex's area density |cos| / A, and
// sampleWi projecting a point back onto the film. Tolerances: Monte Carlo integrals at k = 5
// standard errors (fixed seeds), geometry at float precision.
#include "bdptref/camera.h"
#include "bdptref/rng.h"

#include <catch2/catch.hpp>

using namespace bdptref;

namespace {
// Film of half-extents 1.5 x 0.75 (xmag = ymag * 96 / 48), looking roughly down -z, tilted.
Camera orthoCamera(int w = 96, int h = 48) {
    return Camera::orthographicLookAt(Vec3(1, 2, 3), Vec3(1.5f, 1.7f, -2.f), Vec3(0, 1, 0), 0.75f, w, h);
}
Vec2 uniform2(uint32_t seed, int i) { return PixelSampler(seed, 0, uint64_t(i)).get2D(RngStream::Camera, 0); }
}  // namespace

TEST_CASE("Orthographic camera: generateRay gives parallel rays from the film, pixel positions as documented", "[camera]") {
    const Camera cam = orthoCamera();
    CHECK(cam.isOrthographic());
    CHECK(cam.ymag() == Approx(0.75f));
    CHECK(cam.xmag() == Approx(1.5f));
    CHECK(cam.imagePlaneArea() == Approx(4.f * 1.5f * 0.75f));
    for (int i = 0; i < 200; ++i) {
        const Vec2 raster = uniform2(3, i) * Vec2(96, 48);
        const Ray r = cam.generateRay(raster);
        CHECK(glm::dot(r.dir, cam.forward()) == Approx(1.f).epsilon(1e-6));
        // The origin lies on the film plane, at the documented offsets from the centre.
        const Vec3 d = r.origin - cam.position();
        CHECK(glm::dot(d, cam.forward()) == Approx(0.f).margin(1e-5));
        const Vec3 right = glm::normalize(glm::cross(cam.forward(), cam.up()));
        CHECK(glm::dot(d, right) == Approx((2.f * raster.x / 96.f - 1.f) * 1.5f).margin(1e-5));
        CHECK(glm::dot(d, cam.up()) == Approx((1.f - 2.f * raster.y / 48.f) * 0.75f).margin(1e-5));
    }
    // The image centre is the camera position; the top-left corner is up and left of it.
    const Ray centre = cam.generateRay(Vec2(48, 24));
    CHECK(glm::length(centre.origin - cam.position()) < 1e-5f);
    const Ray corner = cam.generateRay(Vec2(0, 0));
    CHECK(glm::dot(corner.origin - cam.position(), cam.up()) == Approx(0.75f));
}

TEST_CASE("Orthographic camera: sampleWi projects a point back to the film point and pixel of its ray", "[camera]") {
    const Camera cam = orthoCamera();
    for (int i = 0; i < 1000; ++i) {
        const Vec2 raster = uniform2(5, i) * Vec2(96, 48);
        const Ray r = cam.generateRay(raster);
        const float depth = 0.1f + 7.f * uniform2(6, i).x;
        const Vec3 p = r.origin + depth * r.dir;
        CameraImportanceSample s;
        REQUIRE(cam.sampleWi(p, &s));
        CHECK(s.raster.x == Approx(raster.x).margin(2e-3));
        CHECK(s.raster.y == Approx(raster.y).margin(2e-3));
        CHECK(glm::length(s.pCamera - r.origin) < 1e-4f);
        CHECK(glm::dot(s.wi, -cam.forward()) == Approx(1.f).epsilon(1e-6));
        CHECK(s.dist == Approx(depth).epsilon(1e-4));
        CHECK(s.pdf == 1.f);                                // the delta direction's Dirac factor
        CHECK(s.We == Approx(1.f / cam.imagePlaneArea()));  // importance per unit film area
    }
    CameraImportanceSample s;
    CHECK_FALSE(cam.sampleWi(cam.position() - cam.forward(), &s));  // behind the film
    const Vec3 right = glm::normalize(glm::cross(cam.forward(), cam.up()));
    CHECK_FALSE(cam.sampleWi(cam.position() + cam.forward() + 1.6f * right, &s));  // beside the film
    CHECK(cam.We(cam.forward()) == 0.f);  // no importance per solid angle (a delta direction)
}

TEST_CASE("Orthographic camera: importance and the first vertex's density integrate to 1", "[camera]") {
    // (1) Over the film plane, the importance per unit area integrates to 1 (its own measure:
    // area on the film x the direction's Dirac): integral We dA = 1. (2) On a tilted plane in
    // front of the camera, the density of the first vertex, |cos| / A, integrates to 1: the
    // camera samples it. (3) Sample/pdf agreement: the fraction of camera rays that hit a region
    // of that plane equals the integral of the density over the region.
    const Camera cam = orthoCamera();
    const Vec3 right = glm::normalize(glm::cross(cam.forward(), cam.up()));
    const int n = 200000;
    // (1) uniform points on a 4 x 2 rectangle of the film plane (area 8 > A = 4.5).
    double s1 = 0, s1sq = 0;
    for (int i = 0; i < n; ++i) {
        const Vec2 u = uniform2(7, i);
        const Vec3 p = cam.position() + (4.f * u.x - 2.f) * right + (2.f * u.y - 1.f) * cam.up() + 1e-3f * cam.forward();
        CameraImportanceSample s;
        const double v = cam.sampleWi(p, &s) ? double(s.We) * 8.0 : 0.0;
        s1 += v;
        s1sq += v * v;
    }
    const double m1 = s1 / n, se1 = std::sqrt((s1sq / n - m1 * m1) / n);
    INFO("film integral " << m1 << " +- " << se1);
    CHECK(std::abs(m1 - 1.0) < 5 * se1);
    CHECK(se1 < 0.01);
    // (2) a plane 4 units in front, tilted by 40 degrees about `right`; a 10 x 10 square on it.
    const float a = 0.698f;
    const Vec3 n2 = std::cos(a) * (-cam.forward()) + std::sin(a) * cam.up();
    const Vec3 v2 = glm::normalize(glm::cross(n2, right));
    const Vec3 c2 = cam.position() + 4.f * cam.forward();
    const double cosP = std::abs(double(glm::dot(n2, cam.forward())));
    double s2 = 0, s2sq = 0, inRegion = 0, inRegionSq = 0;
    for (int i = 0; i < n; ++i) {
        const Vec2 u = uniform2(8, i);
        const Vec3 p = c2 + (10.f * u.x - 5.f) * right + (10.f * u.y - 5.f) * v2;
        const double v = cam.pdfOrthographicVertex(p, cosP, false) * 100.0;
        s2 += v;
        s2sq += v * v;
        const double r = (u.x < 0.5f && u.y < 0.6f) ? v : 0.0;  // region x < 0, y' < 1 on the plane
        inRegion += r;
        inRegionSq += r * r;
    }
    const double m2 = s2 / n, se2 = std::sqrt((s2sq / n - m2 * m2) / n);
    INFO("first-vertex density integral " << m2 << " +- " << se2);
    CHECK(std::abs(m2 - 1.0) < 5 * se2);
    CHECK(se2 < 0.01);
    // (3) the camera's own rays into the region.
    const double mr = inRegion / n, ser = std::sqrt((inRegionSq / n - mr * mr) / n);
    int hits = 0;
    const int nRays = 100000;
    for (int i = 0; i < nRays; ++i) {
        const Ray r = cam.generateRay(uniform2(9, i) * Vec2(96, 48));
        const float t = glm::dot(c2 - r.origin, n2) / glm::dot(r.dir, n2);
        const Vec3 q = r.origin + t * r.dir - c2;
        if (glm::dot(q, right) < 0.f && glm::dot(q, v2) < 1.f) ++hits;
    }
    const double frac = double(hits) / nRays, seFrac = std::sqrt(frac * (1 - frac) / nRays);
    INFO("fraction " << frac << " +- " << seFrac << ", integral of the density " << mr << " +- " << ser);
    CHECK(std::abs(frac - mr) < 5 * std::sqrt(seFrac * seFrac + ser * ser));
    CHECK(frac > 0.2);  // not vacuous
    // An environment vertex: the direction is the Dirac factor 1.
    CHECK(cam.pdfOrthographicVertex(cam.forward(), 1.0, true) == 1.0);
}

TEST_CASE("Orthographic camera: a crop window restricts sampling and scales the densities", "[camera][crop]") {
    const Camera full = orthoCamera(64, 32);
    const Camera crop = full.withCrop(16, 8, 48, 24);
    CHECK(crop.imagePlaneArea() == Approx(full.imagePlaneArea() / 4.f));
    const Ray inside = full.generateRay(Vec2(20.5f, 10.5f)), outside = full.generateRay(Vec2(4.5f, 4.5f));
    CameraImportanceSample s;
    REQUIRE(crop.sampleWi(inside.origin + inside.dir, &s));
    CHECK(s.We == Approx(4.f / full.imagePlaneArea()));
    CHECK_FALSE(crop.sampleWi(outside.origin + outside.dir, &s));
    CHECK(crop.pdfOrthographicVertex(inside.origin + inside.dir, 1.0, false) == Approx(4.0 / full.imagePlaneArea()));
    CHECK(crop.pdfOrthographicVertex(outside.origin + outside.dir, 1.0, false) == 0.0);
}
