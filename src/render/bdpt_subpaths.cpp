// Camera and light subpaths of BDPT (docs/mis.md, "Subpaths"). Random numbers: docs/rng.md.
#include "bdptref/bdpt.h"
#include "bdptref/errors.h"
#include "render/bdpt_vertex.h"

namespace bdptref {

MisHeuristic parseMisHeuristic(const std::string& name) {
    if (name == "balance") return MisHeuristic::Balance;
    if (name == "power") return MisHeuristic::Power;
    if (name == "uniform") return MisHeuristic::Uniform;
    throw InputError("--mis: unknown heuristic '" + name + "' (balance, power, uniform)");
}

namespace {

// Extends a subpath whose last vertex is path[-1] (already written) along `ray`, writing at most
// maxVertices vertices (positions, normals, throughput, delta flags). Returns the number written.
int randomWalk(const Scene& scene, const PixelSampler& sampler, RngStream stream, Ray ray, Rgb beta, int maxVertices,
               TransportMode mode, int rouletteStart, PathVertex* path) {
    if (maxVertices <= 0) return 0;
    int n = 0;
    for (;;) {
        PathVertex& v = path[n];
        SurfaceHit hit;
        if (!scene.intersect(ray, &hit)) {
            // Escaped: for camera subpaths this is an endpoint on the environment (strategy s = 0).
            if (mode == TransportMode::Radiance && scene.environmentLight() >= 0) {
                v = PathVertex{};
                v.type = VertexType::Light;
                v.infinite = true;
                v.light = scene.environmentLight();
                v.ng = v.ns = ray.dir;
                v.p = ray.origin + ray.dir * (2.f * scene.boundingRadius());
                v.wo = -ray.dir;
                v.beta = beta;
                ++n;
            }
            break;
        }
        v = PathVertex{};
        v.type = VertexType::Surface;
        v.p = hit.p;
        v.ng = hit.ng;
        v.ns = hit.ns;
        v.uv = hit.uv;
        v.wo = -ray.dir;
        v.material = hit.material;
        v.triangle = hit.triangle;
        v.light = hit.light;
        v.beta = beta;
        ++n;
        if (n >= maxVertices) break;

        const uint32_t bounce = uint32_t(n - 1);  // subpath vertex n is reached after n - 1 bounces
        const Bsdf bsdf = vertexBsdf(scene, v);
        BsdfSample bs;
        const float uLobe = sampler.get1D(stream, dim::vertex(bounce, dim::kBsdfLobe));
        const Vec2 uDir = sampler.get2D(stream, dim::vertex(bounce, dim::kBsdfDirection));
        if (!bsdf.sample(v.wo, uLobe, uDir, mode, &bs) || !(bs.pdf > 0.f) || isBlack(bs.f)) break;
        beta *= bs.f * (absDot(bs.wi, v.ns) / bs.pdf);
        if (!isFinite(beta)) break;
        v.delta = bs.delta;

        // Russian roulette (unbiased); MIS densities do not include it (docs/mis.md).
        if (n >= rouletteStart) {
            const float survive = std::max(0.05f, std::min(1.f, maxComponent(beta)));
            if (survive < 1.f) {
                if (!(sampler.get1D(stream, dim::vertex(bounce, dim::kRoulette)) < survive)) break;
                beta /= survive;
            }
        }
        ray.origin = offsetRayOrigin(v.p, glm::dot(bs.wi, v.ng) > 0.f ? v.ng : -v.ng);
        ray.dir = bs.wi;
        ray.tMax = kInfinity;
    }
    return n;
}

// Sets pdfFwd/pdfRev of every vertex from the stored vertices alone (docs/mis.md, "Subpaths").
// They are NOT taken from the sampling step: its ray left from an offset origin, and the MIS walk
// recomputes the densities around each connection from the stored positions. Mixing the two
// would give one path two different sets of densities, and weights that do not sum to 1.
void fillDensities(const Scene& scene, PathVertex* path, int n) {
    for (int i = 1; i < n; ++i) {
        const PathVertex& from = path[i - 1];
        path[i].pdfFwd = from.delta ? 0.0 : vertexPdf(scene, from, i >= 2 ? &path[i - 2] : nullptr, path[i]);
    }
    for (int i = 0; i + 2 < n; ++i) {
        const PathVertex& from = path[i + 1];
        path[i].pdfRev = from.delta ? 0.0 : vertexPdf(scene, from, &path[i + 2], path[i]);
    }
}

}  // namespace

int generateCameraSubpath(const Scene& scene, const PixelSampler& sampler, Vec2 raster, const BdptSettings& settings,
                          PathVertex* path) {
    const int maxVertices = settings.maxCameraVertices();
    if (maxVertices <= 0) return 0;
    const Camera& cam = scene.camera;
    const Ray ray = cam.generateRay(raster);
    PathVertex& c = path[0];
    c = PathVertex{};
    c.type = VertexType::Camera;
    c.p = cam.position();
    c.ng = c.ns = cam.forward();
    c.beta = Rgb(1.f);  // We cos / (pdfPos pdfDir) = 1 for the pinhole
    c.pdfFwd = 1.0;
    float pdfPos, pdfDir;
    cam.pdfWe(ray.dir, &pdfPos, &pdfDir);
    if (!(pdfDir > 0.f)) return 1;
    const int n = 1 + randomWalk(scene, sampler, RngStream::Camera, ray, Rgb(1.f), maxVertices - 1,
                                 TransportMode::Radiance, settings.rouletteStartDepth, path + 1);
    fillDensities(scene, path, n);
    return n;
}

int generateLightSubpath(const Scene& scene, const PixelSampler& sampler, const BdptSettings& settings,
                         PathVertex* path) {
    const int maxVertices = settings.maxLightVertices();
    if (maxVertices <= 0) return 0;
    float pmf = 0.f;
    const int li = scene.lightSampler().sample(sampler.get1D(RngStream::Light, dim::kLightChoice), &pmf);
    if (li < 0 || !(pmf > 0.f)) return 0;
    const Light& light = scene.lights[size_t(li)];
    LightLeSample le;
    if (!sampleLe(light, sampler.get2D(RngStream::Light, dim::kEmitPosition),
                  sampler.get2D(RngStream::Light, dim::kEmitDirection), &le) ||
        !(le.pdfPos > 0.f) || !(le.pdfDir > 0.f) || isBlack(le.Le))
        return 0;
    PathVertex& v = path[0];
    v = PathVertex{};
    v.type = VertexType::Light;
    v.light = li;
    v.infinite = isInfinite(light);
    v.p = le.ray.origin;
    v.ng = v.ns = v.infinite ? -le.ray.dir : le.nLight;  // infinite: direction towards the light
    v.triangle = light.triangle;
    v.beta = light.emission / (pmf * le.pdfPos);  // direction-independent part (docs/mis.md)
    v.pdfFwd = lightOriginDensity(scene, v);
    const float cosLight = light.type == LightType::Area ? absDot(le.nLight, le.ray.dir) : 1.f;
    Ray ray = le.ray;
    if (light.type == LightType::Area)  // leave the emitter's own surface (docs/self-intersection.md)
        ray.origin = offsetRayOrigin(ray.origin, glm::dot(ray.dir, le.nLight) > 0.f ? le.nLight : -le.nLight);
    const Rgb beta = le.Le * (cosLight / (pmf * le.pdfPos * le.pdfDir));
    const int n = 1 + randomWalk(scene, sampler, RngStream::Light, ray, beta, maxVertices - 1,
                                 TransportMode::Importance, settings.rouletteStartDepth, path + 1);
    fillDensities(scene, path, n);  // path[1] from the light: pdfLightToVertex (disk density for infinite lights)
    return n;
}

}  // namespace bdptref
