// Stage-shaped pieces of the unidirectional path tracer (docs/path-tracer.md): the megakernel
// (PathTracer::samplePixel) and the wavefront mode (src/wavefront/) both run a sample as
//   ptBegin, then per bounce: intersect(state.ray) -> ptShade -> [traceShadowRay -> ptAddShadowResult]
// so the estimator is written once. The state is trivially copyable (it lives in wavefront buffers).
#pragma once

#include "bdptref/bdpt.h"
#include "bdptref/integrator.h"
#include "bdptref/scene.h"

#include <vector>

namespace bdptref {

struct PtPathState {
    Ray ray{};              // the next ray to trace (valid while `active`)
    Rgb L{0.f}, beta{1.f};  // radiance gathered so far, throughput
    Vec3 prevP{0.f};        // the vertex `ray` left from (MIS of emission found by BSDF sampling)
    Vec3 prevNg{0.f};       // its geometric normal (zero: the camera), and below its material:
    uint32_t prevMaterial = 0;  // the medium rule of segmentTransmittance (docs/materials.md)
    float prevBsdfPdf = 0.f;
    int32_t bounce = 0;       // vertices found so far = the depth of the emission found next
    bool deltaBounce = true;  // the camera ray counts as "specular": no other strategy sees Le
    bool active = true;
};
static_assert(std::is_trivially_copyable_v<PtPathState>, "PtPathState lives in wavefront buffers");

// Next-event estimation waiting for its shadow ray: the MIS-weighted contribution if unoccluded,
// and the same without its MIS weight (the strategy layer s = 1, --strategies).
struct PtShadowRecord {
    ShadowRay ray{};
    Rgb contribution{0.f}, unweighted{0.f};
    int32_t depth = 0;  // of the path it completes: the shading vertex's bounce + 1
};

// What ptShade computed at one hit (or escape), for `bdptref trace --integrator path`
// (src/verify/trace_path.cpp). Only filled when a PtTrace is passed: the renderer passes none.
struct PtBounceRecord {
    int bounce = 0;           // vertices found before this one (0: the camera ray's hit)
    Ray ray{};                // the ray that found it
    bool escaped = false;     // no hit: the environment (if any) was looked up
    SurfaceHit hit{};         // when !escaped
    Rgb betaIn{1.f};          // throughput arriving here (the ray's transmittance included)
    Rgb transmittance{1.f};   // volume absorption along the ray (segmentTransmittance)
    // Emission found by this ray (BSDF sampling's strategy, path depth = bounce).
    bool emission = false;
    Rgb Le{0.f};
    float emissionBsdfPdf = 0.f, emissionLightPdf = 0.f;  // solid angle at the previous vertex; light pdf = pmf x pdfLi
    float emissionWeight = 1.f;                           // 1 after a delta bounce (the camera ray counts as one)
    Rgb emissionAdded{0.f};
    bool depthLimit = false;  // bounce >= maxDepth: nothing further is sampled
    // Next-event estimation (path depth = bounce + 1).
    bool neeTried = false;    // the BSDF has a non-delta lobe, so the two numbers below were drawn
    float uNeeLight = 0.f;
    Vec2 uNeePosition{0.f};
    int neeLight = -1;        // the chosen light (-1: none)
    float neePmf = 0.f;
    bool neeSampled = false;  // sampleLi succeeded
    LightLiSample nee{};
    Rgb neeFCos{0.f};         // f(wo, wi) |cos(wi, ns)|
    Rgb neeTransmittance{1.f};  // volume absorption along the shadow segment
    float neeBsdfPdf = 0.f, neeWeight = 0.f;
    bool neeShadowRay = false;  // a contribution waits for its shadow ray
    Rgb neeContribution{0.f};   // added if the shadow ray is unoccluded
    bool neeUnoccluded = false; // filled in by the caller that traces the shadow ray
    // BSDF sampling (the next ray).
    bool bsdfDrawn = false;
    float uBsdfLobe = 0.f;
    Vec2 uBsdfDirection{0.f};
    bool bsdfSampled = false;  // a direction with pdf > 0 and f != 0
    BsdfSample bsdf{};
    Rgb betaOut{0.f};          // throughput after the bounce (before roulette)
    // Russian roulette after the bounce.
    bool rouletteTested = false;
    float survive = 1.f, uRoulette = 0.f;
    bool survived = true;
    bool continues = false;    // the path goes on to bounce + 1
};
struct PtTrace {
    std::vector<PtBounceRecord> bounces;
};

// One sample's sums at one path depth, by strategy (--depth-layers, --strategies): the emission
// found by BSDF sampling (BDPT's strategy s = 0, t = depth + 2) and next-event estimation (s = 1,
// t = depth + 1), each as added to the image (MIS-weighted) and unweighted. A path has one vertex
// per bounce, so each depth receives at most one of each. Unweighted, each is an estimator of the
// whole depth layer on its own where it can sample every path (docs/validate.md, "Strategy classes").
struct PtDepthSums {
    Rgb hit{0.f}, hitUnweighted{0.f}, nee{0.f}, neeUnweighted{0.f};
};

// The camera ray through pixel (x, y) (jittered).
PtPathState ptBegin(const Scene& scene, int x, int y, const PixelSampler& sampler);
// The hit of state.ray (null: escaped): emission (MIS-weighted), next-event estimation (returns
// true and fills *nee when a shadow ray must decide it), BSDF sampling and Russian roulette.
// Clears state.active when the path ends.
// `trace` (optional) receives a PtBounceRecord of what was computed. `depthL` (optional, per-depth
// and per-strategy layers): settings.maxDepth + 1 sums, one per path depth; the emission found here
// is added to depthL[bounce] as well as to state.L.
bool ptShade(const Scene& scene, const PixelSampler& sampler, const IntegratorSettings& settings, PtPathState& state,
             const SurfaceHit* hit, PtShadowRecord* nee, PtTrace* trace = nullptr, PtDepthSums* depthL = nullptr);
inline void ptAddShadowResult(PtPathState& state, const PtShadowRecord& nee, bool unoccluded, PtDepthSums* depthL = nullptr) {
    if (!unoccluded) return;
    state.L += nee.contribution;
    if (!depthL) return;
    depthL[nee.depth].nee += nee.contribution;
    depthL[nee.depth].neeUnweighted += nee.unweighted;
}

// The per-depth sums of one finished sample (depthL of ptShade) as depth records, in depth order;
// depths that received nothing are left out. Megakernel and wavefront both call it. The next event
// is added first, as it was computed first (at the previous vertex): the sum is the one state.L saw.
template <class Push>
void ptForEachDepth(const PtDepthSums* depthL, int maxDepth, Push&& push) {
    for (int d = 0; d <= maxDepth; ++d) {
        const Rgb sum = depthL[d].nee + depthL[d].hit;
        if (!(sum == Rgb(0.f))) push(DepthContribution{d, sum, false, Vec2(0.f)});
    }
}

// The same sums as strategy records (s = 0 for the emission found, s = 1 for the next event), in
// depth order, emission first; strategies that received nothing are left out.
template <class Push>
void ptForEachStrategy(const PtDepthSums* depthL, int maxDepth, Push&& push) {
    for (int d = 0; d <= maxDepth; ++d) {
        const PtDepthSums& a = depthL[d];
        if (!(a.hit == Rgb(0.f) && a.hitUnweighted == Rgb(0.f)))
            push(StrategyContribution{0, d + 2, a.hit, a.hitUnweighted, false, Vec2(0.f)});
        if (!(a.nee == Rgb(0.f) && a.neeUnweighted == Rgb(0.f)))
            push(StrategyContribution{1, d + 1, a.nee, a.neeUnweighted, false, Vec2(0.f)});
    }
}

}  // namespace bdptref
