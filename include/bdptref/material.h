// glTF metallic-roughness materials (with KHR_materials_transmission/ior/specular/
// emissive_strength) and the textures they reference. A Material is scene data; at a hit point it
// is resolved into MaterialParams (textures looked up) from which a Bsdf is built.
#pragma once

#include "bdptref/math.h"

#include <cstdint>
#include <string>
#include <vector>

namespace bdptref {

// An RGBA image decoded to linear floats (sRGB-encoded colour textures are decoded on load).
struct Texture {
    int width = 0, height = 0;
    std::vector<Vec4> texels;  // row-major, row 0 = top of the image (glTF uv (0,0) = top-left)
    enum class Wrap : uint8_t { Repeat, ClampToEdge, MirroredRepeat };
    Wrap wrapS = Wrap::Repeat, wrapT = Wrap::Repeat;
    bool nearest = false;  // magFilter NEAREST; otherwise bilinear

    Vec4 lookup(Vec2 uv) const;  // bilinear (or nearest) with the wrap modes
};

// glTF alphaMode (docs/materials.md, "Alpha"): how the coverage alpha (baseColorFactor alpha x
// baseColorTexture alpha) makes a surface partly absent. Opaque: alpha ignored. Mask: the surface
// is there iff alpha >= alphaCutoff. Blend: the surface is there with probability alpha.
enum class AlphaMode : uint8_t { Opaque, Mask, Blend };

struct Material {
    std::string name;
    Rgb baseColor{1.f};
    float baseAlpha = 1.f;         // coverage factor (alphaMode); never used for shading
    AlphaMode alphaMode = AlphaMode::Opaque;
    float alphaCutoff = 0.5f;      // Mask only (glTF default 0.5)
    int baseColorTexture = -1;     // index into Scene::textures; multiplies baseColor
    int metallicRoughnessTexture = -1;  // B = metallic, G = roughness (glTF convention)
    float metallic = 1.f;          // glTF defaults
    float roughness = 1.f;         // perceptual; alpha = roughness^2
    float ior = 1.5f;              // KHR_materials_ior
    float transmission = 0.f;      // KHR_materials_transmission (smooth only, see docs/materials.md)
    float specular = 1.f;          // KHR_materials_specular specularFactor
    Rgb specularColor{1.f};        // KHR_materials_specular specularColorFactor
    Rgb emission{0.f};             // emissiveFactor * emissive_strength (radiance)
    bool doubleSided = false;      // for emission only: see docs/materials.md
};

// A material's parameters at one surface point (textures resolved).
struct MaterialParams {
    Rgb baseColor{1.f};
    float metallic = 0.f;
    float roughness = 1.f;
    float ior = 1.5f;
    float transmission = 0.f;
    float specular = 1.f;
    Rgb specularColor{1.f};
};

MaterialParams resolveMaterial(const Material& m, const std::vector<Texture>& textures, Vec2 uv);

// The texture data of an sRGB-encoded 8-bit channel value in [0,1] -> linear.
float srgbToLinear(float c);

}  // namespace bdptref
