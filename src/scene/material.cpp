// Material parameter resolution at a hit point, texture filtering and the sRGB transfer function.
// Conventions: docs/materials.md ("Textures").
#include "bdptref/material.h"

#include <algorithm>
#include <cmath>

namespace bdptref {

namespace {

// Texel index i (any integer, as a double holding an integer) wrapped into [0, n) by the glTF /
// OpenGL wrap mode (OpenGL 4.6 spec, section 8.14.2: wrapping applies to texel indices).
int wrapIndex(double i, int n, Texture::Wrap mode) {
    switch (mode) {
        case Texture::Wrap::ClampToEdge:
            return int(std::min(std::max(i, 0.0), double(n - 1)));
        case Texture::Wrap::MirroredRepeat: {
            const double period = 2.0 * n;
            const int m = int(i - period * std::floor(i / period));  // [0, 2n)
            const int r = std::min(std::max(m, 0), 2 * n - 1);
            return r < n ? r : 2 * n - 1 - r;
        }
        case Texture::Wrap::Repeat:
        default: {
            const int m = int(i - n * std::floor(i / n));
            return std::min(std::max(m, 0), n - 1);
        }
    }
}

// Reduces a texel coordinate before it is converted to an integer so that huge uv values cannot
// overflow: shifting by a multiple of 2n changes no wrap mode's result, and clamping stays put.
double reduceIndex(double i, int n, Texture::Wrap mode) {
    if (mode == Texture::Wrap::ClampToEdge) return std::min(std::max(i, -1.0), double(n));
    const double period = 2.0 * n;
    return i - period * std::floor(i / period);
}

}  // namespace

Vec4 Texture::lookup(Vec2 uv) const {
    if (width <= 0 || height <= 0 || texels.size() < size_t(width) * size_t(height)) return Vec4(1.f);
    const double u = std::isfinite(uv.x) ? double(uv.x) : 0.0;
    const double v = std::isfinite(uv.y) ? double(uv.y) : 0.0;
    auto texel = [&](int x, int y) { return glm::dvec4(texels[size_t(y) * size_t(width) + size_t(x)]); };
    if (nearest) {
        const double fx = reduceIndex(std::floor(u * width), width, wrapS);
        const double fy = reduceIndex(std::floor(v * height), height, wrapT);
        return Vec4(texel(wrapIndex(fx, width, wrapS), wrapIndex(fy, height, wrapT)));
    }
    // Bilinear between the four nearest texel centres; texel (i, j) has its centre at
    // uv = ((i + 0.5) / width, (j + 0.5) / height), uv (0,0) is the top-left corner of texel (0,0).
    const double x = u * width - 0.5;
    const double y = v * height - 0.5;
    const double x0 = std::floor(x), y0 = std::floor(y);
    const double tx = x - x0, ty = y - y0;
    const double rx = reduceIndex(x0, width, wrapS), ry = reduceIndex(y0, height, wrapT);
    const int i0 = wrapIndex(rx, width, wrapS), i1 = wrapIndex(rx + 1.0, width, wrapS);
    const int j0 = wrapIndex(ry, height, wrapT), j1 = wrapIndex(ry + 1.0, height, wrapT);
    const glm::dvec4 top = texel(i0, j0) * (1.0 - tx) + texel(i1, j0) * tx;
    const glm::dvec4 bottom = texel(i0, j1) * (1.0 - tx) + texel(i1, j1) * tx;
    return Vec4(top * (1.0 - ty) + bottom * ty);
}

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
    return p;
}

float srgbToLinear(float c) {
    // IEC 61966-2-1 sRGB EOTF.
    if (c <= 0.04045f) return c / 12.92f;
    return float(std::pow((double(c) + 0.055) / 1.055, 2.4));
}

}  // namespace bdptref
