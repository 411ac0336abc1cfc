// Stage-shaped pieces of the unidirectional path tracer (docs/path-tracer.md): the megakernel
// (PathTracer::samplePixel) and the wavefront mode (src/wavefront/) both run a sample as
//   ptBegin, then per bounce: intersect(state.ray) -> ptShade -> [traceShadowRay -> ptAddShadowResult]
// so the estimator is written once. The state is trivially copyable (it lives in wavefront buffers).
#pragma once

#include "bdptref/bdpt.h"
#include "bdptref/integrator.h"
#include "bdptref/scene.h"

namespace bdptref {

struct PtPathState {
    Ray ray{};              // the next ray to trace (valid while `active`)
    Rgb L{0.f}, beta{1.f};  // radiance gathered so far, throughput
    Vec3 prevP{0.f};        // the vertex `ray` left from (MIS of emission found by BSDF sampling)
    float prevBsdfPdf = 0.f;
    int32_t bounce = 0;       // vertices found so far = the depth of the emission found next
    bool deltaBounce = true;  // the camera ray counts as "specular": no other strategy sees Le
    bool active = true;
};
static_assert(std::is_trivially_copyable_v<PtPathState>, "PtPathState lives in wavefront buffers");

// Next-event estimation waiting for its shadow ray: the MIS-weighted contribution if unoccluded.
struct PtShadowRecord {
    ShadowRay ray{};
    Rgb contribution{0.f};
};

// The camera ray through pixel (x, y) (jittered).
PtPathState ptBegin(const Scene& scene, int x, int y, const PixelSampler& sampler);
// The hit of state.ray (null: escaped): emission (MIS-weighted), next-event estimation (returns
// true and fills *nee when a shadow ray must decide it), BSDF sampling and Russian roulette.
// Clears state.active when the path ends.
bool ptShade(const Scene& scene, const PixelSampler& sampler, const IntegratorSettings& settings, PtPathState& state,
             const SurfaceHit* hit, PtShadowRecord* nee);
inline void ptAddShadowResult(PtPathState& state, const PtShadowRecord& nee, bool unoccluded) {
    if (unoccluded) state.L += nee.contribution;
}

}  // namespace bdptref
