// The light tree's importance (formula I of docs/lights.md) for the four children of a node at
// once (`importance4`): the same float operations in the same order as the scalar
// `lightImportance`, one SSE lane per child, so every lane equals lightImportance of that child
// bit for bit (tests/unit/test_light_tree.cpp). Internal to src/scene/light_tree.cpp.
#pragma once

#include "bdptref/light_tree.h"

#include <cmath>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace bdptref::lighttree_detail {

// Four floats with the few operations formula I needs; min/max/select mirror std::min/std::max
// (`a < b ? b : a`) so that the lanes round and order exactly as the scalar code.
#if defined(__SSE2__)
struct F4 {
    __m128 v;
    static F4 load(const float* p) { return F4{_mm_loadu_ps(p)}; }
    static F4 all(float x) { return F4{_mm_set1_ps(x)}; }
    void store(float* p) const { _mm_storeu_ps(p, v); }
};
using M4 = F4;  // lane masks: all bits set where true
inline F4 operator+(F4 a, F4 b) { return F4{_mm_add_ps(a.v, b.v)}; }
inline F4 operator-(F4 a, F4 b) { return F4{_mm_sub_ps(a.v, b.v)}; }
inline F4 operator*(F4 a, F4 b) { return F4{_mm_mul_ps(a.v, b.v)}; }
inline F4 operator/(F4 a, F4 b) { return F4{_mm_div_ps(a.v, b.v)}; }
inline M4 operator<(F4 a, F4 b) { return M4{_mm_cmplt_ps(a.v, b.v)}; }
inline M4 operator>(F4 a, F4 b) { return M4{_mm_cmpgt_ps(a.v, b.v)}; }
inline M4 operator<=(F4 a, F4 b) { return M4{_mm_cmple_ps(a.v, b.v)}; }
inline M4 operator|(M4 a, M4 b) { return M4{_mm_or_ps(a.v, b.v)}; }
inline F4 select(M4 m, F4 a, F4 b) { return F4{_mm_or_ps(_mm_and_ps(m.v, a.v), _mm_andnot_ps(m.v, b.v))}; }
inline F4 sqrt4(F4 a) { return F4{_mm_sqrt_ps(a.v)}; }
inline F4 abs4(F4 a) { return F4{_mm_andnot_ps(_mm_set1_ps(-0.f), a.v)}; }
#else
struct F4 {
    float v[4];
    static F4 load(const float* p) { return F4{{p[0], p[1], p[2], p[3]}}; }
    static F4 all(float x) { return F4{{x, x, x, x}}; }
    void store(float* p) const { for (int k = 0; k < 4; ++k) p[k] = v[k]; }
};
struct M4 {
    bool v[4];
};
#define BDPTREF_LANES(expr) \
    for (int k = 0; k < 4; ++k) r.v[k] = (expr);
inline F4 operator+(F4 a, F4 b) { F4 r; BDPTREF_LANES(a.v[k] + b.v[k]) return r; }
inline F4 operator-(F4 a, F4 b) { F4 r; BDPTREF_LANES(a.v[k] - b.v[k]) return r; }
inline F4 operator*(F4 a, F4 b) { F4 r; BDPTREF_LANES(a.v[k] * b.v[k]) return r; }
inline F4 operator/(F4 a, F4 b) { F4 r; BDPTREF_LANES(a.v[k] / b.v[k]) return r; }
inline M4 operator<(F4 a, F4 b) { M4 r; BDPTREF_LANES(a.v[k] < b.v[k]) return r; }
inline M4 operator>(F4 a, F4 b) { M4 r; BDPTREF_LANES(a.v[k] > b.v[k]) return r; }
inline M4 operator<=(F4 a, F4 b) { M4 r; BDPTREF_LANES(a.v[k] <= b.v[k]) return r; }
inline M4 operator|(M4 a, M4 b) { M4 r; BDPTREF_LANES(a.v[k] || b.v[k]) return r; }
inline F4 select(M4 m, F4 a, F4 b) { F4 r; BDPTREF_LANES(m.v[k] ? a.v[k] : b.v[k]) return r; }
inline F4 sqrt4(F4 a) { F4 r; BDPTREF_LANES(std::sqrt(a.v[k])) return r; }
inline F4 abs4(F4 a) { F4 r; BDPTREF_LANES(std::abs(a.v[k])) return r; }
#undef BDPTREF_LANES
#endif
inline F4 max4(F4 a, F4 b) { return select(a < b, b, a); }  // std::max(a, b)
inline F4 min4(F4 a, F4 b) { return select(b < a, b, a); }  // std::min(a, b)
inline F4 safeSqrt4(F4 a) { return sqrt4(max4(F4::all(0.f), a)); }
inline F4 clampCos4(F4 c) { return min4(F4::all(1.f), max4(F4::all(-1.f), c)); }
// cos(max(0, A - B)) and sin(max(0, A - B)) from the sines and cosines of A and B.
inline F4 cosSubClamped4(F4 sinA, F4 cosA, F4 sinB, F4 cosB) { return select(cosA > cosB, F4::all(1.f), cosA * cosB + sinA * sinB); }
inline F4 sinSubClamped4(F4 sinA, F4 cosA, F4 sinB, F4 cosB) { return select(cosA > cosB, F4::all(0.f), sinA * cosB - cosA * sinB); }
inline F4 dot4(F4 ax, F4 ay, F4 az, F4 bx, F4 by, F4 bz) { return ax * bx + ay * by + az * bz; }  // glm::dot's order

// The shading point, broadcast once per walk.
struct Query4 {
    F4 px, py, pz, nx, ny, nz;
    bool hasNormal;
    F4 lenN;  // |n|
    Query4(const Vec3& p, const Vec3& n)
        : px(F4::all(p.x)), py(F4::all(p.y)), pz(F4::all(p.z)), nx(F4::all(n.x)), ny(F4::all(n.y)), nz(F4::all(n.z)),
          hasNormal(glm::dot(n, n) > 0.f), lenN(F4::all(std::sqrt(glm::dot(n, n)))) {}
};

// Formula I for the node's four lanes (empty lanes have phi = 0 and get 0), as lightImportance.
inline void importance4(const LightTree::Node& b, const Query4& q, float out[4]) {
    const F4 zero = F4::all(0.f), one = F4::all(1.f);
    const F4 tx = q.px - F4::load(b.centreX), ty = q.py - F4::load(b.centreY), tz = q.pz - F4::load(b.centreZ);
    const F4 r2 = F4::load(b.radius2);
    const F4 d2Centre = dot4(tx, ty, tz, tx, ty, tz);
    const F4 d2 = max4(max4(d2Centre, r2), F4::all(1e-20f));
    const M4 away = zero < d2Centre;
    const F4 invD = select(away, one / sqrt4(d2Centre), zero);
    const F4 cosWSigned = select(away, clampCos4(dot4(F4::load(b.wX), F4::load(b.wY), F4::load(b.wZ), tx, ty, tz) * invD), one);
    const F4 cosW = select(F4::load(b.twoSided) > zero, abs4(cosWSigned), cosWSigned);
    const F4 sinW = safeSqrt4(one - cosW * cosW);
    const M4 inside = d2Centre <= r2;
    const F4 sin2B = select(inside, zero, r2 / d2Centre);
    const F4 cosB = select(inside, F4::all(-1.f), safeSqrt4(one - sin2B)), sinB = select(inside, zero, sqrt4(sin2B));
    const F4 cosO = F4::load(b.cosTheta_o), sinO = F4::load(b.sinTheta_o);
    const F4 cosX = cosSubClamped4(sinW, cosW, sinO, cosO), sinX = sinSubClamped4(sinW, cosW, sinO, cosO);
    const F4 cosP = cosSubClamped4(sinX, cosX, sinB, cosB);
    const F4 phi = F4::load(b.phi);
    const M4 culled = (cosP <= F4::load(b.cosTheta_e)) | (phi <= zero);  // also !(phi > 0) for NaN-free phi
    F4 importance = phi * cosP / d2;
    if (q.hasNormal) {
        const F4 cosI = clampCos4(abs4(dot4(tx, ty, tz, q.nx, q.ny, q.nz)) * invD / q.lenN);
        const F4 factor = cosSubClamped4(safeSqrt4(one - cosI * cosI), cosI, sinB, cosB);
        importance = select(away, importance * factor, importance);
    }
    select(culled, zero, max4(importance, zero)).store(out);
}

}  // namespace bdptref::lighttree_detail
