// Small scenes built in code and lit only by a generated environment map (unit/test_env_map_maps.h),
// for the env-map render tests: a furnace cube, a diffuse plane, and a plane with two boxes.
#pragma once

#include "unit/test_env_map_maps.h"

#include "bdptref/scene.h"

#include <array>

namespace bdptref::test {

class EnvMapSceneBuilder {
public:
    uint32_t material(const Rgb& albedo, float metallic = 0.f, float roughness = 1.f) {
        Material m;
        m.name = "m" + std::to_string(scene.materials.size());
        m.baseColor = albedo;
        m.metallic = metallic;
        m.roughness = roughness;
        m.specular = metallic > 0.f ? 1.f : 0.f;  // dielectric without a specular layer: Lambert only
        scene.materials.push_back(m);
        return uint32_t(scene.materials.size() - 1);
    }
    void triangle(const Vec3& a, const Vec3& b, const Vec3& c, uint32_t m) {
        const Vec3 n = glm::normalize(glm::cross(b - a, c - a));
        const uint32_t base = uint32_t(scene.mesh.positions.size());
        for (const Vec3& p : {a, b, c}) {
            scene.mesh.positions.push_back(p);
            scene.mesh.normals.push_back(n);
            scene.mesh.vertexHasNormal.push_back(1);
        }
        scene.mesh.indices.push_back(glm::uvec3(base, base + 1, base + 2));
        scene.mesh.triangleMaterial.push_back(m);
    }
    // Counter-clockwise seen from the front.
    void quad(const std::array<Vec3, 4>& p, uint32_t m) {
        triangle(p[0], p[1], p[2], m);
        triangle(p[0], p[2], p[3], m);
    }
    // An axis-aligned box with outward faces.
    void box(const Vec3& lo, const Vec3& hi, uint32_t m) {
        const Vec3 a = lo, b = hi;
        quad({Vec3(a.x, a.y, b.z), Vec3(b.x, a.y, b.z), Vec3(b.x, b.y, b.z), Vec3(a.x, b.y, b.z)}, m);  // +z
        quad({Vec3(b.x, a.y, a.z), Vec3(a.x, a.y, a.z), Vec3(a.x, b.y, a.z), Vec3(b.x, b.y, a.z)}, m);  // -z
        quad({Vec3(b.x, a.y, b.z), Vec3(b.x, a.y, a.z), Vec3(b.x, b.y, a.z), Vec3(b.x, b.y, b.z)}, m);  // +x
        quad({Vec3(a.x, a.y, a.z), Vec3(a.x, a.y, b.z), Vec3(a.x, b.y, b.z), Vec3(a.x, b.y, a.z)}, m);  // -x
        quad({Vec3(a.x, b.y, b.z), Vec3(b.x, b.y, b.z), Vec3(b.x, b.y, a.z), Vec3(a.x, b.y, a.z)}, m);  // +y
        quad({Vec3(a.x, a.y, a.z), Vec3(b.x, a.y, a.z), Vec3(b.x, a.y, b.z), Vec3(a.x, a.y, b.z)}, m);  // -y
    }
    // The floor y = 0, |x|, |z| <= half, facing +y.
    void floor(float half, uint32_t m) {
        quad({Vec3(-half, 0, half), Vec3(half, 0, half), Vec3(half, 0, -half), Vec3(-half, 0, -half)}, m);
    }
    Scene finish(EnvironmentMap map, float scale, const Camera& camera) {
        scene.camera = camera;
        scene.setEnvironmentMap(std::move(map), scale, "test map");
        scene.finalize();
        return std::move(scene);
    }
    Scene scene;
};

// A grey Lambert cube (albedo rho) filling the whole image, under a map of constant value L.
inline Scene furnaceCubeScene(const Rgb& rho, const Rgb& L, int size) {
    EnvMapSceneBuilder b;
    b.box(Vec3(-0.5f), Vec3(0.5f), b.material(rho));
    const int w = 64, h = 32;
    EnvironmentMap map(w, h, texelsOf(w, h, [&](int, int) { return L; }), 0.4f);
    return b.finish(std::move(map), 1.f, Camera::lookAt(Vec3(0.f, 0.f, 3.f), Vec3(0.f), Vec3(0, 1, 0), 0.34f, size, size));
}

// A Lambert floor (albedo rho) seen from above, filling the image, under the sun-and-sky map.
inline Scene sunSkyPlaneScene(const Rgb& rho, float rotation, int size) {
    EnvMapSceneBuilder b;
    b.floor(2.f, b.material(rho));
    return b.finish(sunAndSkyMap(64, 32, rotation, 20000.f), 1.f,
                    Camera::lookAt(Vec3(0.1f, 3.f, 0.2f), Vec3(0.1f, 0.f, 0.2f), Vec3(0, 0, -1), 0.6f, size, size));
}

// A floor with a diffuse and a glossy metal box casting sun shadows, seen from above (the floor
// fills the image: light tracing cannot see the map directly). Every kind of environment path:
// escapes after a bounce, connections, emission onto surfaces.
inline Scene sunSkyBoxesScene(int width, int height, float sun = 2000.f) {
    EnvMapSceneBuilder b;
    b.floor(4.f, b.material(Rgb(0.6f, 0.55f, 0.5f)));
    b.box(Vec3(-0.9f, 0.f, -0.6f), Vec3(-0.1f, 0.8f, 0.2f), b.material(Rgb(0.3f, 0.5f, 0.8f)));
    b.box(Vec3(0.3f, 0.f, -0.2f), Vec3(0.9f, 0.5f, 0.4f), b.material(Rgb(0.9f, 0.7f, 0.4f), 1.f, 0.45f));
    return b.finish(sunAndSkyMap(64, 32, 0.7f, sun), 1.f,
                    Camera::lookAt(Vec3(0.f, 3.2f, 2.f), Vec3(0.f, 0.2f, -0.2f), Vec3(0, 1, 0), 0.7f, width, height));
}

}  // namespace bdptref::test
