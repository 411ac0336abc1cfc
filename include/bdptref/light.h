// Lights: emissive triangles (area lights), KHR_lights_punctual point/spot/directional, and an
// environment (an equirectangular map, env_map.h; the constant --env is its 1x1 case). Each light can
//   (a) sample an incident direction at a reference point (next-event estimation) -> sampleLi,
//       and give the solid-angle density of that choice -> pdfLi;
//   (b) evaluate emitted radiance -> emittedRadiance / environmentRadiance;
//   (c) sample an emitted ray with position and direction densities -> sampleLe / pdfLe.
// Units and conventions: docs/lights.md. A Light is a trivially copyable value (no pointers) so
// GPU-style buffers can hold it.
//
// An area light may carry an emissive texture (glTF emissiveTexture): its radiance then varies
// over the triangle, Le(b) = emission * texture(uv(b)). Every function that returns emitted
// radiance has an overload taking the scene's textures and evaluates it at the point (barycentrics
// b = (b1, b2), p = (1 - b1 - b2) v0 + b1 v1 + b2 v2, as SurfaceHit::bary); the overloads without
// textures are for lights without one. Positions stay uniform by area, so no density depends on
// the texture (docs/lights.md, "Emissive textures").
//
// An environment light's radiance is emission * map(direction); its map lives in the Scene
// (Scene::environmentMaps[envMap]) and only the overloads taking the Scene can see it. The other
// overloads treat an environment light as the constant map of value 1 and throw std::logic_error
// for one that has a map (a caller that forgot the scene).
#pragma once

#include "bdptref/material.h"
#include "bdptref/math.h"
#include "bdptref/sampling.h"

#include <type_traits>
#include <vector>

namespace bdptref {

class Scene;

enum class LightType : uint8_t { Area, Point, Spot, Directional, Environment };

struct Light {
    LightType type = LightType::Point;
    Rgb emission{0.f};  // Area: radiance Le; Point/Spot: intensity I; Directional: irradiance E;
                        // Environment: radiance L
    Vec3 position{0.f};   // Point, Spot
    Vec3 direction{0.f, 0.f, -1.f};  // Spot axis / Directional travel direction (unit)
    float cosInner = 1.f, cosOuter = 0.f;  // Spot cone (glTF innerConeAngle/outerConeAngle)
    // Area light: one triangle in world space.
    Vec3 v0{0.f}, v1{0.f}, v2{0.f};
    Vec3 normal{0.f, 0.f, 1.f};  // geometric normal of the emitting (front) side
    float area = 0.f;
    bool twoSided = false;
    uint32_t triangle = 0;  // primitive id in the scene's mesh
    // Area light with an emissive texture: the texture reference (index into Scene::textures) and
    // the triangle's texture coordinates of its TEXCOORD set at v0, v1, v2.
    TextureRef emissiveTexture;
    Vec2 uv0{0.f}, uv1{0.f}, uv2{0.f};
    // Directional and environment lights emit from a disk covering the scene's bounding sphere.
    Vec3 sceneCenter{0.f};
    float sceneRadius = 1.f;
    // Environment: index into Scene::environmentMaps; -1: the 1x1 map of value 1 (radiance = emission).
    int32_t envMap = -1;
    double power = 0.0;  // luminance of emitted flux, used for light selection (double: it overflows float)
};
static_assert(std::is_trivially_copyable_v<Light>, "Light lives in GPU-style buffers");

// Radiance factor of an area light at barycentrics b (emission times the emissive texture there);
// `emission` for an untextured light (bit-exact). Throws std::logic_error when the light has a
// texture that `textures` does not hold (a caller passed the wrong list).
Rgb areaEmission(const Light& l, const std::vector<Texture>& textures, Vec2 bary);

bool isDeltaPosition(const Light& l);  // Point, Spot
bool isDeltaDirection(const Light& l);  // Directional
bool isInfinite(const Light& l);        // Directional, Environment

struct LightLiSample {
    Vec3 wi;            // unit, from the reference point towards the light
    Rgb Li{0.f};        // radiance (or intensity/dist^2, irradiance for delta lights) arriving
    float pdf = 0.f;    // solid angle at the reference point; 1 for delta lights
    Vec3 pLight{0.f};   // point on the light (a far point for infinite lights)
    Vec3 nLight{0.f};   // light's surface normal at pLight (zero for point/spot)
    float dist = 0.f;   // distance to pLight (infinity for infinite lights)
    Vec2 bary{0.f};     // area lights: barycentrics (b1, b2) of pLight on the triangle
    bool delta = false;
};

bool sampleLi(const Light& l, const std::vector<Texture>& textures, const Vec3& ref, Vec2 u, LightLiSample* out);
bool sampleLi(const Light& l, const Vec3& ref, Vec2 u, LightLiSample* out);
// Solid-angle density at `ref` of sampleLi choosing the direction towards pLight (area: a point
// on the triangle with normal nLight; environment: any direction). 0 for delta lights.
float pdfLi(const Light& l, const Vec3& ref, const Vec3& pLight, const Vec3& nLight);
// Radiance an area light emits from the point with barycentrics `bary` in direction w (unit, leaving).
Rgb emittedRadiance(const Light& l, const std::vector<Texture>& textures, Vec2 bary, const Vec3& w);
Rgb emittedRadiance(const Light& l, const Vec3& w);
// What a light sends in direction w (unit, leaving the light): radiance for area lights (zero
// behind a one-sided one), intensity (with the spot falloff) for point and spot lights, irradiance
// for directional lights, radiance for the environment. `bary`: the point on an area light.
Rgb lightEmission(const Light& l, const std::vector<Texture>& textures, Vec2 bary, const Vec3& w);
Rgb lightEmission(const Light& l, const Vec3& w);
// Radiance arriving from the environment along a ray with direction rayDir (escaped rays).
Rgb environmentRadiance(const Light& l, const Vec3& rayDir);
Rgb environmentRadiance(const Light& l, const Scene& scene, const Vec3& rayDir);

struct LightLeSample {
    Ray ray;              // origin on the light, unit direction of emission
    Vec3 nLight{0.f};     // surface normal at the origin (zero for point/spot)
    Rgb Le{0.f};          // radiance (area/env), intensity (point/spot) or irradiance (directional)
    float pdfPos = 0.f;   // area density of the origin (1 for delta positions)
    float pdfDir = 0.f;   // solid-angle density of the direction (1 for delta directions)
    Vec2 bary{0.f};       // area lights: barycentrics (b1, b2) of the origin on the triangle
};

bool sampleLe(const Light& l, const std::vector<Texture>& textures, Vec2 uPos, Vec2 uDir, LightLeSample* out);
bool sampleLe(const Light& l, Vec2 uPos, Vec2 uDir, LightLeSample* out);
void pdfLe(const Light& l, const Vec3& origin, const Vec3& dir, const Vec3& nLight, float* pdfPos, float* pdfDir);

// The same for a light of `scene` (its textures and environment maps): what the renderer calls.
// Environment densities (docs/lights.md, "Environment"): sampleLi / pdfLi give the map's
// solid-angle density of the direction; for pdfLi pass that direction (unit, towards the
// environment, PathVertex::ng of an infinite vertex) as nLight (zero: normalize(pLight - ref)).
// sampleLe / pdfLe: the direction's density (of -dir, dir being the direction of travel) and the
// area density 1 / (pi R^2) of the origin on the disk of the scene's bounding radius.
bool sampleLi(const Light& l, const Scene& scene, const Vec3& ref, Vec2 u, LightLiSample* out);
float pdfLi(const Light& l, const Scene& scene, const Vec3& ref, const Vec3& pLight, const Vec3& nLight);
Rgb lightEmission(const Light& l, const Scene& scene, Vec2 bary, const Vec3& w);
bool sampleLe(const Light& l, const Scene& scene, Vec2 uPos, Vec2 uDir, LightLeSample* out);
void pdfLe(const Light& l, const Scene& scene, const Vec3& origin, const Vec3& dir, const Vec3& nLight, float* pdfPos,
           float* pdfDir);

// Chooses lights in proportion to their power.
class LightSampler {
public:
    LightSampler() = default;
    explicit LightSampler(const std::vector<Light>& lights);
    // Returns the light index (or -1 with no lights) and its probability.
    int sample(float u, float* pmf) const;
    float pmf(int lightIndex) const;

private:
    Distribution1D distribution_;
};

double lightPower(const Light& l);  // luminance of the emitted flux, computed in double
// The same for an area light with an emissive texture: the flux estimated from the texture over
// the triangle (fixed barycentric points, with a floor; docs/lights.md "Emissive textures").
double lightPower(const Light& l, const std::vector<Texture>& textures);
// Any light of `scene` (environment: pi R^2 times the map's integrated luminance).
double lightPower(const Light& l, const Scene& scene);
const char* lightTypeName(LightType t);  // "area", "point", "spot", "directional", "environment"

}  // namespace bdptref
