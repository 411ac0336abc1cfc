// The witness scenes (scenes/witnesses/, docs/validating-a-gpu-port.md "Witnesses: settling a
// difference"): closed-form answers, known without either renderer, that settled bdptref's
// differences with Blender Cycles. bdptref must render them right, at a precision that would see
// the other renderer's error: each check is |estimate - exact| <= k sigma with k = 5, sigma the
// standard error of the estimate from the same run (the film's variance of the mean, pixels
// independent), and sigma small enough that the measured Cycles error would exceed k sigma.
#include "support/render_util.h"

#include <catch2/catch.hpp>

#include <cmath>

using namespace bdptref;
using namespace bdptref::test;

namespace {
constexpr double kSigmas = 5.0;

// Lambert's polygon formula: the radiance leaving a Lambert point p (normal n, albedo rho) lit by
// a polygon of radiance Le, rho Le / (2 pi) |sum_i theta_i n . u_i| (theta_i the angle edge i
// subtends at p, u_i the unit normal of the plane through p and the edge).
double polygonRadiance(const DVec3& p, const DVec3& n, const DVec3* v, int count, double rho, double le) {
    double sum = 0.0;
    for (int i = 0; i < count; ++i) {
        const DVec3 a = glm::normalize(v[i] - p), b = glm::normalize(v[(i + 1) % count] - p);
        const DVec3 c = glm::cross(a, b);
        const double len = glm::length(c);
        if (len > 0.0) sum += std::atan2(len, glm::dot(a, b)) * glm::dot(c, n) / len;
    }
    return rho * le / (2.0 * kPi) * std::abs(sum);
}

// scenes/witnesses/generate.py, light_in_ceiling: the Cornell box's light (x 213..343, z 227..332
// at y 548.8, radiance 1) seen by the wall x = 0 (albedo 0.5) through an orthographic camera at
// (100, 448.8, 279.5) looking along -x (right = -z, up = +y), xmag = ymag = 100; every length times
// `unit`. The pixel's value is the radiance averaged over its footprint (q x q midpoints).
double lightWallPixel(int x, int y, int width, int height, double unit) {
    const DVec3 light[4] = {DVec3(213, 548.8, 227) * unit, DVec3(343, 548.8, 227) * unit,
                            DVec3(343, 548.8, 332) * unit, DVec3(213, 548.8, 332) * unit};
    const double ymag = 100.0 * unit, xmag = ymag * width / height, cy = 448.8 * unit, cz = 279.5 * unit;
    constexpr int q = 16;
    double sum = 0.0;
    for (int j = 0; j < q; ++j)
        for (int i = 0; i < q; ++i) {
            const double rx = x + (i + 0.5) / q, ry = y + (j + 0.5) / q;
            const DVec3 p(0.0, cy + (1.0 - 2.0 * ry / height) * ymag, cz - (2.0 * rx / width - 1.0) * xmag);
            sum += polygonRadiance(p, DVec3(1, 0, 0), light, 4, 0.5, 1.0);
        }
    return sum / (q * q);
}

struct Estimate {
    double value = 0, exact = 0, sigma = 0;
};

// The mean over pixels [0, w) x [y0, y1) of the film (green channel; the scene is grey) against the
// closed form, with the film's standard error of that mean.
Estimate rows(const Film& film, int width, int height, int y0, int y1, double unit) {
    Estimate e;
    int n = 0;
    for (int y = y0; y < y1; ++y)
        for (int x = 0; x < width; ++x) {
            e.value += film.mean(x, y)[1];
            e.sigma += film.varianceOfMean(x, y)[1];
            e.exact += lightWallPixel(x, y, width, height, unit);
            ++n;
        }
    e.value /= n;
    e.exact /= n;
    e.sigma = std::sqrt(e.sigma) / n;
    return e;
}
}  // namespace

TEST_CASE("Witness: a light in a hole of the ceiling seen at grazing angles (Lambert's polygon formula)",
          "[witness][pt]") {
    // Cycles 3.4 renders this -0.95% (rows under the ceiling -2% ... -4%) in these units and right
    // in metres (the -m file): docs/validating-a-gpu-port.md. bdptref must be right in both, and
    // tell a 1% error from noise over the image and a 2% error over the four top rows.
    const int w = 16, h = 16;
    for (const char* file : {"scenes/witnesses/hole-light-wall.gltf", "scenes/witnesses/hole-light-wall-m.gltf",
                             "scenes/witnesses/open-light-wall.gltf"}) {
        const double unit = std::string(file).find("-m.gltf") != std::string::npos ? 0.001 : 1.0;
        DYNAMIC_SECTION(file) {
            const Film film = renderFilm(loadTestScene(file, w, h), "path", 512, 1, 29);
            const Estimate all = rows(film, w, h, 0, h, unit);
            INFO("image: " << all.value << " +- " << all.sigma << ", exact " << all.exact);
            CHECK(std::abs(all.value - all.exact) <= kSigmas * all.sigma);
            CHECK(kSigmas * all.sigma < 0.005 * all.exact);
            for (int y = 0; y < 4; ++y) {  // grazing: the light is within 2.5 degrees of these rows' plane
                const Estimate r = rows(film, w, h, y, y + 1, unit);
                INFO("row " << y << ": " << r.value << " +- " << r.sigma << ", exact " << r.exact);
                CHECK(std::abs(r.value - r.exact) <= kSigmas * r.sigma);
            }
            const Estimate band = rows(film, w, h, 0, 4, unit);  // Cycles in mm: -3% here
            INFO("rows 0-3: " << band.value << " +- " << band.sigma << ", exact " << band.exact);
            CHECK(std::abs(band.value - band.exact) <= kSigmas * band.sigma);
            CHECK(kSigmas * band.sigma < 0.02 * band.exact);
        }
    }
}

TEST_CASE("Witness: a closed emitting box of albedo 0.999 at depth 16 gives (1 - rho^17) / (1 - rho)",
          "[witness][pt]") {
    // white-box.gltf's albedo with the light everywhere: Cycles 3.4 renders it +0.15% (its Russian
    // roulette with the default sampling pattern); bdptref must be right to better than that.
    const Scene scene = loadTestScene("scenes/witnesses/white-emitting-box.gltf", 16, 16);
    const double rho = 0.999, exact = (1.0 - std::pow(rho, 17)) / (1.0 - rho);
    const PooledMean m = pooledMean(renderFilm(scene, "path", 768, 16, 31));
    for (int c = 0; c < 3; ++c) {
        INFO("channel " << c << ": " << m.mean[c] << " +- " << m.standardError[c] << ", exact " << exact);
        CHECK(std::abs(m.mean[c] - exact) <= kSigmas * m.standardError[c]);
        CHECK(kSigmas * m.standardError[c] < 0.0014 * exact);
    }
}
