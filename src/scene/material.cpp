// Material parameter resolution at a hit point and the sRGB transfer function (texture storage and
// filtering: texture.cpp).
// Conventions: docs/materials.md ("Textures").
#include "bdptref/material.h"

#include <cmath>

namespace bdptref {

Vec4 sampleTexture(const TextureRef& ref, const std::vector<Texture>& textures, const SurfaceAttributes& at) {
    if (ref.texture < 0 || size_t(ref.texture) >= textures.size()) return Vec4(1.f);
    const int set = ref.texCoord >= 0 && ref.texCoord < kMaxTexCoordSets ? ref.texCoord : 0;
    const Vec3 uv1(at.uv[set], 1.f);
    return textures[size_t(ref.texture)].lookup(Vec2(glm::dot(ref.row0, uv1), glm::dot(ref.row1, uv1)));
}

MaterialParams resolveMaterial(const Material& m, const std::vector<Texture>& textures, const SurfaceAttributes& at) {
    MaterialParams p;
    p.baseColor = m.baseColor;
    p.metallic = m.metallic;
    p.roughness = m.roughness;
    p.ior = m.ior;
    p.transmission = m.transmission;
    p.specular = m.specular;
    p.specularColor = m.specularColor;
    p.baseColor *= Rgb(at.color.r, at.color.g, at.color.b);  // COLOR_0 (1 where absent)
    if (m.baseColorTexture.valid()) {
        const Vec4 t = sampleTexture(m.baseColorTexture, textures, at);
        p.baseColor *= Rgb(t.r, t.g, t.b);
    }
    if (m.metallicRoughnessTexture.valid()) {
        const Vec4 t = sampleTexture(m.metallicRoughnessTexture, textures, at);
        p.roughness *= t.g;  // glTF: G channel = roughness
        p.metallic *= t.b;   // glTF: B channel = metallic
    }
    if (m.transmissionTexture.valid()) p.transmission *= sampleTexture(m.transmissionTexture, textures, at).r;
    if (m.specularTexture.valid()) p.specular *= sampleTexture(m.specularTexture, textures, at).a;
    if (m.specularColorTexture.valid()) {
        const Vec4 t = sampleTexture(m.specularColorTexture, textures, at);
        p.specularColor *= Rgb(t.r, t.g, t.b);
    }
    p.sheenColor = m.sheenColor;
    p.sheenRoughness = m.sheenRoughness;
    if (!isBlack(p.sheenColor)) {
        if (m.sheenColorTexture.valid()) {
            const Vec4 t = sampleTexture(m.sheenColorTexture, textures, at);
            p.sheenColor *= Rgb(t.r, t.g, t.b);
        }
        if (m.sheenRoughnessTexture.valid()) p.sheenRoughness *= sampleTexture(m.sheenRoughnessTexture, textures, at).a;
    }
    p.clearcoat = m.clearcoat;
    p.clearcoatRoughness = m.clearcoatRoughness;
    if (p.clearcoat > 0.f) {
        if (m.clearcoatTexture.valid()) p.clearcoat *= sampleTexture(m.clearcoatTexture, textures, at).r;
        if (m.clearcoatRoughnessTexture.valid())
            p.clearcoatRoughness *= sampleTexture(m.clearcoatRoughnessTexture, textures, at).g;
    }
    return p;
}

float srgbToLinear(float c) {
    // IEC 61966-2-1 sRGB EOTF.
    if (c <= 0.04045f) return c / 12.92f;
    return float(std::pow((double(c) + 0.055) / 1.055, 2.4));
}

}  // namespace bdptref
