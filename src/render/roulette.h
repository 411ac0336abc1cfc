// Russian roulette: one policy for every estimator (PT, LT, BDPT's two subpaths, the wavefront
// mode), docs/path-tracer.md "Russian roulette". From the third bounce on (rouletteStartDepth),
// after sampling a vertex's BSDF, the walk survives with probability
//     q = max(0.05, min(1, max_c beta_c / max_c beta0_c))
// where beta is the throughput after the bounce and beta0 the throughput the walk started with
// (1 on camera paths; Le cos / (pmf pdfPos pdfDir) on light subpaths, which is why the raw
// throughput cannot be used there: it is in units of power and would almost never be < 1).
// Survivors are divided by q (unbiased). Once roulette has started, a survivor's normalised
// throughput is 1 (unless q hit a bound), so q is in effect the last bounce's f cos / pdf: the
// walk stops where the scene absorbs, and rays go where they still carry energy.
// Roulette is not part of any MIS density (docs/mis.md).
#pragma once

#include "bdptref/math.h"

#include <algorithm>
#include <cmath>

namespace bdptref {

constexpr float kRouletteFloor = 0.05f;  // bounds the survivors' weight 1/q by 20

// `startScale` = 1 / max_c beta0_c (0 when beta0 is black or not finite: q is then the floor).
inline float rouletteSurvival(const Rgb& beta, float startScale) {
    return std::max(kRouletteFloor, std::min(1.f, maxComponent(beta) * startScale));
}

inline float rouletteStartScale(const Rgb& beta0) {
    const float m = maxComponent(beta0);
    return m > 0.f && std::isfinite(m) ? 1.f / m : 0.f;
}

}  // namespace bdptref
