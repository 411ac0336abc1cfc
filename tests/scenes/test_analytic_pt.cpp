// The path tracer on scenes with closed-form answers (scenes/README.md). Each check is
// |estimate - exact| < k*sigma with k = 5, sigma the standard error of the pooled mean from the
// same run, and sigma < 0.3% of the value so that a 1% bug cannot hide inside the tolerance.
#include "support/render_util.h"

#include <catch2/catch.hpp>

using namespace bdptref;
using namespace bdptref::test;

namespace {
constexpr double kSigmas = 5.0;
constexpr double kMaxRelativeSigma = 0.003;

void checkGrey(const PooledMean& m, double exact) {
    for (int c = 0; c < 3; ++c) {
        INFO("channel " << c << ": estimate " << m.mean[c] << " +- " << m.standardError[c] << ", exact " << exact
                        << " (" << m.samples << " samples)");
        CHECK(std::abs(m.mean[c] - exact) <= kSigmas * m.standardError[c] + 1e-6 * exact);
        CHECK(m.standardError[c] < kMaxRelativeSigma * exact);
    }
}
}  // namespace

TEST_CASE("PT: closed emitting box of albedo rho gives Le (1 - rho^(N+1)) / (1 - rho)", "[analytic][pt]") {
    const Scene scene = loadTestScene("scenes/furnace-box.gltf", 32, 32);
    const double rho = 0.5, Le = 1.0;
    for (int depth : {0, 1, 2, 5, 64}) {
        DYNAMIC_SECTION("max depth " << depth) {
            const Film film = renderFilm(scene, "path", 64, depth, 17);
            const double exact = Le * (1.0 - std::pow(rho, depth + 1)) / (1.0 - rho);
            const PooledMean m = pooledMean(film);
            if (depth == 0) {
                // Only emission seen directly: deterministic, exact up to float rounding.
                for (int c = 0; c < 3; ++c) CHECK(m.mean[c] == Approx(exact).epsilon(1e-6));
            } else {
                checkGrey(m, exact);
            }
        }
    }
}

TEST_CASE("PT: point light inside a diffuse sphere", "[analytic][pt]") {
    // Sphere: L = rho I / (pi R^2) * (1 - rho^N) / (1 - rho). The scene is a polyhedron inscribed
    // in the unit sphere, so the answer is an interval, derived from the mesh, not a tolerance:
    // with h_min the smallest distance from the centre to a face plane, the irradiance I cos/d^2
    // anywhere on a face lies in [I h_min, I / h_min^2] (vertices: d = 1, cos = h; foot of the
    // face: d = h). Every further bounce in a closed Lambertian enclosure is rho times a convex
    // average of the previous one (form factors sum to 1), so the depth-N radiance lies in
    // [h_min, 1/h_min^2] times the sphere's value. The estimate must fall inside that interval
    // widened by 5 sigma.
    const Scene scene = loadTestScene("scenes/sphere-point-light.gltf", 32, 32);
    double hMin = 1.0;
    for (const glm::uvec3& t : scene.mesh.indices) {
        const DVec3 a(scene.mesh.positions[t.x]), b(scene.mesh.positions[t.y]), c(scene.mesh.positions[t.z]);
        hMin = std::min(hMin, std::abs(glm::dot(glm::normalize(glm::cross(b - a, c - a)), a)));
    }
    REQUIRE(hMin > 0.999);  // the interval is narrow enough for the test to see a 1% bug
    const double rho = 0.5, I = 1.0, R = 1.0;
    for (int depth : {1, 3, 64}) {
        DYNAMIC_SECTION("max depth " << depth) {
            const PooledMean m = pooledMean(renderFilm(scene, "path", 128, depth, 23));
            const double sphere = rho * I / (double(kPi) * R * R) * (1.0 - std::pow(rho, depth)) / (1.0 - rho);
            const double lo = sphere * hMin, hi = sphere / (hMin * hMin);
            for (int c = 0; c < 3; ++c) {
                INFO("channel " << c << ": " << m.mean[c] << " +- " << m.standardError[c] << ", interval [" << lo << ", " << hi << "]");
                CHECK(m.mean[c] >= lo - kSigmas * m.standardError[c]);
                CHECK(m.mean[c] <= hi + kSigmas * m.standardError[c]);
                CHECK(m.standardError[c] < kMaxRelativeSigma * sphere);
            }
        }
    }
}

TEST_CASE("PT: convex Lambertian object under a constant environment gives rho * L_env", "[analytic][pt]") {
    const Rgb env(0.8f, 1.0f, 1.3f);
    const Scene scene = loadTestScene("scenes/env-sphere.glb", 32, 32, env);
    const double rho = 0.5;
    for (int depth : {1, 64}) {
        DYNAMIC_SECTION("max depth " << depth) {
            const PooledMean m = pooledMean(renderFilm(scene, "path", 64, depth, 29));
            for (int c = 0; c < 3; ++c) {
                const double exact = rho * double(env[c]);
                INFO("channel " << c << ": " << m.mean[c] << " +- " << m.standardError[c] << " exact " << exact);
                CHECK(std::abs(m.mean[c] - exact) <= kSigmas * m.standardError[c]);
                CHECK(m.standardError[c] < kMaxRelativeSigma * exact);
            }
        }
    }
    // Depth 0: the camera sees only the (non-emissive) sphere.
    const PooledMean m0 = pooledMean(renderFilm(scene, "path", 4, 0, 29));
    CHECK(m0.mean == DVec3(0.0));
}
