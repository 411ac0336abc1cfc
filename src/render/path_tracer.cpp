// Unidirectional path tracer with next-event estimation; see docs/path-tracer.md.
#include "bdptref/bsdf.h"
#include "bdptref/errors.h"
#include "bdptref/integrator.h"
#include "bdptref/scene.h"
#include "render/mis.h"

namespace bdptref {

namespace {

class PathTracer final : public Integrator {
public:
    explicit PathTracer(const IntegratorSettings& s) : settings_(s) {}
    const char* name() const override { return "path"; }

    void samplePixel(const Scene& scene, int x, int y, const PixelSampler& sampler, SampleOutput& out) const override {
        out.L = radiance(scene, x, y, sampler);
    }

private:
    Rgb radiance(const Scene& scene, int x, int y, const PixelSampler& sampler) const {
        const Vec2 jitter = sampler.get2D(RngStream::Camera, dim::kFilm);
        Ray ray = scene.camera.generateRay(Vec2(float(x), float(y)) + jitter);
        Rgb L(0.f), beta(1.f);
        bool deltaBounce = true;  // the camera ray counts as "specular": no other strategy sees Le
        float prevBsdfPdf = 0.f;
        Vec3 prevP = ray.origin;
        const LightSampler& lights = scene.lightSampler();

        for (int bounce = 0;; ++bounce) {
            SurfaceHit hit;
            if (!scene.intersect(ray, &hit)) {
                if (const Light* env = scene.environment()) {
                    const Rgb Le = environmentRadiance(*env, ray.dir);
                    float w = 1.f;
                    if (!deltaBounce)
                        w = powerHeuristic(prevBsdfPdf, lights.pmf(scene.environmentLight()) * pdfLi(*env, prevP, Vec3(0.f), Vec3(0.f)));
                    L += beta * Le * w;
                }
                break;
            }
            // Emission found by BSDF sampling (path depth = bounce).
            if (hit.light >= 0) {
                const Light& light = scene.lights[size_t(hit.light)];
                const Rgb Le = emittedRadiance(light, -ray.dir);
                if (!isBlack(Le)) {
                    float w = 1.f;
                    if (!deltaBounce)
                        w = powerHeuristic(prevBsdfPdf, lights.pmf(hit.light) * pdfLi(light, prevP, hit.p, hit.ng));
                    L += beta * Le * w;
                }
            }
            if (bounce >= settings_.maxDepth) break;  // a further vertex would exceed the depth

            const Bsdf bsdf(resolveMaterial(scene.materials[hit.material], scene.textures, hit.uv), hit.ns, hit.ng);
            const Vec3 wo = -ray.dir;

            // Next-event estimation (path depth = bounce + 1).
            if (bsdf.hasNonDelta()) {
                float pmf = 0.f;
                const int li = lights.sample(sampler.get1D(RngStream::Camera, dim::vertex(uint32_t(bounce), dim::kNeeLight)), &pmf);
                LightLiSample ls;
                if (li >= 0 && pmf > 0.f &&
                    sampleLi(scene.lights[size_t(li)], hit.p, sampler.get2D(RngStream::Camera, dim::vertex(uint32_t(bounce), dim::kNeePosition)), &ls)) {
                    const Light& light = scene.lights[size_t(li)];
                    const Rgb f = bsdf.f(wo, ls.wi, TransportMode::Radiance) * absDot(ls.wi, hit.ns);
                    if (!isBlack(f) && !isBlack(ls.Li)) {
                        const bool unoccluded = isInfinite(light) ? scene.visibleToInfinity(hit.p, hit.ng, ls.wi)
                                                                  : scene.visible(hit.p, hit.ng, ls.pLight, ls.nLight);
                        if (unoccluded) {
                            const float lightPdf = pmf * ls.pdf;
                            const float w = ls.delta ? 1.f : powerHeuristic(lightPdf, bsdf.pdf(wo, ls.wi));
                            L += beta * f * ls.Li * (w / lightPdf);
                        }
                    }
                }
            }

            // Continue the path by sampling the BSDF.
            BsdfSample bs;
            const float uLobe = sampler.get1D(RngStream::Camera, dim::vertex(uint32_t(bounce), dim::kBsdfLobe));
            const Vec2 uDir = sampler.get2D(RngStream::Camera, dim::vertex(uint32_t(bounce), dim::kBsdfDirection));
            if (!bsdf.sample(wo, uLobe, uDir, TransportMode::Radiance, &bs) || !(bs.pdf > 0.f) || isBlack(bs.f)) break;
            beta *= bs.f * (absDot(bs.wi, hit.ns) / bs.pdf);
            if (!isFinite(beta)) break;
            deltaBounce = bs.delta;
            prevBsdfPdf = bs.pdf;
            prevP = hit.p;
            ray.origin = offsetRayOrigin(hit.p, glm::dot(bs.wi, hit.ng) > 0.f ? hit.ng : -hit.ng);
            ray.dir = bs.wi;
            ray.tMax = kInfinity;

            // Russian roulette: unbiased, survivors are divided by the survival probability.
            if (bounce + 1 >= settings_.rouletteStartDepth) {
                const float survive = std::min(1.f, maxComponent(beta));
                if (survive < 1.f) {
                    const float u = sampler.get1D(RngStream::Camera, dim::vertex(uint32_t(bounce), dim::kRoulette));
                    if (!(u < std::max(survive, 0.05f))) break;
                    beta /= std::max(survive, 0.05f);
                }
            }
        }
        return L;
    }

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
