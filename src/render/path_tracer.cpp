// Unidirectional path tracer with next-event estimation; see docs/path-tracer.md.
#include "bdptref/bsdf.h"
#include "bdptref/errors.h"
#include "bdptref/integrator.h"
#include "bdptref/scene.h"
#include "render/mis.h"
#include "render/path_tracer.h"

namespace bdptref {

PtPathState ptBegin(const Scene& scene, int x, int y, const PixelSampler& sampler) {
    const Vec2 jitter = sampler.get2D(RngStream::Camera, dim::kFilm);
    PtPathState st;
    st.ray = scene.camera.generateRay(Vec2(float(x), float(y)) + jitter);
    st.prevP = st.ray.origin;
    return st;
}

bool ptShade(const Scene& scene, const PixelSampler& sampler, const IntegratorSettings& settings, PtPathState& st,
             const SurfaceHit* hit, PtShadowRecord* nee) {
    const LightSampler& lights = scene.lightSampler();
    const int bounce = st.bounce;
    const Ray& ray = st.ray;
    st.active = false;
    if (!hit) {
        if (const Light* env = scene.environment()) {
            const Rgb Le = environmentRadiance(*env, scene, ray.dir);
            float w = 1.f;
            if (!st.deltaBounce)
                w = powerHeuristic(st.prevBsdfPdf, lights.pmf(scene.environmentLight()) * pdfLi(*env, scene, st.prevP, Vec3(0.f), ray.dir));
            st.L += st.beta * Le * w;
        }
        return false;
    }
    // Emission found by BSDF sampling (path depth = bounce).
    if (hit->light >= 0) {
        const Light& light = scene.lights[size_t(hit->light)];
        const Rgb Le = emittedRadiance(light, scene.textures, hit->bary, -ray.dir);
        if (!isBlack(Le)) {
            float w = 1.f;
            if (!st.deltaBounce)
                w = powerHeuristic(st.prevBsdfPdf, lights.pmf(hit->light) * pdfLi(light, st.prevP, hit->p, hit->ng));
            st.L += st.beta * Le * w;
        }
    }
    if (bounce >= settings.maxDepth) return false;  // a further vertex would exceed the depth

    const Bsdf bsdf(scene.materialParams(hit->material, hit->triangle, hit->bary), hit->ns, hit->ng);
    const Vec3 wo = -ray.dir;

    // Next-event estimation (path depth = bounce + 1); its shadow ray is traced by the caller.
    bool hasShadowRay = false;
    if (bsdf.hasNonDelta()) {
        float pmf = 0.f;
        const int li = lights.sample(sampler.get1D(RngStream::Camera, dim::vertex(uint32_t(bounce), dim::kNeeLight)), &pmf);
        LightLiSample ls;
        if (li >= 0 && pmf > 0.f &&
            sampleLi(scene.lights[size_t(li)], scene, hit->p, sampler.get2D(RngStream::Camera, dim::vertex(uint32_t(bounce), dim::kNeePosition)), &ls)) {
            const Light& light = scene.lights[size_t(li)];
            const Rgb f = bsdf.f(wo, ls.wi, TransportMode::Radiance) * absDot(ls.wi, hit->ns);
            if (!isBlack(f) && !isBlack(ls.Li)) {
                nee->ray = isInfinite(light) ? ShadowRay{hit->p, hit->ng, ls.wi, Vec3(0.f), true}
                                             : ShadowRay{hit->p, hit->ng, ls.pLight, ls.nLight, false};
                const float lightPdf = pmf * ls.pdf;
                const float w = ls.delta ? 1.f : powerHeuristic(lightPdf, bsdf.pdf(wo, ls.wi));
                nee->contribution = st.beta * f * ls.Li * (w / lightPdf);
                hasShadowRay = true;
            }
        }
    }

    // Continue the path by sampling the BSDF.
    BsdfSample bs;
    const float uLobe = sampler.get1D(RngStream::Camera, dim::vertex(uint32_t(bounce), dim::kBsdfLobe));
    const Vec2 uDir = sampler.get2D(RngStream::Camera, dim::vertex(uint32_t(bounce), dim::kBsdfDirection));
    if (!bsdf.sample(wo, uLobe, uDir, TransportMode::Radiance, &bs) || !(bs.pdf > 0.f) || isBlack(bs.f)) return hasShadowRay;
    st.beta *= bs.f * (absDot(bs.wi, hit->ns) / bs.pdf);
    if (!isFinite(st.beta)) return hasShadowRay;
    st.deltaBounce = bs.delta;
    st.prevBsdfPdf = bs.pdf;
    st.prevP = hit->p;
    st.ray.origin = offsetRayOrigin(hit->p, glm::dot(bs.wi, hit->ng) > 0.f ? hit->ng : -hit->ng);
    st.ray.dir = bs.wi;
    st.ray.tMax = kInfinity;

    // Russian roulette: unbiased, survivors are divided by the survival probability.
    if (bounce + 1 >= settings.rouletteStartDepth) {
        const float survive = std::min(1.f, maxComponent(st.beta));
        if (survive < 1.f) {
            const float u = sampler.get1D(RngStream::Camera, dim::vertex(uint32_t(bounce), dim::kRoulette));
            if (!(u < std::max(survive, 0.05f))) return hasShadowRay;
            st.beta /= std::max(survive, 0.05f);
        }
    }
    st.bounce = bounce + 1;
    st.active = true;
    return hasShadowRay;
}

namespace {

class PathTracer final : public Integrator {
public:
    explicit PathTracer(const IntegratorSettings& s) : settings_(s) {}
    const char* name() const override { return "path"; }

    // The megakernel schedule: every stage of one sample back to back.
    void samplePixel(const Scene& scene, int x, int y, const PixelSampler& sampler, SampleOutput& out) const override {
        PtPathState st = ptBegin(scene, x, y, sampler);
        while (st.active) {
            SurfaceHit hit;
            const bool found = scene.intersect(st.ray, &hit);
            PtShadowRecord nee;
            if (ptShade(scene, sampler, settings_, st, found ? &hit : nullptr, &nee))
                ptAddShadowResult(st, nee, traceShadowRay(scene, nee.ray));
        }
        out.L = st.L;
    }

private:
    IntegratorSettings settings_;
};

}  // namespace

std::unique_ptr<Integrator> makePathTracer(const IntegratorSettings& settings) {
    return std::make_unique<PathTracer>(settings);
}

std::unique_ptr<Integrator> makeIntegrator(const std::string& name, const IntegratorSettings& settings) {
    if (settings.maxDepth < 0) throw InputError("--max-depth must be >= 0");
    if (name == "path" || name == "pt") return makePathTracer(settings);
    if (name == "lt" || name == "light") return makeLightTracer(settings);
    if (name == "bdpt") return makeBdpt(settings);
    throw InputError("--integrator: unknown integrator '" + name + "' (available: path, lt, bdpt)");
}

}  // namespace bdptref
