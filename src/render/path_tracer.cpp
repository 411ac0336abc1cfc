// Unidirectional path tracer with next-event estimation; see docs/path-tracer.md.
#include "bdptref/bsdf.h"
#include "bdptref/errors.h"
#include "bdptref/integrator.h"
#include "bdptref/scene.h"
#include "core/ray_offset.h"
#include "render/light_choice.h"
#include "render/mis.h"
#include "render/roulette.h"
#include "render/path_tracer.h"
#include "render/segment_transmittance.h"

namespace bdptref {

namespace {
// The emission record of a trace: what ptShade added for emission found by the path's ray.
PtBounceRecord recordEmission(PtBounceRecord r, const PtPathState& st, const Rgb& Le, float lightPdf, float w) {
    r.emission = true;
    r.Le = Le;
    r.emissionBsdfPdf = st.deltaBounce ? 0.f : st.prevBsdfPdf;
    r.emissionLightPdf = lightPdf;
    r.emissionWeight = w;
    r.emissionAdded = st.beta * Le * w;
    return r;
}
}  // namespace

PtPathState ptBegin(const Scene& scene, int x, int y, const PixelSampler& sampler) {
    const Vec2 jitter = sampler.get2D(RngStream::Camera, dim::kFilm);
    PtPathState st;
    st.ray = scene.camera.generateRay(Vec2(float(x), float(y)) + jitter);
    st.prevP = st.ray.origin;
    return st;
}

namespace {

// The bounce's trace record (trace only: what is computed here), or nullptr.
PtBounceRecord* beginBounceRecord(PtTrace* trace, const PtPathState& st, const SurfaceHit* hit, const Rgb& T) {
    if (!trace) return nullptr;
    PtBounceRecord* rec = &trace->bounces.emplace_back();
    rec->bounce = st.bounce;
    rec->ray = st.ray;
    rec->escaped = !hit;
    if (hit) rec->hit = *hit;
    rec->betaIn = st.beta;
    rec->transmittance = T;
    return rec;
}

// Emission found by BSDF sampling, into the image and the depth's sums (the strategy s = 0).
void addFoundEmission(PtPathState& st, const Rgb& Le, float w, PtDepthSums* depthL) {
    const Rgb unweighted = st.beta * Le;
    const Rgb added = unweighted * w;
    st.L += added;
    if (!depthL) return;
    depthL[st.bounce].hit += added;
    depthL[st.bounce].hitUnweighted += unweighted;
}

// The environment seen by a ray that escaped (path depth = bounce), MIS-weighted against light sampling.
void addEscapedRadiance(const Scene& scene, LightSamplerKind kind, PtPathState& st, PtBounceRecord* rec, PtDepthSums* depthL) {
    const Light* env = scene.environment();
    if (!env) return;
    const Rgb Le = environmentRadiance(*env, scene, st.ray.dir);
    float w = 1.f, lightPdf = 0.f;
    if (!st.deltaBounce) {
        const float pmf = lightChoicePmf(scene, kind, st.prevP, st.prevNg, scene.environmentLight());
        lightPdf = pmf * pdfLi(*env, scene, st.prevP, Vec3(0.f), st.ray.dir);
        w = powerHeuristic(st.prevBsdfPdf, lightPdf);
    }
    addFoundEmission(st, Le, w, depthL);
    if (rec) *rec = recordEmission(*rec, st, Le, lightPdf, w);
}

// Emission found by BSDF sampling (path depth = bounce), MIS-weighted against light sampling.
void addHitEmission(const Scene& scene, LightSamplerKind kind, PtPathState& st, const SurfaceHit& hit, PtBounceRecord* rec,
                    PtDepthSums* depthL) {
    if (hit.light < 0) return;
    const Light& light = scene.lights[size_t(hit.light)];
    const Rgb Le = emittedRadiance(light, scene.textures, hit.bary, -st.ray.dir);
    if (isBlack(Le)) return;
    float w = 1.f, lightPdf = 0.f;
    if (!st.deltaBounce) {
        lightPdf = lightChoicePmf(scene, kind, st.prevP, st.prevNg, hit.light) * pdfLi(light, st.prevP, hit.p, hit.ng);
        w = powerHeuristic(st.prevBsdfPdf, lightPdf);
    }
    addFoundEmission(st, Le, w, depthL);
    if (rec) *rec = recordEmission(*rec, st, Le, lightPdf, w);
}

// Next-event estimation (path depth = bounce + 1): fills *nee and returns true when a shadow ray is
// to be traced by the caller.
bool nextEventEstimation(const Scene& scene, LightSamplerKind kind, const PixelSampler& sampler, const PtPathState& st,
                         const SurfaceHit* hit, const Bsdf& bsdf, const Vec3& wo, PtShadowRecord* nee, PtBounceRecord* rec) {
    if (!bsdf.hasNonDelta()) return false;
    const int bounce = st.bounce;
    float pmf = 0.f;
    const float uLight = sampler.get1D(RngStream::Camera, dim::vertex(uint32_t(bounce), dim::kNeeLight));
    const int li = chooseLight(scene, kind, hit->p, hit->ng, uLight, &pmf);
    const Vec2 uPosition = sampler.get2D(RngStream::Camera, dim::vertex(uint32_t(bounce), dim::kNeePosition));
    LightLiSample ls;
    const bool sampled = li >= 0 && pmf > 0.f && sampleLi(scene.lights[size_t(li)], scene, hit->p, uPosition, &ls);
    if (rec) {
        rec->neeTried = true;
        rec->uNeeLight = uLight;
        rec->uNeePosition = uPosition;
        rec->neeLight = li;
        rec->neePmf = pmf;
        rec->neeSampled = sampled;
        if (sampled) rec->nee = ls;
    }
    if (!sampled) return false;
    const Light& light = scene.lights[size_t(li)];
    float pdfOfWi = 0.f;  // f and pdf in one evaluation (Bsdf::evaluate)
    const Rgb f = bsdf.evaluate(wo, ls.wi, TransportMode::Radiance, &pdfOfWi) * absDot(ls.wi, hit->ns);
    const Rgb Tnee = segmentTransmittance(scene, surfaceEnd(*hit), lightEnd(scene, li, ls.pLight, ls.wi));
    if (isBlack(f) || isBlack(ls.Li) || isBlack(Tnee)) return false;
    if (isInfinite(light)) nee->ray.set(hit->p, hit->ng, ls.wi, Vec3(0.f), true);
    else nee->ray.set(hit->p, hit->ng, ls.pLight, ls.nLight, false);
    const float lightPdf = pmf * ls.pdf;
    const float bsdfPdf = ls.delta ? 0.f : pdfOfWi;
    const float w = ls.delta ? 1.f : powerHeuristic(lightPdf, bsdfPdf);
    nee->unweighted = st.beta * f * Tnee * ls.Li * (1.f / lightPdf);  // equals the weighted one where w = 1
    nee->contribution = st.beta * f * Tnee * ls.Li * (w / lightPdf);
    nee->depth = bounce + 1;
    if (rec) {
        rec->neeFCos = f;
        rec->neeTransmittance = Tnee;
        rec->neeBsdfPdf = bsdfPdf;
        rec->neeWeight = w;
        rec->neeShadowRay = true;
        rec->neeContribution = nee->contribution;
    }
    return true;
}

// Samples the BSDF and moves st.ray to the next segment; false when the path ends here.
bool sampleNextDirection(const PixelSampler& sampler, PtPathState& st, const SurfaceHit* hit, const Bsdf& bsdf,
                         const Vec3& wo, PtBounceRecord* rec) {
    const int bounce = st.bounce;
    BsdfSample bs;
    const float uLobe = sampler.get1D(RngStream::Camera, dim::vertex(uint32_t(bounce), dim::kBsdfLobe));
    const Vec2 uDir = sampler.get2D(RngStream::Camera, dim::vertex(uint32_t(bounce), dim::kBsdfDirection));
    const bool sampled = bsdf.sample(wo, uLobe, uDir, TransportMode::Radiance, &bs) && bs.pdf > 0.f && !isBlack(bs.f);
    if (rec) {
        rec->bsdfDrawn = true;
        rec->uBsdfLobe = uLobe;
        rec->uBsdfDirection = uDir;
        rec->bsdfSampled = sampled;
        rec->bsdf = bs;
    }
    if (!sampled) return false;
    st.beta *= bs.f * (absDot(bs.wi, hit->ns) / bs.pdf);
    if (rec) rec->betaOut = st.beta;
    if (!isFinite(st.beta)) return false;
    st.deltaBounce = bs.delta;
    st.prevBsdfPdf = bs.pdf;
    st.prevP = hit->p;
    st.prevNg = hit->ng;
    st.prevMaterial = hit->material;
    st.ray.origin = offsetRayOriginInline(hit->p, glm::dot(bs.wi, hit->ng) > 0.f ? hit->ng : -hit->ng);
    st.ray.dir = bs.wi;
    st.ray.tMax = kInfinity;
    return true;
}

// Russian roulette (render/roulette.h; a camera path starts with throughput 1): unbiased,
// survivors are divided by the survival probability. False when the path is ended.
bool survivesRoulette(const PixelSampler& sampler, const IntegratorSettings& settings, PtPathState& st, PtBounceRecord* rec) {
    const int bounce = st.bounce;
    if (bounce + 1 >= settings.rouletteStartDepth) {
        const float survive = rouletteSurvival(st.beta, 1.f);
        if (survive < 1.f) {
            const float u = sampler.get1D(RngStream::Camera, dim::vertex(uint32_t(bounce), dim::kRoulette));
            const bool survived = u < survive;
            if (rec) {
                rec->rouletteTested = true;
                rec->survive = survive;
                rec->uRoulette = u;
                rec->survived = survived;
            }
            if (!survived) return false;
            st.beta /= survive;
        }
    }
    return true;
}

}  // namespace

bool ptShade(const Scene& scene, const PixelSampler& sampler, const IntegratorSettings& settings, PtPathState& st,
             const SurfaceHit* hit, PtShadowRecord* nee, PtTrace* trace, PtDepthSums* depthL) {
    const int bounce = st.bounce;
    st.active = false;
    // Volume absorption along the ray just traced (docs/materials.md, "Volume absorption").
    const SegmentEnd from = st.prevNg != Vec3(0.f) ? SegmentEnd{st.prevP, st.prevNg, st.prevMaterial, false} : pointEnd(st.prevP);
    const Rgb T = segmentTransmittance(scene, from, hit ? surfaceEnd(*hit) : infiniteEnd(st.ray.dir));
    st.beta *= T;
    PtBounceRecord* rec = beginBounceRecord(trace, st, hit, T);
    if (!hit) {
        addEscapedRadiance(scene, settings.lightSampler, st, rec, depthL);
        return false;
    }
    addHitEmission(scene, settings.lightSampler, st, *hit, rec, depthL);
    if (bounce >= settings.maxDepth) {  // a further vertex would exceed the depth
        if (rec) rec->depthLimit = true;
        return false;
    }
    const Bsdf bsdf = scene.bsdfAt(hit->material, hit->triangle, hit->bary, hit->ns, hit->ng);
    const Vec3 wo = -st.ray.dir;
    const bool hasShadowRay = nextEventEstimation(scene, settings.lightSampler, sampler, st, hit, bsdf, wo, nee, rec);
    if (!sampleNextDirection(sampler, st, hit, bsdf, wo, rec) || !survivesRoulette(sampler, settings, st, rec))
        return hasShadowRay;
    st.bounce = bounce + 1;
    st.active = true;
    if (rec) rec->continues = true;
    return hasShadowRay;
}

namespace {

class PathTracer final : public Integrator {
public:
    explicit PathTracer(const IntegratorSettings& s) : settings_(s) {}
    const char* name() const override { return "path"; }

    // The megakernel schedule: every stage of one sample back to back.
    void samplePixel(const Scene& scene, int x, int y, const PixelSampler& sampler, SampleOutput& out) const override {
        thread_local std::vector<PtDepthSums> depthBuffer;  // per-depth sums of this sample (--depth-layers, --strategies)
        PtDepthSums* depthL = nullptr;
        if (settings_.recordDepths || settings_.recordStrategies) {
            depthBuffer.assign(size_t(settings_.maxDepth) + 1, PtDepthSums{});
            depthL = depthBuffer.data();
        }
        PtPathState st = ptBegin(scene, x, y, sampler);
        while (st.active) {
            SurfaceHit hit;
            const bool found = scene.intersect(st.ray, &hit);
            PtShadowRecord nee;
            if (ptShade(scene, sampler, settings_, st, found ? &hit : nullptr, &nee, nullptr, depthL))
                ptAddShadowResult(st, nee, traceShadowRay(scene, nee.ray), depthL);
        }
        out.L = st.L;
        if (settings_.recordDepths)
            ptForEachDepth(depthL, settings_.maxDepth, [&](const DepthContribution& c) { out.depths.push_back(c); });
        if (settings_.recordStrategies)
            ptForEachStrategy(depthL, settings_.maxDepth, [&](const StrategyContribution& c) { out.strategies.push_back(c); });
    }

private:
    IntegratorSettings settings_;
};

}  // namespace

std::unique_ptr<Integrator> makePathTracer(const IntegratorSettings& settings) {
    return std::make_unique<PathTracer>(settings);
}

void checkLightSamplerSupported(const std::string& integrator, const IntegratorSettings& settings) {
    if (settings.lightSampler == LightSamplerKind::Power || (integrator != "lt" && integrator != "light")) return;
    throw InputError("--light-sampler tree: light tracing has no shading point to choose a light at (its subpaths "
                     "start on a light chosen by power); use --integrator path or bdpt (docs/lights.md, \"Light tree\")");
}

std::unique_ptr<Integrator> makeIntegrator(const std::string& name, const IntegratorSettings& settings) {
    if (settings.maxDepth < 0) throw InputError("--max-depth must be >= 0");
    if (name == "path" || name == "pt") return makePathTracer(settings);
    checkLightSamplerSupported(name, settings);
    if (name == "lt" || name == "light") return makeLightTracer(settings);
    if (name == "bdpt") return makeBdpt(settings);
    throw InputError("--integrator: unknown integrator '" + name + "' (available: path, lt, bdpt)");
}

}  // namespace bdptref
