// glTF metallic-roughness materials (with KHR_materials_transmission/ior/specular/volume/
// emissive_strength/clearcoat/sheen) and the textures they reference. A Material is scene data; at a hit point it
// is resolved into MaterialParams (textures looked up) from which a Bsdf is built.
#pragma once

#include "bdptref/math.h"

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace bdptref {

// A texture: an image's texels as the file stores them (8- or 16-bit unsigned normalized, or float),
// with its channel count, decoded to linear RGBA when read. The bytes are shared: the Textures made
// from one image (e.g. sRGB for base colour, linear for metallic-roughness) hold the same data.
struct Texture {
    enum class Format : uint8_t { Unorm8, Unorm16, Float32 };
    enum class Wrap : uint8_t { Repeat, ClampToEdge, MirroredRepeat };
    int width = 0, height = 0;
    int channels = 4;               // 1 grey, 2 grey + alpha, 3 RGB, 4 RGBA
    Format format = Format::Unorm8;
    bool srgb = false;              // colour channels are sRGB-encoded (alpha never is)
    // Row-major, row 0 = top of the image (glTF uv (0,0) = top-left); channels interleaved; native
    // byte order for 16-bit and float.
    std::shared_ptr<const std::vector<uint8_t>> data;
    Wrap wrapS = Wrap::Repeat, wrapT = Wrap::Repeat;
    bool nearest = false;  // magFilter NEAREST; otherwise bilinear

    // A float RGBA texture from linear values (tests, generated data).
    static Texture fromLinear(int width, int height, const std::vector<Vec4>& rgba);
    size_t bytesPerTexel() const;
    bool valid() const;                 // data holds width x height texels of this format
    Vec4 texel(int x, int y) const;     // linear RGBA; x in [0, width), y in [0, height), valid()
    Vec4 lookup(Vec2 uv) const;         // bilinear (or nearest) with the wrap modes; (1,1,1,1) if !valid()
};

// Texture coordinate sets a mesh may carry (glTF TEXCOORD_0 .. TEXCOORD_3).
constexpr int kMaxTexCoordSets = 4;

// A material's reference to a texture: which texture, which TEXCOORD_n set, and an affine uv
// transform (KHR_texture_transform; identity otherwise): uv' = (row0 . (u, v, 1), row1 . (u, v, 1)).
struct TextureRef {
    int texture = -1;  // index into Scene::textures; -1: none
    int texCoord = 0;  // TEXCOORD_n
    Vec3 row0{1.f, 0.f, 0.f};
    Vec3 row1{0.f, 1.f, 0.f};
    bool valid() const { return texture >= 0; }
};

// What the mesh interpolates at a surface point for the material: every texture coordinate set
// (zero where the primitive lacks it) and the vertex colour COLOR_0 (1 where absent).
struct SurfaceAttributes {
    Vec2 uv[kMaxTexCoordSets] = {Vec2(0.f), Vec2(0.f), Vec2(0.f), Vec2(0.f)};
    Vec4 color{1.f};
};

// A texture's value at a surface point (its TEXCOORD set, transformed); Vec4(1) for no texture.
Vec4 sampleTexture(const TextureRef& ref, const std::vector<Texture>& textures, const SurfaceAttributes& at);

// glTF alphaMode (docs/materials.md, "Alpha"): how the coverage alpha (baseColorFactor alpha x
// baseColorTexture alpha x COLOR_0 alpha) makes a surface partly absent. Opaque: alpha ignored. Mask: the surface
// is there iff alpha >= alphaCutoff. Blend: the surface is there with probability alpha.
enum class AlphaMode : uint8_t { Opaque, Mask, Blend };

struct Material {
    std::string name;
    Rgb baseColor{1.f};
    float baseAlpha = 1.f;         // coverage factor (alphaMode); never used for shading
    AlphaMode alphaMode = AlphaMode::Opaque;
    float alphaCutoff = 0.5f;      // Mask only (glTF default 0.5)
    TextureRef baseColorTexture;          // multiplies baseColor (and COLOR_0)
    TextureRef metallicRoughnessTexture;  // B = metallic, G = roughness (glTF convention)
    TextureRef normalTexture;             // tangent-space normal map (docs/materials.md, "Normal maps")
    float normalScale = 1.f;              // normalTexture.scale
    float metallic = 1.f;          // glTF defaults
    float roughness = 1.f;         // perceptual; alpha = roughness^2
    float ior = 1.5f;              // KHR_materials_ior
    float transmission = 0.f;      // KHR_materials_transmission (smooth or rough, see docs/materials.md)
    float specular = 1.f;          // KHR_materials_specular specularFactor
    Rgb specularColor{1.f};        // KHR_materials_specular specularColorFactor
    TextureRef transmissionTexture;   // R multiplies transmission (linear)
    TextureRef specularTexture;       // A multiplies specular (linear)
    TextureRef specularColorTexture;  // RGB multiplies specularColor (sRGB)
    Rgb emission{0.f};             // emissiveFactor * emissive_strength (radiance)
    TextureRef emissiveTexture;    // multiplies emission (sRGB); see docs/lights.md
    bool doubleSided = false;      // for emission only: see docs/materials.md
    // KHR_materials_volume: absorption coefficient sigma_a = -ln(attenuationColor) / attenuationDistance
    // per channel (1 / world length; +inf for a zero colour channel) of the medium enclosed by the
    // meshes of this material; zero: no absorption. Applied along path segments by
    // segmentTransmittance (src/render/segment_transmittance.h, docs/materials.md "Volume absorption").
    Rgb absorption{0.f};
    // KHR_materials_clearcoat (docs/materials.md, "Clearcoat"): a GGX coat of IOR 1.5 over the
    // material, weighted by clearcoat x clearcoatTexture.R; its roughness is clearcoatRoughness x
    // clearcoatRoughnessTexture.G. The coat's normal is the interpolated vertex normal (not the
    // base's normal map), perturbed by clearcoatNormalTexture when there is one.
    float clearcoat = 0.f;
    float clearcoatRoughness = 0.f;
    TextureRef clearcoatTexture;           // R multiplies clearcoat (linear)
    TextureRef clearcoatRoughnessTexture;  // G multiplies clearcoatRoughness (linear)
    TextureRef clearcoatNormalTexture;     // tangent-space normal map of the coat
    float clearcoatNormalScale = 1.f;      // clearcoatNormalTexture.scale
    // KHR_materials_sheen (docs/materials.md, "Sheen"): a Charlie sheen lobe over the base, colour
    // sheenColor x sheenColorTexture.RGB (sRGB), roughness sheenRoughness x sheenRoughnessTexture.A.
    Rgb sheenColor{0.f};
    float sheenRoughness = 0.f;
    TextureRef sheenColorTexture;
    TextureRef sheenRoughnessTexture;
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
    float clearcoat = 0.f;           // coat weight in [0,1]; 0: no coat
    float clearcoatRoughness = 0.f;  // perceptual; the coat's alpha = clearcoatRoughness^2 (0: a delta coat)
    // The coat's unit normal (world space), or zero: the coat uses the shading normal the Bsdf is
    // given. Scene::materialParams sets it where it differs from that normal (a base normal map, or
    // a clearcoatNormalTexture).
    Vec3 clearcoatNormal{0.f};
    Rgb sheenColor{0.f};        // 0: no sheen
    float sheenRoughness = 0.f;  // perceptual; alpha = sheenRoughness^2 (floored, docs/materials.md)
};

// Textures resolved, the coat normal left zero (it needs the surface: Scene::materialParams).
MaterialParams resolveMaterial(const Material& m, const std::vector<Texture>& textures, const SurfaceAttributes& at);

// The texture data of an sRGB-encoded 8-bit channel value in [0,1] -> linear.
float srgbToLinear(float c);

}  // namespace bdptref
