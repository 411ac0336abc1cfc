#include "bdptref/light.h"

namespace bdptref {

bool isDeltaPosition(const Light& l) { return l.type == LightType::Point || l.type == LightType::Spot; }
bool isDeltaDirection(const Light& l) { return l.type == LightType::Directional; }
bool isInfinite(const Light& l) { return l.type == LightType::Directional || l.type == LightType::Environment; }

namespace {

// glTF KHR_lights_punctual's recommended spot falloff (smooth between outer and inner cone).
float spotFalloff(const Light& l, float cosTheta) {
    const float scale = 1.f / std::max(0.001f, l.cosInner - l.cosOuter);
    const float offset = -l.cosOuter * scale;
    const float a = glm::clamp(cosTheta * scale + offset, 0.f, 1.f);
    return a * a;
}

// Cosine at the light surface on the emitting side; <= 0 means the direction is not emitted into.
float emittingCosine(const Light& l, const Vec3& w) {
    const float c = glm::dot(l.normal, w);
    return l.twoSided ? std::abs(c) : c;
}

Vec3 pointOnTriangle(const Light& l, Vec2 u) {
    const Vec2 b = squareToUniformTriangle(u);
    return b.x * l.v0 + b.y * l.v1 + (1.f - b.x - b.y) * l.v2;
}

// A point on the disk of radius R, perpendicular to `axis`, centred at `centre`.
Vec3 pointOnDisk(const Vec3& centre, const Vec3& axis, float radius, Vec2 u) {
    const Frame f(axis);
    const Vec2 d = squareToConcentricDisk(u);
    return centre + radius * (d.x * f.s + d.y * f.t);
}

}  // namespace

bool sampleLi(const Light& l, const Vec3& ref, Vec2 u, LightLiSample* out) {
    *out = LightLiSample{};
    switch (l.type) {
    case LightType::Area: {
        const Vec3 p = pointOnTriangle(l, u);
        Vec3 d = p - ref;
        const float dist2 = glm::dot(d, d);
        if (!(dist2 > 0.f)) return false;
        const float dist = std::sqrt(dist2);
        d /= dist;
        const float cosLight = emittingCosine(l, -d);
        if (!(cosLight > 0.f)) return false;
        out->wi = d;
        out->pLight = p;
        out->nLight = l.normal;
        out->dist = dist;
        out->pdf = dist2 / (cosLight * l.area);
        out->Li = l.emission;
        return std::isfinite(out->pdf);
    }
    case LightType::Point:
    case LightType::Spot: {
        Vec3 d = l.position - ref;
        const float dist2 = glm::dot(d, d);
        if (!(dist2 > 0.f)) return false;
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
        out->wi = squareToUniformSphere(u);
        out->pLight = ref + out->wi * (2.f * l.sceneRadius);
        out->dist = kInfinity;
        out->pdf = uniformSpherePdf();
        out->Li = l.emission;
        return true;
    }
    }
    return false;
}

float pdfLi(const Light& l, const Vec3& ref, const Vec3& pLight, const Vec3& nLight) {
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
    case LightType::Environment: return uniformSpherePdf();
    default: return 0.f;  // delta lights cannot be hit
    }
}

Rgb emittedRadiance(const Light& l, const Vec3& w) {
    if (l.type != LightType::Area) return Rgb(0.f);
    return emittingCosine(l, w) > 0.f ? l.emission : Rgb(0.f);
}

Rgb lightEmission(const Light& l, const Vec3& w) {
    switch (l.type) {
    case LightType::Area: return emittedRadiance(l, w);
    case LightType::Point: return l.emission;
    case LightType::Spot: return l.emission * spotFalloff(l, glm::dot(l.direction, w));
    case LightType::Directional:
    case LightType::Environment: return l.emission;
    }
    return Rgb(0.f);
}

Rgb environmentRadiance(const Light& l, const Vec3& /*rayDir*/) {
    return l.type == LightType::Environment ? l.emission : Rgb(0.f);
}

bool sampleLe(const Light& l, Vec2 uPos, Vec2 uDir, LightLeSample* out) {
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
        out->ray.origin = pointOnTriangle(l, uPos);
        out->ray.dir = Frame(n).toWorld(local);
        out->nLight = l.normal;
        out->Le = l.emission;
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
        const Vec3 w = squareToUniformSphere(uDir);  // direction towards the environment
        out->ray.origin = pointOnDisk(l.sceneCenter + w * l.sceneRadius, w, l.sceneRadius, uPos);
        out->ray.dir = -w;
        out->nLight = -w;
        out->Le = l.emission;
        out->pdfPos = 1.f / (kPi * l.sceneRadius * l.sceneRadius);
        out->pdfDir = uniformSpherePdf();
        return true;
    }
    }
    return false;
}

void pdfLe(const Light& l, const Vec3& /*origin*/, const Vec3& dir, const Vec3& nLight, float* pdfPos, float* pdfDir) {
    *pdfPos = 0.f;
    *pdfDir = 0.f;
    switch (l.type) {
    case LightType::Area: {
        const float c = glm::dot(nLight, dir);
        const float cosLight = l.twoSided ? std::abs(c) : c;
        if (cosLight <= 0.f) return;
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
        *pdfDir = uniformSpherePdf();
        return;
    }
}

double lightPower(const Light& l) {
    // In double: luminance 3e37 times 4 pi already exceeds FLT_MAX (docs/lights.md, "Limits").
    const Rgb& e = l.emission;
    const double y = 0.2126 * double(e.r) + 0.7152 * double(e.g) + 0.0722 * double(e.b);  // luminance(), in double
    const double pi = double(kPi), r2 = double(l.sceneRadius) * double(l.sceneRadius);
    switch (l.type) {
    case LightType::Area: return y * double(l.area) * pi * (l.twoSided ? 2.0 : 1.0);
    case LightType::Point: return y * 4.0 * pi;
    case LightType::Spot: return y * 2.0 * pi * (1.0 - 0.5 * (double(l.cosInner) + double(l.cosOuter)));
    case LightType::Directional: return y * pi * r2;
    case LightType::Environment: return y * 4.0 * pi * pi * r2;
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
