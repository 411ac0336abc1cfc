// Charlie D and Lambda and the albedo quadrature (sheen_quadrature.h). Moved verbatim from
// bsdf_sheen.cpp: the generated table must be bit-identical to the one once computed at run time.
#include "sheen_quadrature.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>

namespace bdptref {
namespace bsdf_detail {

namespace {
// bsdf_terms.h's kPiD, not included: the generator is built without the library's headers.
constexpr double kPi = 3.14159265358979323846;

// The extension's fit l(x) of log Lambda, interpolated in (1 - alpha)^2.
double charlieL(double x, double alpha) {
    const double t = (1.0 - alpha) * (1.0 - alpha);
    auto mix = [t](double a, double b) { return a * (1.0 - t) + b * t; };
    const double a = mix(21.5473, 25.3245), b = mix(3.82987, 3.32435), c = mix(0.19823, 0.16801);
    const double d = mix(-1.97760, -1.27393), e = mix(-4.32054, -4.85967);
    return a / (1.0 + b * std::pow(x, c)) + d * x + e;
}
}  // namespace

double charlieD(double cosH, double alpha) {
    const double sin2 = std::max(0.0, 1.0 - cosH * cosH);
    return (2.0 + 1.0 / alpha) * std::pow(sin2, 0.5 / alpha) / (2.0 * kPi);
}

double charlieLambda(double cosTheta, double alpha) {
    const double c = std::abs(cosTheta);
    return c < 0.5 ? std::exp(charlieL(c, alpha)) : std::exp(2.0 * charlieL(0.5, alpha) - charlieL(1.0 - c, alpha));
}

// Over l in (theta, phi), phi in [0, pi] doubled by the symmetry about the plane of v: 96 x 48
// cells (the lobe is at least ~0.14 rad wide).
double albedoQuadrature(double mu, double roughness) {
    const double alpha = roughness * roughness;
    const glm::dvec3 v(std::sqrt(std::max(0.0, 1.0 - mu * mu)), 0.0, mu);
    const int nt = 96, np = 48;
    const double lambdaV = charlieLambda(mu, alpha);
    double sum = 0.0;
    for (int i = 0; i < nt; ++i) {
        const double theta = 0.5 * kPi * (i + 0.5) / nt, cosT = std::cos(theta), sinT = std::sin(theta);
        const double vis = 1.0 / ((1.0 + lambdaV + charlieLambda(cosT, alpha)) * 4.0 * mu * cosT);
        for (int k = 0; k < np; ++k) {
            const double phi = kPi * (k + 0.5) / np;
            const glm::dvec3 l(sinT * std::cos(phi), sinT * std::sin(phi), cosT);
            sum += charlieD(glm::normalize(v + l).z, alpha) * vis * cosT * sinT;
        }
    }
    return 2.0 * sum * (0.5 * kPi / nt) * (kPi / np);
}

}  // namespace bsdf_detail
}  // namespace bdptref
