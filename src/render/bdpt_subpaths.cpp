// Camera and light subpaths of BDPT (docs/mis.md, "Subpaths"). Random numbers: docs/rng.md.
#include "bdptref/bdpt.h"
#include "bdptref/errors.h"
#include "core/ray_offset.h"
#include "render/bdpt_vertex.h"
#include "render/roulette.h"
#include "render/segment_transmittance.h"

namespace bdptref {

MisHeuristic parseMisHeuristic(const std::string& name) {
    if (name == "balance") return MisHeuristic::Balance;
    if (name == "power") return MisHeuristic::Power;
    if (name == "uniform") return MisHeuristic::Uniform;
    throw InputError("--mis: unknown heuristic '" + name + "' (balance, power, uniform)");
}

bool walkAddVertex(const Scene& scene, const SurfaceHit* hit, SubpathWalk* walk, PathVertex* path, Bsdf* bsdfs) {
    PathVertex& v = path[walk->vertices];
    const Ray& ray = walk->ray;
    walk->active = false;
    // Volume absorption along the segment just traced (docs/materials.md, "Volume absorption").
    if (!scene.absorptionFree())
        walk->beta *= segmentTransmittance(scene, vertexEnd(scene, path[walk->vertices - 1]),
                                           hit ? surfaceEnd(*hit) : infiniteEnd(ray.dir));
    if (!hit) {
        // Escaped: for camera subpaths this is an endpoint on the environment (strategy s = 0).
        if (walk->mode == TransportMode::Radiance && scene.environmentLight() >= 0) {
            v = PathVertex{};
            v.type = VertexType::Light;
            v.infinite = true;
            v.light = scene.environmentLight();
            v.ng = v.ns = ray.dir;
            v.p = ray.origin + ray.dir * (2.f * scene.boundingRadius());
            v.wo = -ray.dir;
            v.beta = walk->beta;
            ++walk->vertices;
        }
        return false;
    }
    v = PathVertex{};
    v.type = VertexType::Surface;
    v.p = hit->p;
    v.ng = hit->ng;
    v.ns = hit->ns;
    v.bary = hit->bary;
    v.wo = -ray.dir;
    v.material = hit->material;
    v.triangle = hit->triangle;
    v.light = hit->light;
    v.beta = walk->beta;
    if (bsdfs) bsdfs[walk->vertices] = vertexBsdf(scene, v);
    ++walk->vertices;
    return walk->vertices < walk->maxVertices;
}

namespace {

// walkScatter with the BSDF of the walk's last vertex.
bool scatterWith(const Bsdf& bsdf, const PixelSampler& sampler, SubpathWalk* walk, PathVertex* path) {
    walk->active = false;
    PathVertex& v = path[walk->vertices - 1];
    const uint32_t bounce = uint32_t(walk->vertices - 2);  // subpath vertex i is reached after i - 1 bounces
    BsdfSample bs;
    const float uLobe = sampler.get1D(walk->stream, dim::vertex(bounce, dim::kBsdfLobe));
    const Vec2 uDir = sampler.get2D(walk->stream, dim::vertex(bounce, dim::kBsdfDirection));
    if (!bsdf.sample(v.wo, uLobe, uDir, walk->mode, &bs) || !(bs.pdf > 0.f) || isBlack(bs.f)) return false;
    Rgb beta = walk->beta * (bs.f * (absDot(bs.wi, v.ns) / bs.pdf));
    if (!isFinite(beta)) return false;
    v.delta = bs.delta;

    // Russian roulette (render/roulette.h); MIS densities do not include it (docs/mis.md).
    if (walk->vertices - 1 >= walk->rouletteStart) {
        const float survive = rouletteSurvival(beta, walk->rouletteScale);
        if (survive < 1.f) {
            if (!(sampler.get1D(walk->stream, dim::vertex(bounce, dim::kRoulette)) < survive)) return false;
            beta /= survive;
        }
    }
    walk->beta = beta;
    walk->ray.origin = offsetRayOriginInline(v.p, glm::dot(bs.wi, v.ng) > 0.f ? v.ng : -v.ng);
    walk->ray.dir = bs.wi;
    walk->ray.tMax = kInfinity;
    walk->active = true;
    return true;
}

}  // namespace

bool walkScatter(const Scene& scene, const PixelSampler& sampler, SubpathWalk* walk, PathVertex* path,
                 const Bsdf* bsdfs) {
    const int last = walk->vertices - 1;
    return bsdfs ? scatterWith(bsdfs[last], sampler, walk, path)
                 : scatterWith(vertexBsdf(scene, path[last]), sampler, walk, path);
}

// Sets pdfFwd/pdfRev of every vertex from the stored vertices alone (docs/mis.md, "Subpaths").
// They are NOT taken from the sampling step: its ray left from an offset origin, and the MIS walk
// recomputes the densities around each connection from the stored positions. Mixing the two
// would give one path two different sets of densities, and weights that do not sum to 1.
void fillSubpathDensities(const Scene& scene, PathVertex* path, int n, const MisSettings& mis, const Bsdf* bsdfs) {
    // vertexPdf reads the BSDF of surface vertices only: the others' side-array entries are unused.
    auto pdf = [&](int from, const PathVertex* prev, const PathVertex& next) {
        return bsdfs ? vertexPdf(scene, path[from], bsdfs[from], prev, next) : vertexPdf(scene, path[from], prev, next);
    };
    // Vertex j answers pdfFwd of j + 1 (arriving from j - 1) and pdfRev of j - 1 (arriving from
    // j + 1). At an inner surface vertex both come from one BSDF evaluation of the pair of
    // directions (Bsdf::pdfBothWays), and each edge's direction is normalised once: directionTo(a, b)
    // is exactly -directionTo(b, a). Same bits as vertexPdf for each density.
    Vec3 towardsPrev(0.f);  // directionTo(path[j], path[j - 1])
    for (int j = 0; j + 1 < n; ++j) {
        const PathVertex& v = path[j];
        const Vec3 towardsNext = directionTo(v, path[j + 1]);
        if (v.delta) {
            path[j + 1].pdfFwd = 0.0;
            if (j >= 1) path[j - 1].pdfRev = 0.0;
        } else if (j >= 1 && v.type == VertexType::Surface) {
            float fwd, rev;
            if (bsdfs) bsdfs[j].pdfBothWays(towardsPrev, towardsNext, &fwd, &rev);
            else vertexBsdf(scene, v).pdfBothWays(towardsPrev, towardsNext, &fwd, &rev);
            path[j + 1].pdfFwd = convertDensity(fwd, v, path[j + 1]);
            path[j - 1].pdfRev = convertDensity(rev, v, path[j - 1]);
        } else {
            path[j + 1].pdfFwd = pdf(j, j >= 1 ? &path[j - 1] : nullptr, path[j + 1]);
            if (j >= 1) path[j - 1].pdfRev = pdf(j, &path[j + 1], path[j - 1]);
        }
        towardsPrev = -towardsNext;
        // directionTo(path[j + 1], path[j]) exactly (its zero vector is +0, not -0), stored for
        // the connections' densities (connectionDensities).
        path[j + 1].toPrev = towardsNext == Vec3(0.f) ? Vec3(0.f) : towardsPrev;
    }
    if (n > 0) path[0].toPrev = Vec3(0.f);
    fillRecursiveMis(scene, path, n, mis);
}

namespace {

// The megakernel schedule of a walk: extend and shade back to back until the walk ends.
int walkToEnd(const Scene& scene, const PixelSampler& sampler, SubpathWalk* walk, PathVertex* path, Bsdf* bsdfs) {
    while (walk->active) {
        SurfaceHit hit;
        const bool found = scene.intersect(walk->ray, &hit);
        if (!walkAddVertex(scene, found ? &hit : nullptr, walk, path, bsdfs)) break;
        if (!walkScatter(scene, sampler, walk, path, bsdfs)) break;
    }
    return walk->vertices;
}

}  // namespace

void beginCameraSubpath(const Scene& scene, Vec2 raster, const BdptSettings& settings, PathVertex* path,
                        SubpathWalk* walk) {
    *walk = SubpathWalk{};
    walk->maxVertices = settings.maxCameraVertices();
    walk->rouletteStart = settings.rouletteStartDepth;
    walk->mode = TransportMode::Radiance;
    walk->stream = RngStream::Camera;
    if (walk->maxVertices <= 0) return;
    const Camera& cam = scene.camera;
    const Ray ray = cam.generateRay(raster);
    PathVertex& c = path[0];
    c = PathVertex{};
    c.type = VertexType::Camera;
    c.p = ray.origin;  // the pinhole, or the film point of an orthographic camera
    c.ng = c.ns = cam.forward();
    c.beta = Rgb(1.f);  // We cos / (pdfPos pdfDir) = 1 for both projections (docs/camera.md)
    c.pdfFwd = 1.0;
    walk->vertices = 1;
    float pdfPos, pdfDir;
    cam.pdfWe(ray.dir, &pdfPos, &pdfDir);
    if (!(pdfDir > 0.f)) return;
    walk->ray = ray;
    walk->beta = Rgb(1.f);
    walk->rouletteScale = 1.f;
    walk->active = walk->maxVertices > 1;
}

void beginLightSubpath(const Scene& scene, const PixelSampler& sampler, const BdptSettings& settings, PathVertex* path,
                       SubpathWalk* walk) {
    *walk = SubpathWalk{};
    walk->maxVertices = settings.maxLightVertices();
    walk->rouletteStart = settings.rouletteStartDepth;
    walk->mode = TransportMode::Importance;
    walk->stream = RngStream::Light;
    if (walk->maxVertices <= 0) return;
    float pmf = 0.f;
    const int li = scene.lightSampler().sample(sampler.get1D(RngStream::Light, dim::kLightChoice), &pmf);
    if (li < 0 || !(pmf > 0.f)) return;
    const Light& light = scene.lights[size_t(li)];
    LightLeSample le;
    if (!sampleLe(light, scene, sampler.get2D(RngStream::Light, dim::kEmitPosition),
                  sampler.get2D(RngStream::Light, dim::kEmitDirection), &le) ||
        !(le.pdfPos > 0.f) || !(le.pdfDir > 0.f) || isBlack(le.Le))
        return;
    PathVertex& v = path[0];
    v = PathVertex{};
    v.type = VertexType::Light;
    v.light = li;
    v.infinite = isInfinite(light);
    v.p = le.ray.origin;
    v.ng = v.ns = v.infinite ? -le.ray.dir : le.nLight;  // infinite: direction towards the light
    v.triangle = light.triangle;
    v.bary = le.bary;
    // Direction-independent part (docs/mis.md); an area light's Le is that, at the sampled point,
    // an environment map's Le at the sampled direction (the vertex's only direction).
    const bool pointwiseLe = light.type == LightType::Area || light.type == LightType::Environment;
    v.beta = (pointwiseLe ? le.Le : light.emission) / (pmf * le.pdfPos);
    v.pdfFwd = lightOriginDensity(scene, v);
    walk->vertices = 1;
    const float cosLight = light.type == LightType::Area ? absDot(le.nLight, le.ray.dir) : 1.f;
    Ray ray = le.ray;
    if (light.type == LightType::Area)  // leave the emitter's own surface (docs/self-intersection.md)
        ray.origin = offsetRayOriginInline(ray.origin, glm::dot(ray.dir, le.nLight) > 0.f ? le.nLight : -le.nLight);
    walk->ray = ray;
    walk->beta = le.Le * (cosLight / (pmf * le.pdfPos * le.pdfDir));
    walk->rouletteScale = rouletteStartScale(walk->beta);
    walk->active = walk->maxVertices > 1;
}

int generateCameraSubpath(const Scene& scene, const PixelSampler& sampler, Vec2 raster, const BdptSettings& settings,
                          PathVertex* path, Bsdf* bsdfs) {
    SubpathWalk walk;
    beginCameraSubpath(scene, raster, settings, path, &walk);
    const int n = walkToEnd(scene, sampler, &walk, path, bsdfs);
    fillSubpathDensities(scene, path, n, settings.mis, bsdfs);
    return n;
}

int traceLightSubpath(const Scene& scene, const PixelSampler& sampler, const BdptSettings& settings, PathVertex* path,
                      Bsdf* bsdfs) {
    SubpathWalk walk;
    beginLightSubpath(scene, sampler, settings, path, &walk);
    return walkToEnd(scene, sampler, &walk, path, bsdfs);
}

int generateLightSubpath(const Scene& scene, const PixelSampler& sampler, const BdptSettings& settings,
                         PathVertex* path, Bsdf* bsdfs) {
    const int n = traceLightSubpath(scene, sampler, settings, path, bsdfs);
    fillSubpathDensities(scene, path, n, settings.mis, bsdfs);  // path[1] from the light: pdfLightToVertex (disk density for infinite lights)
    return n;
}

}  // namespace bdptref
