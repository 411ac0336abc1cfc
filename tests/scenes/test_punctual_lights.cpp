// Point, spot and directional lights rendered by the path tracer over a Lambertian plane, against
// the closed form L(x) = rho/pi * E(x) with E the irradiance the light gives at x (direct light
// only exists: the plane is alone, so every path beyond depth 1 escapes). The expected value of a
// pixel is the average of L over the pixel's footprint (box filter), computed by a 16x16 midpoint
// rule; its error is estimated as |Q16 - Q8|. Each pixel must agree within 5 sigma plus that
// quadrature error, where sigma is the larger of the pixel's standard error from the run and the
// exact one, sqrt(Var_footprint(L) / n): the jitter is the only randomness here, and a pixel the
// cone edge barely touches can have all its samples miss the lit part (run estimate 0).
#include "bdptref/gltf_loader.h"
#include "support/gltf_builder.h"
#include "support/render_util.h"

#include <catch2/catch.hpp>

using namespace bdptref;
using namespace bdptref::test;

namespace {

constexpr float kRho = 0.5f;
constexpr int kSize = 24;

// A 20x20 plane at y = 0 facing +y, pure Lambert (KHR_materials_specular 0), plus one light node.
std::string writePlaneScene(const std::string& name, const json& light, const json& lightNode) {
    Doc d;
    d.use("KHR_materials_specular");
    d.use("KHR_lights_punctual");
    const int pos = d.floats({-10, 0, -10, -10, 0, 10, 10, 0, 10, 10, 0, -10}, "VEC3");
    const int nrm = d.floats({0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0}, "VEC3");
    const int idx = d.indices(std::vector<uint16_t>{0, 1, 2, 0, 2, 3});
    const int mat = d.material({{"pbrMetallicRoughness", {{"baseColorFactor", {kRho, kRho, kRho, 1}}, {"metallicFactor", 0}, {"roughnessFactor", 1}}},
                                {"extensions", {{"KHR_materials_specular", {{"specularFactor", 0}}}}}});
    d.node({{"mesh", d.mesh(Doc::prim(pos, idx, nrm, -1, 4, mat))}});
    d.j["extensions"]["KHR_lights_punctual"]["lights"] = json::array({light});
    json n = lightNode;
    n["extensions"]["KHR_lights_punctual"]["light"] = 0;
    d.node(n);
    return d.write(name);
}

Scene loadPlane(const std::string& path) {
    LoadOptions o;
    o.width = kSize;
    o.height = kSize;
    Scene s = loadGltfScene(path, o);
    s.camera = Camera::lookAt(Vec3(0.3f, 3.f, 0.2f), Vec3(0.3f, 0.f, 0.2f), Vec3(0, 0, -1), 1.2f, kSize, kSize);
    s.finalize();
    return s;
}

// Radiance seen through raster position r: rho/pi * irradiance(point on the plane).
template <class Irradiance>
double radianceAt(const Scene& s, Vec2 r, Irradiance E) {
    const Ray ray = s.camera.generateRay(r);
    const DVec3 o = s.toWorld(ray.origin);  // the camera ray is in render space; the plane and E in world
    const double t = -o.y / double(ray.dir.y);
    const DVec3 x = o + t * DVec3(ray.dir);
    return double(kRho) / double(kPi) * E(x);
}

// Mean and mean square of L over the pixel footprint (midpoint rule, n x n).
template <class Irradiance>
std::pair<double, double> pixelMoments(const Scene& s, int px, int py, int n, Irradiance E) {
    double sum = 0, sum2 = 0;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const double L = radianceAt(s, Vec2(px + (i + 0.5f) / n, py + (j + 0.5f) / n), E);
            sum += L;
            sum2 += L * L;
        }
    return {sum / (n * n), sum2 / (n * n)};
}

template <class Irradiance>
void checkAgainstClosedForm(const Scene& s, Irradiance E) {
    constexpr int kSpp = 64;
    for (int depth : {1, 8}) {
        const Film film = renderFilm(s, "path", kSpp, depth, 41);
        int bad = 0;
        double largest = 0;
        for (int y = 0; y < kSize; ++y)
            for (int x = 0; x < kSize; ++x) {
                const auto [q16, m2] = pixelMoments(s, x, y, 16, E);
                const double q8 = pixelMoments(s, x, y, 8, E).first;
                const double exactSe = std::sqrt(std::max(0.0, m2 - q16 * q16) / kSpp);
                const double mean = film.mean(x, y).g, se = std::max(exactSe, std::sqrt(film.varianceOfMean(x, y).g));
                const double tol = 5.0 * se + std::abs(q16 - q8) + 1e-6 * q16;
                if (std::abs(mean - q16) > tol) {
                    ++bad;
                    INFO("pixel " << x << "," << y << ": " << mean << " +- " << se << " vs " << q16);
                    CHECK(std::abs(mean - q16) <= tol);
                }
                largest = std::max(largest, q16);
            }
        CHECK(bad == 0);
        CHECK(largest > 0.01);  // the light reaches the image: the comparison is not vacuous
    }
}

}  // namespace

TEST_CASE("Directional light: a Lambertian plane shows rho E cos(theta) / pi everywhere", "[lights][render]") {
    // Node rotated 30 degrees about x: the light travels along R(-z).
    const float a = glm::radians(30.f);
    const json light = {{"type", "directional"}, {"color", {1, 1, 1}}, {"intensity", 2.0}};
    // Quaternion for -(90 - 30) degrees about x turns -z towards -y, 30 degrees off vertical.
    const float h = 0.5f * -(glm::radians(90.f) - a);
    const Scene s = loadPlane(writePlaneScene("directional.gltf", light, {{"rotation", {std::sin(h), 0, 0, std::cos(h)}}}));
    REQUIRE(s.lights.size() == 1);
    CHECK(s.lights[0].type == LightType::Directional);
    CHECK(-s.lights[0].direction.y == Approx(std::cos(a)).epsilon(1e-5));
    checkAgainstClosedForm(s, [&](const DVec3&) { return 2.0 * std::cos(double(a)); });
}

TEST_CASE("Point light: rho/pi * I cos / d^2 over a plane", "[lights][render]") {
    const json light = {{"type", "point"}, {"color", {1, 1, 1}}, {"intensity", 3.0}};
    const DVec3 lp(1.0, 2.0, 0.5);
    const Scene s = loadPlane(writePlaneScene("point.gltf", light, {{"translation", {lp.x, lp.y, lp.z}}}));
    checkAgainstClosedForm(s, [&](const DVec3& x) {
        const DVec3 d = lp - x;
        const double d2 = glm::dot(d, d);
        return 3.0 * (d.y / std::sqrt(d2)) / d2;
    });
}

TEST_CASE("Spot light: the glTF cone falloff over a plane", "[lights][render]") {
    const double inner = 0.2, outer = 0.5;
    const json light = {{"type", "spot"}, {"color", {1, 1, 1}}, {"intensity", 3.0}, {"spot", {{"innerConeAngle", inner}, {"outerConeAngle", outer}}}};
    const DVec3 lp(0.2, 1.5, 0.0);
    const float h = 0.5f * -glm::radians(90.f);  // -z -> -y: pointing straight down
    const Scene s = loadPlane(writePlaneScene("spot.gltf", light, {{"translation", {lp.x, lp.y, lp.z}}, {"rotation", {std::sin(h), 0, 0, std::cos(h)}}}));
    checkAgainstClosedForm(s, [&](const DVec3& x) {
        const DVec3 d = lp - x;
        const double d2 = glm::dot(d, d), cosAxis = d.y / std::sqrt(d2);
        // glTF's recommended falloff: clamp(cos * scale + offset, 0, 1)^2.
        const double scale = 1.0 / std::max(0.001, std::cos(inner) - std::cos(outer));
        const double f = std::clamp(cosAxis * scale - std::cos(outer) * scale, 0.0, 1.0);
        return 3.0 * f * f * cosAxis / d2;
    });
}
