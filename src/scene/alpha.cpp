// Alpha coverage: docs/materials.md ("Alpha"), docs/rng.md ("Alpha coverage").
#include "scene/alpha.h"

#include "bdptref/rng.h"
#include "bdptref/scene.h"

#include <cstring>

namespace bdptref {

bool needsAlphaTest(const Material& m, bool colors) {
    switch (m.alphaMode) {
        case AlphaMode::Opaque: return false;
        case AlphaMode::Mask: return m.baseColorTexture.valid() || colors || !(m.baseAlpha >= m.alphaCutoff);
        case AlphaMode::Blend: return m.baseColorTexture.valid() || colors || !(m.baseAlpha >= 1.f);
    }
    return false;
}

float surfaceCoverage(const Scene& scene, uint32_t triangle, Vec2 barycentrics) {
    const Material& m = scene.materials[scene.mesh.triangleMaterial[triangle]];
    // The alpha of the base colour: factor x texture (its TEXCOORD set and transform) x COLOR_0,
    // from the same attributes the shading reads (Scene::attributes), so both see the same texel.
    const SurfaceAttributes at = scene.attributes(triangle, barycentrics);
    return m.baseAlpha * sampleTexture(m.baseColorTexture, scene.textures, at).a * at.color.a;
}

namespace {
uint32_t bitsOf(float f) {
    uint32_t u;
    std::memcpy(&u, &f, sizeof u);
    return u;
}
// Key of the first Philox call: "alph", "aBld" in ASCII (any fixed constant; written in docs/rng.md).
constexpr PhiloxKey kAlphaKey = {0x616C7068u, 0x61426C64u};
}  // namespace

float blendDecisionNumber(const Vec3& origin, const Vec3& dir, uint32_t triangle) {
    // Two chained Philox blocks hash all 7 words (origin, direction, triangle) without folding
    // bits together: the first turns the origin into a key, the second encrypts the direction.
    const PhiloxCounter k = philox4x32_10({bitsOf(origin.x), bitsOf(origin.y), bitsOf(origin.z), triangle}, kAlphaKey);
    const PhiloxCounter w = philox4x32_10({bitsOf(dir.x), bitsOf(dir.y), bitsOf(dir.z), triangle}, {k[0], k[1]});
    return uintToUnitFloat(w[0]);
}

bool surfaceCovers(const Scene& scene, uint32_t triangle, Vec2 barycentrics, const Vec3& origin, const Vec3& dir) {
    const Material& m = scene.materials[scene.mesh.triangleMaterial[triangle]];
    switch (m.alphaMode) {
        case AlphaMode::Opaque: return true;
        case AlphaMode::Mask: return surfaceCoverage(scene, triangle, barycentrics) >= m.alphaCutoff;
        case AlphaMode::Blend: {
            const float alpha = surfaceCoverage(scene, triangle, barycentrics);
            // u in [0, 1): alpha >= 1 always covers and alpha <= 0 never does, without hashing.
            return alpha >= 1.f || (alpha > 0.f && blendDecisionNumber(origin, dir, triangle) < alpha);
        }
    }
    return true;
}

}  // namespace bdptref
