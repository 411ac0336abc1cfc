#include "bdptref/light.h"

#include "bdptref/env_map.h"
#include "bdptref/scene.h"

#include <stdexcept>

namespace bdptref {

bool isDeltaPosition(const Light& l) { return l.type == LightType::Point || l.type == LightType::Spot; }
bool isDeltaDirection(const Light& l) { return l.type == LightType::Directional; }
bool isInfinite(const Light& l) { return l.type == LightType::Directional || l.type == LightType::Environment; }

namespace {

// glTF KHR_lights_punctual's recommended spot falloff (smooth between outer and inner cone).
float spotFalloff(const Light& l, float cosTheta) {
    const float scale = 1.f / std::max(0.001f, l.cosInner - l.cosOuter);
    const float offset = -l.cosOuter * scale;
    const float x = cosTheta * scale + offset;
    const float a = x > 0.f ? (x < 1.f ? x : 1.f) : 0.f;  // glm::clamp would pass a NaN (a NaN direction) on
    return a * a;
}

// Cosine at the light surface on the emitting side; <= 0 means the direction is not emitted into.
float emittingCosine(const Light& l, const Vec3& w) {
    const float c = glm::dot(l.normal, w);
    return l.twoSided ? std::abs(c) : c;
}

// A point uniform on the triangle; *bary receives its barycentrics (b1, b2) in SurfaceHit's
// convention p = (1 - b1 - b2) v0 + b1 v1 + b2 v2.
Vec3 pointOnTriangle(const Light& l, Vec2 u, Vec2* bary) {
    const Vec2 b = squareToUniformTriangle(u);
    const float b2 = 1.f - b.x - b.y;
    *bary = Vec2(b.y, b2);
    return b.x * l.v0 + b.y * l.v1 + b2 * l.v2;
}

const std::vector<Texture>& noTextures() {
    static const std::vector<Texture> none;
    return none;
}

double luminanceD(const Rgb& e) { return 0.2126 * double(e.r) + 0.7152 * double(e.g) + 0.0722 * double(e.b); }

// A point on the disk of radius R, perpendicular to `axis`, centred at `centre`.
Vec3 pointOnDisk(const Vec3& centre, const Vec3& axis, float radius, Vec2 u) {
    const Frame f(axis);
    const Vec2 d = squareToConcentricDisk(u);
    return centre + radius * (d.x * f.s + d.y * f.t);
}

// The map of an environment light: the scene's (maps != nullptr) or the constant map of value 1.
const EnvironmentMap& mapOf(const Light& l, const std::vector<EnvironmentMap>* maps) {
    static const EnvironmentMap unit = EnvironmentMap::constant();
    if (l.envMap < 0) return unit;
    if (!maps) throw std::logic_error("internal: an environment map light evaluated without the scene");
    if (size_t(l.envMap) >= maps->size()) throw std::logic_error("internal: an environment light refers to a map the scene does not hold");
    return (*maps)[size_t(l.envMap)];
}

bool sampleLiImpl(const Light& l, const std::vector<Texture>& textures, const std::vector<EnvironmentMap>* maps, const Vec3& ref,
                  Vec2 u, LightLiSample* out);
float pdfLiImpl(const Light& l, const std::vector<EnvironmentMap>* maps, const Vec3& ref, const Vec3& pLight, const Vec3& nLight);
Rgb lightEmissionImpl(const Light& l, const std::vector<Texture>& textures, const std::vector<EnvironmentMap>* maps, Vec2 bary,
                      const Vec3& w);
bool sampleLeImpl(const Light& l, const std::vector<Texture>& textures, const std::vector<EnvironmentMap>* maps, Vec2 uPos,
                  Vec2 uDir, LightLeSample* out);
void pdfLeImpl(const Light& l, const std::vector<EnvironmentMap>* maps, const Vec3& dir, const Vec3& nLight, float* pdfPos,
               float* pdfDir);

}  // namespace

Rgb areaEmission(const Light& l, const std::vector<Texture>& textures, Vec2 bary) {
    if (!l.emissiveTexture.valid()) return l.emission;
    if (size_t(l.emissiveTexture.texture) >= textures.size())
        throw std::logic_error("internal: an emissive-textured light evaluated without the scene's textures");
    SurfaceAttributes at;
    const float b1 = bary.x, b2 = bary.y, b0 = 1.f - b1 - b2;  // as Scene::attributes interpolates
    const int set = l.emissiveTexture.texCoord >= 0 && l.emissiveTexture.texCoord < kMaxTexCoordSets ? l.emissiveTexture.texCoord : 0;
    at.uv[set] = b0 * l.uv0 + b1 * l.uv1 + b2 * l.uv2;
    const Vec4 t = sampleTexture(l.emissiveTexture, textures, at);
    return l.emission * Rgb(t.r, t.g, t.b);
}

bool sampleLi(const Light& l, const Vec3& ref, Vec2 u, LightLiSample* out) { return sampleLi(l, noTextures(), ref, u, out); }

bool sampleLi(const Light& l, const std::vector<Texture>& textures, const Vec3& ref, Vec2 u, LightLiSample* out) {
    return sampleLiImpl(l, textures, nullptr, ref, u, out);
}

bool sampleLi(const Light& l, const Scene& scene, const Vec3& ref, Vec2 u, LightLiSample* out) {
    return sampleLiImpl(l, scene.textures, &scene.environmentMaps, ref, u, out);
}

float pdfLi(const Light& l, const Vec3& ref, const Vec3& pLight, const Vec3& nLight) { return pdfLiImpl(l, nullptr, ref, pLight, nLight); }

float pdfLi(const Light& l, const Scene& scene, const Vec3& ref, const Vec3& pLight, const Vec3& nLight) {
    return pdfLiImpl(l, &scene.environmentMaps, ref, pLight, nLight);
}

namespace {

bool sampleLiImpl(const Light& l, const std::vector<Texture>& textures, const std::vector<EnvironmentMap>* maps, const Vec3& ref,
                  Vec2 u, LightLiSample* out) {
    *out = LightLiSample{};
    switch (l.type) {
    case LightType::Area: {
        const Vec3 p = pointOnTriangle(l, u, &out->bary);
        Vec3 d = p - ref;
        const float dist2 = glm::dot(d, d);
        if (!(dist2 > 0.f) || !std::isfinite(dist2)) return false;  // no direction from ref (docs/hard-cases.md)
        const float dist = std::sqrt(dist2);
        d /= dist;
        const float cosLight = emittingCosine(l, -d);
        if (!(cosLight > 0.f)) return false;
        out->wi = d;
        out->pLight = p;
        out->nLight = l.normal;
        out->dist = dist;
        out->pdf = dist2 / (cosLight * l.area);
        out->Li = areaEmission(l, textures, out->bary);
        return std::isfinite(out->pdf);
    }
    case LightType::Point:
    case LightType::Spot: {
        Vec3 d = l.position - ref;
        const float dist2 = glm::dot(d, d);
        if (!(dist2 > 0.f) || !std::isfinite(dist2)) return false;
        const float dist = std::sqrt(dist2);
        d /= dist;
        float scale = 1.f;
        if (l.type == LightType::Spot) scale = spotFalloff(l, glm::dot(l.direction, -d));
        if (scale == 0.f) return false;
        out->wi = d;
        out->pLight = l.position;
        out->dist = dist;
        out->pdf = 1.f;
        out->delta = true;
        out->Li = l.emission * (scale / dist2);
        return true;
    }
    case LightType::Directional: {
        out->wi = -l.direction;
        out->pLight = ref + out->wi * (2.f * l.sceneRadius);
        out->dist = kInfinity;
        out->pdf = 1.f;
        out->delta = true;
        out->Li = l.emission;
        return true;
    }
    case LightType::Environment: {
        const EnvironmentMap& env = mapOf(l, maps);
        if (!env.sample(u, &out->wi, &out->pdf)) return false;
        out->pLight = ref + out->wi * (2.f * l.sceneRadius);
        out->dist = kInfinity;
        out->Li = l.emission * env.lookup(out->wi);
        return true;
    }
    }
    return false;
}

float pdfLiImpl(const Light& l, const std::vector<EnvironmentMap>* maps, const Vec3& ref, const Vec3& pLight, const Vec3& nLight) {
    switch (l.type) {
    case LightType::Area: {
        Vec3 d = pLight - ref;
        const float dist2 = glm::dot(d, d);
        if (!(dist2 > 0.f)) return 0.f;
        d /= std::sqrt(dist2);
        (void)nLight;  // an area light is one triangle: its normal is l.normal
        const float cosLight = emittingCosine(l, -d);
        if (!(cosLight > 0.f)) return 0.f;
        return dist2 / (cosLight * l.area);
    }
    case LightType::Environment: {
        // The direction towards the environment: nLight as given (exact), else from the points.
        const Vec3 w = nLight != Vec3(0.f) ? nLight : glm::normalize(pLight - ref);
        return mapOf(l, maps).pdf(w);
    }
    default: return 0.f;  // delta lights cannot be hit
    }
}

}  // namespace

Rgb emittedRadiance(const Light& l, const Vec3& w) { return emittedRadiance(l, noTextures(), Vec2(0.f), w); }

Rgb emittedRadiance(const Light& l, const std::vector<Texture>& textures, Vec2 bary, const Vec3& w) {
    if (l.type != LightType::Area) return Rgb(0.f);
    return emittingCosine(l, w) > 0.f ? areaEmission(l, textures, bary) : Rgb(0.f);
}

Rgb lightEmission(const Light& l, const Vec3& w) { return lightEmission(l, noTextures(), Vec2(0.f), w); }

Rgb lightEmission(const Light& l, const std::vector<Texture>& textures, Vec2 bary, const Vec3& w) {
    return lightEmissionImpl(l, textures, nullptr, bary, w);
}

Rgb lightEmission(const Light& l, const Scene& scene, Vec2 bary, const Vec3& w) {
    return lightEmissionImpl(l, scene.textures, &scene.environmentMaps, bary, w);
}

Rgb environmentRadiance(const Light& l, const Vec3& rayDir) {
    return l.type == LightType::Environment ? l.emission * mapOf(l, nullptr).lookup(rayDir) : Rgb(0.f);
}

Rgb environmentRadiance(const Light& l, const Scene& scene, const Vec3& rayDir) {
    return l.type == LightType::Environment ? l.emission * mapOf(l, &scene.environmentMaps).lookup(rayDir) : Rgb(0.f);
}

bool sampleLe(const Light& l, Vec2 uPos, Vec2 uDir, LightLeSample* out) { return sampleLe(l, noTextures(), uPos, uDir, out); }

bool sampleLe(const Light& l, const std::vector<Texture>& textures, Vec2 uPos, Vec2 uDir, LightLeSample* out) {
    return sampleLeImpl(l, textures, nullptr, uPos, uDir, out);
}

bool sampleLe(const Light& l, const Scene& scene, Vec2 uPos, Vec2 uDir, LightLeSample* out) {
    return sampleLeImpl(l, scene.textures, &scene.environmentMaps, uPos, uDir, out);
}

void pdfLe(const Light& l, const Vec3& /*origin*/, const Vec3& dir, const Vec3& nLight, float* pdfPos, float* pdfDir) {
    pdfLeImpl(l, nullptr, dir, nLight, pdfPos, pdfDir);
}

void pdfLe(const Light& l, const Scene& scene, const Vec3& /*origin*/, const Vec3& dir, const Vec3& nLight, float* pdfPos,
           float* pdfDir) {
    pdfLeImpl(l, &scene.environmentMaps, dir, nLight, pdfPos, pdfDir);
}

namespace {

Rgb lightEmissionImpl(const Light& l, const std::vector<Texture>& textures, const std::vector<EnvironmentMap>* maps, Vec2 bary,
                      const Vec3& w) {
    switch (l.type) {
    case LightType::Area: return emittedRadiance(l, textures, bary, w);
    case LightType::Point: return l.emission;
    case LightType::Spot: return l.emission * spotFalloff(l, glm::dot(l.direction, w));
    case LightType::Directional: return l.emission;
    case LightType::Environment: return l.emission * mapOf(l, maps).lookup(-w);  // w leaves the light: it arrives from -w
    }
    return Rgb(0.f);
}

bool sampleLeImpl(const Light& l, const std::vector<Texture>& textures, const std::vector<EnvironmentMap>* maps, Vec2 uPos,
                  Vec2 uDir, LightLeSample* out) {
    *out = LightLeSample{};
    switch (l.type) {
    case LightType::Area: {
        Vec3 n = l.normal;
        Vec2 ud = uDir;
        if (l.twoSided) {  // pick the side with probability 1/2, reuse the number
            if (ud.x < 0.5f) {
                ud.x *= 2.f;
            } else {
                ud.x = std::min(2.f * (ud.x - 0.5f), 0x1.fffffep-1f);
                n = -n;
            }
        }
        const Vec3 local = squareToCosineHemisphere(ud);
        if (!(local.z > 0.f)) return false;
        out->ray.origin = pointOnTriangle(l, uPos, &out->bary);
        out->ray.dir = Frame(n).toWorld(local);
        out->nLight = l.normal;
        out->Le = areaEmission(l, textures, out->bary);
        out->pdfPos = 1.f / l.area;
        out->pdfDir = cosineHemispherePdf(local.z) * (l.twoSided ? 0.5f : 1.f);
        return true;
    }
    case LightType::Point: {
        out->ray.origin = l.position;
        out->ray.dir = squareToUniformSphere(uDir);
        out->Le = l.emission;
        out->pdfPos = 1.f;
        out->pdfDir = uniformSpherePdf();
        return true;
    }
    case LightType::Spot: {
        const Vec3 local = squareToUniformCone(uDir, l.cosOuter);
        out->ray.origin = l.position;
        out->ray.dir = Frame(l.direction).toWorld(local);
        out->Le = l.emission * spotFalloff(l, local.z);
        out->pdfPos = 1.f;
        out->pdfDir = uniformConePdf(l.cosOuter);
        return !isBlack(out->Le);
    }
    case LightType::Directional: {
        // A disk covering the scene's bounding sphere, placed upstream of it.
        out->ray.origin = pointOnDisk(l.sceneCenter - l.direction * l.sceneRadius, l.direction, l.sceneRadius, uPos);
        out->ray.dir = l.direction;
        out->nLight = l.direction;
        out->Le = l.emission;
        out->pdfPos = 1.f / (kPi * l.sceneRadius * l.sceneRadius);
        out->pdfDir = 1.f;
        return true;
    }
    case LightType::Environment: {
        // A direction from the map (towards the environment), then parallel rays through a disk
        // of the scene's bounding radius perpendicular to it, placed on the map's side.
        const EnvironmentMap& env = mapOf(l, maps);
        Vec3 w;
        if (!env.sample(uDir, &w, &out->pdfDir)) return false;
        out->ray.origin = pointOnDisk(l.sceneCenter + w * l.sceneRadius, w, l.sceneRadius, uPos);
        out->ray.dir = -w;
        out->nLight = -w;
        out->Le = l.emission * env.lookup(w);
        out->pdfPos = 1.f / (kPi * l.sceneRadius * l.sceneRadius);
        return true;
    }
    }
    return false;
}

void pdfLeImpl(const Light& l, const std::vector<EnvironmentMap>* maps, const Vec3& dir, const Vec3& nLight, float* pdfPos,
               float* pdfDir) {
    *pdfPos = 0.f;
    *pdfDir = 0.f;
    switch (l.type) {
    case LightType::Area: {
        const float c = glm::dot(nLight, dir);
        const float cosLight = l.twoSided ? std::abs(c) : c;
        if (!(cosLight > 0.f) || !std::isfinite(cosLight)) return;  // no direction (NaN, Inf): no density
        *pdfPos = 1.f / l.area;
        *pdfDir = cosLight * kInvPi * (l.twoSided ? 0.5f : 1.f);
        return;
    }
    case LightType::Point:
        *pdfPos = 1.f;
        *pdfDir = uniformSpherePdf();
        return;
    case LightType::Spot:
        *pdfPos = 1.f;
        *pdfDir = glm::dot(l.direction, dir) >= l.cosOuter ? uniformConePdf(l.cosOuter) : 0.f;
        return;
    case LightType::Directional:
        *pdfPos = 1.f / (kPi * l.sceneRadius * l.sceneRadius);
        *pdfDir = 0.f;  // delta direction: a given direction has zero density
        return;
    case LightType::Environment:
        *pdfPos = 1.f / (kPi * l.sceneRadius * l.sceneRadius);
        *pdfDir = mapOf(l, maps).pdf(-dir);  // dir travels into the scene: it came from -dir
        return;
    }
}

}  // namespace

namespace {

// The largest luminance of emission * texel over every texel that can influence the triangle's
// texture lookups: its (transformed) uv bounding box grown by one texel for bilinear filtering,
// each texel read at its centre through Texture::lookup (so the wrap modes apply). A bound on the
// luminance anywhere on the triangle (a bilinear value is a convex combination of texels).
double maxTexelLuminance(const Light& l, const Texture& tex) {
    const TextureRef& r = l.emissiveTexture;
    Vec2 lo(kInfinity), hi(-kInfinity);
    for (const Vec2& uv : {l.uv0, l.uv1, l.uv2}) {
        const Vec3 h(uv, 1.f);
        const Vec2 t(glm::dot(r.row0, h), glm::dot(r.row1, h));
        lo = glm::min(lo, t);
        hi = glm::max(hi, t);
    }
    if (!isFinite(Vec3(lo, 0.f)) || !isFinite(Vec3(hi, 0.f))) return 0.0;
    // Texel index range; more than two periods (mirrored repeat) covers every texel.
    // So does a range far from the origin (|uv| ~ 1e30): converting it to int64_t would overflow.
    auto range = [](float a, float b, int n, int64_t* i0, int64_t* i1) {
        double x0 = std::floor(double(a) * n) - 1.0, x1 = std::floor(double(b) * n) + 1.0;
        if (x1 - x0 + 1.0 > 2.0 * n || !(std::abs(x0) < 0x1p52 && std::abs(x1) < 0x1p52)) x0 = 0.0, x1 = 2.0 * n - 1.0;
        *i0 = int64_t(x0);
        *i1 = int64_t(x1);
    };
    int64_t x0, x1, y0, y1;
    range(lo.x, hi.x, tex.width, &x0, &x1);
    range(lo.y, hi.y, tex.height, &y0, &y1);
    double best = 0.0;
    for (int64_t y = y0; y <= y1; ++y)
        for (int64_t x = x0; x <= x1; ++x) {
            const Vec4 t = tex.lookup(Vec2(float((double(x) + 0.5) / tex.width), float((double(y) + 0.5) / tex.height)));
            best = std::max(best, luminanceD(l.emission * Rgb(t.r, t.g, t.b)));
        }
    return best;
}

}  // namespace

double lightPower(const Light& l, const std::vector<Texture>& textures) {
    if (l.type != LightType::Area || !l.emissiveTexture.valid()) return lightPower(l);
    if (size_t(l.emissiveTexture.texture) >= textures.size())
        throw std::logic_error("internal: the power of an emissive-textured light computed without the scene's textures");
    // Mean luminance at 64 fixed points, the centres of an 8x8 grid mapped by the area-preserving
    // squareToUniformTriangle (a stratified estimate of the triangle's mean radiance), floored at
    // 1e-3 of the largest value the texture can give there: a triangle whose grid points all land
    // on black texels but that emits elsewhere must keep a positive selection probability, or light
    // tracing would never start a path from it.
    constexpr int kGrid = 8;
    double sum = 0.0;
    for (int j = 0; j < kGrid; ++j)
        for (int i = 0; i < kGrid; ++i) {
            Vec2 bary;
            pointOnTriangle(l, Vec2((float(i) + 0.5f) / kGrid, (float(j) + 0.5f) / kGrid), &bary);
            sum += luminanceD(areaEmission(l, textures, bary));
        }
    const double mean = sum / double(kGrid * kGrid);
    const double floor = 1e-3 * maxTexelLuminance(l, textures[size_t(l.emissiveTexture.texture)]);
    return std::max(mean, floor) * double(l.area) * double(kPi) * (l.twoSided ? 2.0 : 1.0);
}

double lightPower(const Light& l, const Scene& scene) {
    if (l.type == LightType::Environment)
        return double(kPi) * double(l.sceneRadius) * double(l.sceneRadius) * mapOf(l, &scene.environmentMaps).integratedLuminance(l.emission);
    return lightPower(l, scene.textures);
}

double lightPower(const Light& l) {
    if (l.type == LightType::Environment)  // the constant map; a light with a map needs the scene
        return double(kPi) * double(l.sceneRadius) * double(l.sceneRadius) * mapOf(l, nullptr).integratedLuminance(l.emission);
    if (l.type == LightType::Area && l.emissiveTexture.valid())
        throw std::logic_error("internal: the power of an emissive-textured light computed without the scene's textures");
    // In double: luminance 3e37 times 4 pi already exceeds FLT_MAX (docs/lights.md, "Limits").
    const Rgb& e = l.emission;
    const double y = 0.2126 * double(e.r) + 0.7152 * double(e.g) + 0.0722 * double(e.b);  // luminance(), in double
    const double pi = double(kPi), r2 = double(l.sceneRadius) * double(l.sceneRadius);
    switch (l.type) {
    case LightType::Area: return y * double(l.area) * pi * (l.twoSided ? 2.0 : 1.0);
    case LightType::Point: return y * 4.0 * pi;
    case LightType::Spot: return y * 2.0 * pi * (1.0 - 0.5 * (double(l.cosInner) + double(l.cosOuter)));
    case LightType::Directional: return y * pi * r2;
    case LightType::Environment: break;  // above
    }
    return 0.0;
}

const char* lightTypeName(LightType t) {
    switch (t) {
    case LightType::Area: return "area";
    case LightType::Point: return "point";
    case LightType::Spot: return "spot";
    case LightType::Directional: return "directional";
    case LightType::Environment: return "environment";
    }
    return "?";
}

LightSampler::LightSampler(const std::vector<Light>& lights) {
    std::vector<double> w;
    w.reserve(lights.size());
    for (const Light& l : lights) w.push_back(std::max(0.0, l.power));
    distribution_ = Distribution1D(w);
}

int LightSampler::sample(float u, float* pmf) const {
    if (distribution_.empty() || distribution_.total() <= 0) {
        *pmf = 0.f;
        return -1;
    }
    return int(distribution_.sample(u, pmf));
}

float LightSampler::pmf(int i) const { return i < 0 ? 0.f : distribution_.pmf(size_t(i)); }

}  // namespace bdptref
