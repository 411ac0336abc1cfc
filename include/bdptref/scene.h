// The scene after loading: one triangle mesh (every glTF primitive flattened), its materials and
// textures, the lights, the camera, and the Embree acceleration structure.
//
// Coordinates: before finalize() positions are world coordinates (as loaded or set by the
// caller); finalize() moves them into RENDER SPACE, world coordinates minus `worldOrigin`, which
// it sets to the camera's position so that the camera sits exactly at (0, 0, 0). Rendering
// happens in render space; what is shown to users (trace JSON, `info`) adds worldOrigin back.
// Why: docs/self-intersection.md, "Camera-relative render space".
#pragma once

#include "bdptref/bsdf.h"
#include "bdptref/camera.h"
#include "bdptref/env_map.h"
#include "bdptref/light.h"
#include "bdptref/light_tree.h"
#include "bdptref/material.h"
#include "bdptref/math.h"

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace bdptref {

class Accel;
struct CoverageTest;
struct EmbreeHit;

// Rays traced through Scene::intersect (extension: closest hit) and Scene::visible /
// visibleToInfinity (shadow: next-event and connection rays), summed over every thread of the
// process since it started. For benchmarks: take the difference around a render.
struct RayCounts {
    uint64_t extension = 0;
    uint64_t shadow = 0;
    uint64_t total() const { return extension + shadow; }
};
RayCounts rayCountsSoFar();

// One triangle mesh in world space. Triangle i uses vertices indices[i]; per-vertex attributes
// are parallel to positions. uvSets[n] is TEXCOORD_n (as many sets as any primitive had; zero
// where a primitive lacks the set); colors is COLOR_0 (empty when no primitive had it; 1 where a
// primitive lacks it). tangents (glTF TANGENT form: xyz, w = bitangent sign) is empty unless some
// primitive's material has a normal texture; then it is parallel to positions, (0,0,0,0) for the
// vertices of the other primitives.
struct TriangleMesh {
    std::vector<Vec3> positions;
    std::vector<Vec3> normals;
    std::vector<std::vector<Vec2>> uvSets;
    std::vector<Vec4> colors;
    std::vector<Vec4> tangents;
    std::vector<uint8_t> vertexHasNormal;  // 0 where the source primitive had no normals
    std::vector<glm::uvec3> indices;
    std::vector<uint32_t> triangleMaterial;
    std::vector<int32_t> triangleLight;  // index into Scene::lights, or -1
    size_t triangleCount() const { return indices.size(); }
};

// What the closest-hit query found, in the form shading needs.
struct SurfaceHit {
    Vec3 p{0.f};
    Vec3 ng{0.f};  // unit geometric normal, front face = counter-clockwise winding
    Vec3 ns{0.f};  // unit shading normal (interpolated, then normal-mapped; ng where the source had none), same side as ng
    Vec2 bary{0.f};  // barycentric coordinates (b1, b2) of p in `triangle`
    float t = 0.f;
    uint32_t triangle = 0;
    uint32_t material = 0;
    int32_t light = -1;
};

// What was in the file, for `bdptref info` and for honest error reporting.
struct SceneInfo {
    std::string path;
    std::string contentHash;  // FNV-1a 64 of the scene file, every external file it loaded, and the --env-map file (docs/scenes.md)
    std::vector<std::string> extensionsUsed;
    std::vector<std::string> extensionsIgnored;  // used by the file, not implemented, not required
    std::vector<std::string> warnings;           // things that do not change the picture
    // Picture-changing parts of the file that are not implemented and were left out (e.g.
    // "extension KHR_materials_iridescence"): recorded in the EXR header as bdptref:ignoredFeatures,
    // and a failure under `render --strict-scene`.
    std::vector<std::string> ignoredFeatures;
    std::vector<std::string> featuresUsed;  // what of the file is rendered beyond plain meshes ("skins", "COLOR_0", ...)
    std::string cameraSource;                    // "scene camera 0: node 3 'X' ..." / "default" / "command line"
    std::vector<SceneCameraEntry> cameras;       // every camera node instance, in traversal order
    int cameraUsed = -1;                         // index into cameras of the one rendered; -1: none
};

class Scene {
public:
    Scene();
    ~Scene();
    Scene(Scene&&) noexcept;
    Scene& operator=(Scene&&) noexcept;
    Scene(const Scene&) = delete;
    Scene& operator=(const Scene&) = delete;

    TriangleMesh mesh;
    std::vector<Material> materials;
    std::vector<Texture> textures;
    // Environment maps of environment lights (Light::envMap indexes it; the constant --env needs none).
    std::vector<EnvironmentMap> environmentMaps;
    std::vector<Light> lights;  // area lights first (one per emissive triangle), then punctual, then environment
    // What each light is called in messages, parallel to `lights` ("node 3: KHR_lights_punctual
    // light 0 ('Sun')"); filled by the loader for punctual lights and by finalize() for the rest.
    // Lights added without a name are called by their type and index.
    std::vector<std::string> lightNames;
    Camera camera;
    bool hasSceneCamera = false;
    SceneInfo info;
    // The world position of render space's (0, 0, 0): after finalize(), the camera's world
    // position (exactly; every position above is relative to it). Zero before finalize().
    DVec3 worldOrigin{0.0};
    // World <-> render coordinates of a point (in double, rounded to float once). toRender throws
    // InputError when the point is not finite or farther from the origin than float can hold.
    Vec3 toRender(const DVec3& world) const;
    DVec3 toWorld(const Vec3& render) const { return DVec3(render) + worldOrigin; }

    // Adds the constant environment (radiance L). Call before finalize().
    void setEnvironment(const Rgb& L);
    // Adds an environment map light of radiance scale * map(direction) instead (docs/lights.md,
    // "Environment"); `name` says where it came from in messages. Call before finalize().
    void setEnvironmentMap(EnvironmentMap map, float scale, const std::string& name);
    // Moves everything into camera-centred render space (see the top of this file), creates area
    // lights from emissive triangles, computes bounds and light powers, builds the Embree BVH.
    // Must be called once after the geometry and the camera are complete; throws InputError on an
    // unusable scene (e.g. no geometry and no lights) and on a light the renderer's single-precision
    // transport cannot represent or cannot select (docs/lights.md, "Limits"). A scene without any
    // usable light gets a warning in info.warnings that says how to light it.
    void finalize();

    // Every query below skips the points of alpha-tested (MASK / BLEND) surfaces that the ray does
    // not find, the same way for all three (docs/materials.md, "Alpha").
    bool intersect(const Ray& ray, SurfaceHit* hit) const;
    // intersect() of n rays, traced together through Embree's stream API (the wavefront mode's
    // extend stage): found[i] = intersect(*rays[i], hits[i]), the same hits.
    void intersectStream(const Ray* const* rays, uint32_t n, SurfaceHit* const* hits, bool* found) const;
    // The mesh's interpolated attributes at barycentrics (b1, b2) of a triangle, and the material
    // parameters there (textures and vertex colour resolved).
    SurfaceAttributes attributes(uint32_t triangle, Vec2 bary) const;
    MaterialParams materialParams(uint32_t material, uint32_t triangle, Vec2 bary) const;
    // Bsdf(materialParams(material, triangle, bary), ns, ng), the same bits: for a material whose
    // parameters are the same everywhere (no texture, no vertex colours, no clearcoat) a copy of the
    // BSDF finalize() built for it, at these normals. The materials are fixed by finalize().
    Bsdf bsdfAt(uint32_t material, uint32_t triangle, Vec2 bary, const Vec3& ns, const Vec3& ng) const;
    // Barycentrics (b1, b2) of the point of a triangle's plane nearest to p (for paths read from
    // JSON without them); (0, 0) for an invalid triangle.
    Vec2 barycentricsOf(uint32_t triangle, const Vec3& p) const;
    // True when the segment between two points is unobstructed. n0/n1 are the geometric normals
    // at the endpoints used to offset them off their surfaces (zero vector: a point in space, e.g.
    // a point light or the pinhole). For an infinite light pass `towardsInfinity` = true and p1
    // as the direction.
    bool visible(const Vec3& p0, const Vec3& n0, const Vec3& p1, const Vec3& n1) const;
    bool visibleToInfinity(const Vec3& p0, const Vec3& n0, const Vec3& dir) const;
    // The ray visible() and visibleToInfinity() trace (offset origin, direction, t range: the
    // direction is not normalised for a segment, t in (0, 1) spans it), and many of them traced
    // together through Embree's stream API (the wavefront mode's shadow stages): occluded[i] is
    // what !visible... answers for the ends rays[i] was made from.
    static Ray segmentRay(const Vec3& p0, const Vec3& n0, const Vec3& p1, const Vec3& n1);
    static Ray infinityRay(const Vec3& p0, const Vec3& n0, const Vec3& dir);
    void occludedStream(const Ray* rays, uint32_t n, bool* occluded) const;

    const LightSampler& lightSampler() const { return lightSampler_; }
    // The light tree over the same lights (--light-sampler tree; docs/lights.md, "Light tree"),
    // built on the first call (thread-safe), so renders with the power sampler never pay its build.
    const LightTree& lightTree() const;
    int environmentLight() const { return envLight_; }
    // Bounds and bounding sphere of the geometry, in render space (toWorld for world coordinates).
    Vec3 boundsMin() const { return boundsMin_; }
    Vec3 boundsMax() const { return boundsMax_; }
    Vec3 boundingCenter() const { return center_; }
    float boundingRadius() const { return radius_; }
    // The light an escaped ray or an emissive hit belongs to.
    const Light* environment() const { return envLight_ >= 0 ? &lights[size_t(envLight_)] : nullptr; }
    // True once finalize() found no material with volume absorption: every segment's
    // transmittance is then 1 (segmentTransmittance skips the medium rule). False before finalize().
    bool absorptionFree() const { return absorptionFree_; }

private:
    void moveOriginToCamera();
    CoverageTest coverageTest() const;  // alpha coverage (src/scene/alpha.h) for the Embree filters
    void surfaceHitOf(const EmbreeHit& h, SurfaceHit* hit) const;
    void checkLightPowers(const std::vector<Light>& all, const std::vector<std::string>& names);
    std::unique_ptr<Accel> accel_;
    LightSampler lightSampler_;
    struct LazyLightTree;  // a std::once_flag and the tree (scene.cpp); null before finalize()
    std::unique_ptr<LazyLightTree> lightTree_;
    int envLight_ = -1;
    bool hasEnvironment_ = false;
    bool absorptionFree_ = false;
    std::vector<Bsdf> uniformBsdfs_;       // per material: its BSDF (zero normals) where uniformBsdf_
    std::vector<uint8_t> uniformBsdf_;     // per material: parameters the same at every point
    void buildUniformBsdfs();
    Rgb envRadiance_{0.f};
    int envMapIndex_ = -1;      // into environmentMaps; -1: the constant environment
    std::string envName_ = "the environment (--env)";
    Vec3 boundsMin_{0.f}, boundsMax_{0.f}, center_{0.f};
    float radius_ = 1.f;
};

}  // namespace bdptref
