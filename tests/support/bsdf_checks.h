// Helpers shared by the BSDF unit tests (test_bsdf.cpp, test_clearcoat.cpp, test_sheen.cpp):
// outgoing directions about a shading normal, RGB comparison, the adjoint shading-normal factor
// and the chi-square test of a Bsdf's non-delta sampling against its pdf().
#pragma once

#include "bdptref/bsdf.h"
#include "support/chi2.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <string>

// Catch's REQUIRE and INFO cost about a microsecond each (INFO formats eagerly); the loops of the
// BSDF tests make millions of checks, so a condition goes through Catch only when it fails.
#define REQUIRE_QUIET(cond, msg) \
    do {                         \
        if (!(cond)) {           \
            INFO(msg);           \
            REQUIRE((cond));     \
        }                        \
    } while (false)

namespace bdptref::test {

// The direction at polar angle thetaDeg from ns (0 = along it), azimuth 200 degrees in its frame.
inline Vec3 woAtAngle(const Vec3& ns, float thetaDeg) {
    if (thetaDeg == 0.f) return ns;
    const float t = thetaDeg * kPi / 180.f, ph = 200.f * kPi / 180.f;
    return glm::normalize(Frame(ns).toWorld(Vec3(std::sin(t) * std::cos(ph), std::sin(t) * std::sin(ph), std::cos(t))));
}

// |a - b| <= rel |b| + absTol per channel.
inline bool closeRgb(const Rgb& a, const Rgb& b, float rel, float absTol) {
    for (int i = 0; i < 3; ++i)
        if (!(std::abs(a[i] - b[i]) <= rel * std::abs(b[i]) + absTol)) return false;
    return true;
}

inline std::string str(const Rgb& c) {
    return "(" + std::to_string(c.r) + ", " + std::to_string(c.g) + ", " + std::to_string(c.b) + ")";
}

// Veach's adjoint factor |wo.ns||wi.ng| / (|wo.ng||wi.ns|), in double.
inline double adjointFactorOf(const Vec3& wo, const Vec3& wi, const Vec3& ns, const Vec3& ng) {
    return double(absDot(wo, ns)) * absDot(wi, ng) / (double(absDot(wo, ng)) * absDot(wi, ns));
}

// Chi-square test of b.sample() (Radiance mode, non-delta samples; delta and failed samples are the
// lost cell) against b.pdf() for one wo, with `n` samples drawn from TestRng(seed, i).
inline Chi2Result bsdfSamplingChi2(const Bsdf& b, const Vec3& wo, const DirectionBinning& bins, uint64_t seed, uint64_t n) {
    return chi2DirectionTest(
        [&](uint64_t i, Vec3* d) {
            TestRng rng(seed, i);
            const float uLobe = rng.uniform();
            const Vec2 u = rng.uniform2D();
            BsdfSample s;
            if (!b.sample(wo, uLobe, u, TransportMode::Radiance, &s) || s.delta) return false;
            *d = s.wi;
            return true;
        },
        [&](const Vec3& d) { return double(b.pdf(wo, d)); }, n, bins);
}

}  // namespace bdptref::test
