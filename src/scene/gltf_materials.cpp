// glTF materials (metallic-roughness core and the supported KHR_materials_* extensions) and
// their textures.

#include "scene/gltf_loader_internal.h"

namespace bdptref {
namespace gltfload {

// ----- materials and textures

float Loader::factor(double v, const std::string& who, double lo, double hi) const {
    const float f = float(v);
    if (!std::isfinite(v) || !std::isfinite(f)) fail(who + " is not finite (" + fmt(v) + ")");
    if (v < 0.0 && lo >= 0.0) fail(who + " is negative (" + fmt(v) + ")");
    if (v < lo || v > hi) fail(who + " = " + fmt(v) + " is outside [" + fmt(lo) + ", " + fmt(hi) + "]");
    return f;
}

MaterialUse Loader::material(int gltfIndex) {
    auto it = materialMap_.find(gltfIndex);
    if (it != materialMap_.end()) return it->second;
    MaterialUse use;
    unsigned sets = 0;
    Material m = convertMaterial(gltfIndex, &sets);
    use.sceneIndex = int(scene_.materials.size());
    use.texCoordSets = sets;
    scene_.materials.push_back(std::move(m));
    materialMap_[gltfIndex] = use;
    return use;
}

TextureRef Loader::textureRef(const std::string& who, int index, int texCoord, const tinygltf::ExtensionMap& extensions,
                              bool srgb, unsigned* texCoordSets) {
    TextureRef ref;
    auto it = extensions.find("KHR_texture_transform");
    if (it != extensions.end()) textureTransform(who + ": KHR_texture_transform", it->second, &ref, &texCoord);
    if (texCoord < 0 || texCoord >= kMaxTexCoordSets)
        fail(who + ": texCoord " + std::to_string(texCoord) + " is not supported (TEXCOORD_0 to TEXCOORD_" +
             std::to_string(kMaxTexCoordSets - 1) + " are)");
    ref.texture = texture(who, index, srgb);
    // The slot's name is the last word of `who` ("material 2 ('x') baseColorTexture").
    useFeature(who.substr(who.find_last_of(' ') + 1));
    ref.texCoord = texCoord;
    *texCoordSets |= 1u << unsigned(texCoord);
    return ref;
}

// KHR_texture_transform: uv' = T(offset) R(rotation) S(scale) uv. The rotation is the one the
// Khronos sample renderer and the TextureTransformTest model use, R = [cos sin; -sin cos]: a
// counter-clockwise turn of the uv axes as drawn with v pointing down (glTF issue #1563: the
// extension's GLSL listing, read column-major, has the opposite sign). docs/materials.md "Textures".
void Loader::textureTransform(const std::string& who, const tinygltf::Value& t, TextureRef* ref, int* texCoord) const {
    if (!t.IsObject()) fail(who + " must be an object");
    auto number = [&](const tinygltf::Value& v, const std::string& name) {
        if (!v.IsNumber()) fail(who + "." + name + " is not a number");
        const double x = v.GetNumberAsDouble();
        if (!std::isfinite(x) || !std::isfinite(float(x))) fail(who + "." + name + " is not finite (" + fmt(x) + ")");
        return x;
    };
    auto pair = [&](const char* key, double def, double out[2]) {
        out[0] = out[1] = def;
        if (!t.Has(key)) return;
        const tinygltf::Value& a = t.Get(key);
        if (!a.IsArray() || a.ArrayLen() != 2) fail(who + "." + key + " must be an array of 2 numbers");
        for (int i = 0; i < 2; ++i) out[i] = number(a.Get(i), std::string(key) + "[" + std::to_string(i) + "]");
    };
    double offset[2], scale[2];
    pair("offset", 0.0, offset);
    pair("scale", 1.0, scale);
    const double rotation = t.Has("rotation") ? number(t.Get("rotation"), "rotation") : 0.0;
    if (t.Has("texCoord")) {
        const tinygltf::Value& v = t.Get("texCoord");
        if (!v.IsInt() || v.Get<int>() < 0) fail(who + ".texCoord must be a non-negative integer");
        *texCoord = v.Get<int>();  // overrides the textureInfo's texCoord (the extension's rule)
    }
    const double c = std::cos(rotation), s = std::sin(rotation);
    ref->row0 = Vec3(float(c * scale[0]), float(s * scale[1]), float(offset[0]));
    ref->row1 = Vec3(float(-s * scale[0]), float(c * scale[1]), float(offset[1]));
}

int Loader::texture(const std::string& who, int index, bool srgb) {
    if (index < 0 || size_t(index) >= model_.textures.size())
        fail(who + ": texture " + std::to_string(index) + " does not exist (the file has " + std::to_string(model_.textures.size()) +
             " textures)");
    const TextureKey key{index, srgb};
    auto it = textureMap_.find(key);
    if (it != textureMap_.end()) return it->second;

    const tinygltf::Texture& tex = model_.textures[size_t(index)];
    const std::string tw = who + ": texture " + std::to_string(index);
    if (tex.source < 0 || size_t(tex.source) >= model_.images.size())
        fail(tw + " has no usable image source (source " + std::to_string(tex.source) +
             "; images provided only through extensions are not supported)");
    Texture out;
    if (tex.sampler >= 0 || tex.sampler < -1) {
        if (tex.sampler < 0 || size_t(tex.sampler) >= model_.samplers.size())
            fail(tw + ": sampler " + std::to_string(tex.sampler) + " does not exist");
        const tinygltf::Sampler& s = model_.samplers[size_t(tex.sampler)];
        auto wrap = [&](int v, const char* name) {
            switch (v) {
                case TINYGLTF_TEXTURE_WRAP_REPEAT: return Texture::Wrap::Repeat;
                case TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE: return Texture::Wrap::ClampToEdge;
                case TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT: return Texture::Wrap::MirroredRepeat;
                default: fail(tw + ": sampler " + std::to_string(tex.sampler) + " has invalid " + name + " " + std::to_string(v));
            }
        };
        out.wrapS = wrap(s.wrapS, "wrapS");
        out.wrapT = wrap(s.wrapT, "wrapT");
        if (s.magFilter == TINYGLTF_TEXTURE_FILTER_NEAREST)
            out.nearest = true;
        else if (s.magFilter != TINYGLTF_TEXTURE_FILTER_LINEAR && s.magFilter != -1)
            fail(tw + ": sampler " + std::to_string(tex.sampler) + " has invalid magFilter " + std::to_string(s.magFilter));
        // minFilter is validated but not used: no mip-mapping (docs/materials.md, "Textures").
        switch (s.minFilter) {
            case -1:
            case TINYGLTF_TEXTURE_FILTER_NEAREST:
            case TINYGLTF_TEXTURE_FILTER_LINEAR:
            case TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_NEAREST:
            case TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_NEAREST:
            case TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_LINEAR:
            case TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_LINEAR: break;
            default: fail(tw + ": sampler " + std::to_string(tex.sampler) + " has invalid minFilter " + std::to_string(s.minFilter));
        }
    }

    const Texture& img = image(tw, tex.source);
    out.width = img.width;
    out.height = img.height;
    out.channels = img.channels;
    out.format = img.format;
    out.data = img.data;
    out.srgb = srgb;
    const int sceneIndex = int(scene_.textures.size());
    scene_.textures.push_back(std::move(out));
    textureMap_[key] = sceneIndex;
    return sceneIndex;
}

// An image's texels as decoded (8 or 16 bit, its own channel count), checked once and moved out of
// the model: every Texture made from it (other samplers, sRGB and linear uses) shares the bytes.
const Texture& Loader::image(const std::string& tw, int source) {
    auto it = images_.find(source);
    if (it != images_.end()) return it->second;
    tinygltf::Image& img = model_.images[size_t(source)];
    const std::string iw = tw + ": image " + std::to_string(source) + (img.uri.empty() || img.uri.compare(0, 5, "data:") == 0
                                                                         ? std::string()
                                                                         : " ('" + img.uri + "')");
    if (img.image.empty() || img.width <= 0 || img.height <= 0)
        fail(iw + " could not be loaded or is empty");
    if (img.component < 1 || img.component > 4) fail(iw + " has " + std::to_string(img.component) + " channels (expected 1 to 4)");
    if (img.bits != 8 && img.bits != 16) fail(iw + " has " + std::to_string(img.bits) + " bits per channel (expected 8 or 16)");
    const size_t bytesPer = size_t(img.bits / 8);
    const size_t texels = size_t(img.width) * size_t(img.height);
    if (img.image.size() != texels * size_t(img.component) * bytesPer)
        fail(iw + ": decoded data has " + std::to_string(img.image.size()) + " bytes, expected " +
             std::to_string(texels * size_t(img.component) * bytesPer));
    Texture t;
    t.width = img.width;
    t.height = img.height;
    t.channels = img.component;
    t.format = img.bits == 8 ? Texture::Format::Unorm8 : Texture::Format::Unorm16;
    t.data = std::make_shared<const std::vector<uint8_t>>(std::move(img.image));
    img.image = std::vector<unsigned char>();
    return images_.emplace(source, std::move(t)).first->second;
}

Material Loader::convertMaterial(int gi, unsigned* texCoordSets) {
    const tinygltf::Material& g = model_.materials[size_t(gi)];
    const std::string who = "material " + std::to_string(gi) + (g.name.empty() ? "" : " ('" + g.name + "')");
    const auto& pbr = g.pbrMetallicRoughness;
    Material m;
    m.name = g.name;

    if (pbr.baseColorFactor.size() != 4) fail(who + ": baseColorFactor must have 4 elements");
    m.baseColor = Rgb(factor(pbr.baseColorFactor[0], who + ": baseColorFactor[0]", 0.0, 1.0),
                      factor(pbr.baseColorFactor[1], who + ": baseColorFactor[1]", 0.0, 1.0),
                      factor(pbr.baseColorFactor[2], who + ": baseColorFactor[2]", 0.0, 1.0));
    m.baseAlpha = factor(pbr.baseColorFactor[3], who + ": baseColorFactor[3]", 0.0, 1.0);
    m.metallic = factor(pbr.metallicFactor, who + ": metallicFactor", 0.0, 1.0);
    m.roughness = factor(pbr.roughnessFactor, who + ": roughnessFactor", 0.0, 1.0);

    // alphaMode (docs/materials.md, "Alpha"); the emissive check is below, once emission is known.
    if (g.alphaMode == "MASK") {
        m.alphaMode = AlphaMode::Mask;
        useFeature("alphaMode MASK");
        m.alphaCutoff = factor(g.alphaCutoff, who + ": alphaCutoff", 0.0, std::numeric_limits<double>::max());
    } else if (g.alphaMode == "BLEND") {
        m.alphaMode = AlphaMode::Blend;
        useFeature("alphaMode BLEND");
    } else if (g.alphaMode != "OPAQUE") {
        fail(who + ": invalid alphaMode '" + g.alphaMode + "'");
    }
    m.doubleSided = g.doubleSided;

    if (pbr.baseColorTexture.index >= 0) {
        m.baseColorTexture = textureRef(who + " baseColorTexture", pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord,
                                        pbr.baseColorTexture.extensions, true, texCoordSets);
    }
    if (pbr.metallicRoughnessTexture.index >= 0) {
        m.metallicRoughnessTexture = textureRef(who + " metallicRoughnessTexture", pbr.metallicRoughnessTexture.index,
                                                pbr.metallicRoughnessTexture.texCoord, pbr.metallicRoughnessTexture.extensions, false,
                                                texCoordSets);
    }
    if (g.normalTexture.index >= 0) {
        // Linear data (not sRGB); the perturbation is docs/materials.md, "Normal maps".
        m.normalTexture = textureRef(who + " normalTexture", g.normalTexture.index, g.normalTexture.texCoord,
                                     g.normalTexture.extensions, false, texCoordSets);
        m.normalScale = factor(g.normalTexture.scale, who + ": normalTexture.scale", -std::numeric_limits<double>::max(),
                               std::numeric_limits<double>::max());
    }
    if (g.occlusionTexture.index >= 0)
        warn(who, "occlusionTexture ignored (occlusion is computed by the light transport itself)");

    // Reads a number from an extension object; absent -> def.
    auto number = [&](const tinygltf::Value& obj, const char* ext, const char* key, double def) {
        if (!obj.IsObject() || !obj.Has(key)) return def;
        const tinygltf::Value& v = obj.Get(key);
        if (!v.IsNumber()) fail(who + ": " + ext + "." + key + " is not a number");
        return v.GetNumberAsDouble();
    };
    // A textureInfo inside a material extension (tinygltf leaves these as JSON values).
    auto extTexture = [&](const tinygltf::Value& obj, const char* ext, const char* key, bool srgb) {
        TextureRef ref;
        if (!obj.IsObject() || !obj.Has(key)) return ref;
        const std::string w = who + " " + ext + "." + key;
        const tinygltf::Value& info = obj.Get(key);
        if (!info.IsObject() || !info.Has("index") || !info.Get("index").IsInt()) fail(w + " must be an object with an integer index");
        int texCoord = 0;
        if (info.Has("texCoord")) {
            if (!info.Get("texCoord").IsInt()) fail(w + ".texCoord must be an integer");
            texCoord = info.Get("texCoord").Get<int>();
        }
        tinygltf::ExtensionMap extensions;
        if (info.Has("extensions")) {
            const tinygltf::Value& e = info.Get("extensions");
            if (!e.IsObject()) fail(w + ".extensions must be an object");
            for (const std::string& k : e.Keys()) extensions[k] = e.Get(k);
        }
        return textureRef(w, info.Get("index").Get<int>(), texCoord, extensions, srgb, texCoordSets);
    };
    auto ext = [&](const char* name) -> const tinygltf::Value* {
        auto it = g.extensions.find(name);
        return it == g.extensions.end() ? nullptr : &it->second;
    };

    double strength = 1.0;
    if (const tinygltf::Value* e = ext("KHR_materials_emissive_strength"))
        strength = factor(number(*e, "KHR_materials_emissive_strength", "emissiveStrength", 1.0),
                          who + ": KHR_materials_emissive_strength.emissiveStrength", 0.0, std::numeric_limits<double>::max());
    if (g.emissiveFactor.size() != 3) fail(who + ": emissiveFactor must have 3 elements");
    bool emissiveAboveOne = false;
    for (int c = 0; c < 3; ++c) {
        const double f = g.emissiveFactor[size_t(c)];
        factor(f, who + ": emissiveFactor[" + std::to_string(c) + "]", 0.0, std::numeric_limits<double>::max());
        emissiveAboveOne = emissiveAboveOne || f > 1.0;
        m.emission[c] = factor(f * strength, who + ": emission (emissiveFactor[" + std::to_string(c) + "] * emissiveStrength)", 0.0,
                               std::numeric_limits<double>::max());
    }
    if (emissiveAboveOne)
        warn(who, "emissiveFactor above 1 (outside the glTF schema's range) used as given");
    if (g.emissiveTexture.index >= 0) {
        // emission = emissiveFactor * strength * emissiveTexture (sRGB); the area lights evaluate it
        // at each point (docs/lights.md, "Emissive textures").
        if (!isBlack(m.emission))
            m.emissiveTexture = textureRef(who + " emissiveTexture", g.emissiveTexture.index, g.emissiveTexture.texCoord,
                                           g.emissiveTexture.extensions, true, texCoordSets);
        else
            warn(who, "emissiveTexture ignored (the emissive factor is zero, so it has no effect)");
    }

    if (m.alphaMode != AlphaMode::Opaque && !isBlack(m.emission))
        fail(who + ": alphaMode " + g.alphaMode + " on an emissive material is not supported (an area light with partial "
                   "coverage would need the coverage in light sampling and every light density); make the emitter OPAQUE");

    if (const tinygltf::Value* e = ext("KHR_materials_ior")) {
        const double ior = number(*e, "KHR_materials_ior", "ior", 1.5);
        if (!std::isfinite(ior) || !std::isfinite(float(ior))) fail(who + ": KHR_materials_ior.ior is not finite");
        if (ior != 0.0 && ior < 1.0)
            fail(who + ": KHR_materials_ior.ior = " + fmt(ior) + " is invalid (must be >= 1, or exactly 0)");
        m.ior = float(ior);
    }
    if (const tinygltf::Value* e = ext("KHR_materials_transmission")) {
        m.transmissionTexture = extTexture(*e, "KHR_materials_transmission", "transmissionTexture", false);
        m.transmission = factor(number(*e, "KHR_materials_transmission", "transmissionFactor", 0.0),
                                who + ": KHR_materials_transmission.transmissionFactor", 0.0, 1.0);
    }
    if (const tinygltf::Value* e = ext("KHR_materials_specular")) {
        m.specularTexture = extTexture(*e, "KHR_materials_specular", "specularTexture", false);
        m.specularColorTexture = extTexture(*e, "KHR_materials_specular", "specularColorTexture", true);
        m.specular = factor(number(*e, "KHR_materials_specular", "specularFactor", 1.0),
                            who + ": KHR_materials_specular.specularFactor", 0.0, 1.0);
        if (e->IsObject() && e->Has("specularColorFactor")) {
            const tinygltf::Value& a = e->Get("specularColorFactor");
            if (!a.IsArray() || a.ArrayLen() != 3) fail(who + ": KHR_materials_specular.specularColorFactor must be an array of 3 numbers");
            for (int c = 0; c < 3; ++c) {
                const tinygltf::Value& v = a.Get(c);
                if (!v.IsNumber()) fail(who + ": KHR_materials_specular.specularColorFactor must be an array of 3 numbers");
                m.specularColor[c] = factor(v.GetNumberAsDouble(), who + ": KHR_materials_specular.specularColorFactor[" +
                                                                      std::to_string(c) + "]",
                                            0.0, std::numeric_limits<double>::max());
            }
        }
    }
    if (const tinygltf::Value* e = ext("KHR_materials_volume")) volume(who, *e, ext("KHR_materials_transmission") != nullptr, &m);
    if (const tinygltf::Value* e = ext("KHR_materials_sheen")) {
        // docs/materials.md, "Sheen": colour x sheenColorTexture.RGB (sRGB), roughness x
        // sheenRoughnessTexture.A (linear).
        const char* sh = "KHR_materials_sheen";
        if (e->IsObject() && e->Has("sheenColorFactor")) {
            const tinygltf::Value& a = e->Get("sheenColorFactor");
            if (!a.IsArray() || a.ArrayLen() != 3) fail(who + ": KHR_materials_sheen.sheenColorFactor must be an array of 3 numbers");
            for (int c = 0; c < 3; ++c) {
                const tinygltf::Value& v = a.Get(c);
                if (!v.IsNumber()) fail(who + ": KHR_materials_sheen.sheenColorFactor must be an array of 3 numbers");
                m.sheenColor[c] = factor(v.GetNumberAsDouble(), who + ": KHR_materials_sheen.sheenColorFactor[" + std::to_string(c) + "]",
                                         0.0, 1.0);
            }
        }
        m.sheenRoughness = factor(number(*e, sh, "sheenRoughnessFactor", 0.0), who + ": KHR_materials_sheen.sheenRoughnessFactor", 0.0, 1.0);
        if (!isBlack(m.sheenColor)) {
            m.sheenColorTexture = extTexture(*e, sh, "sheenColorTexture", true);
            m.sheenRoughnessTexture = extTexture(*e, sh, "sheenRoughnessTexture", false);
            useFeature("KHR_materials_sheen");
        }
    }
    if (const tinygltf::Value* e = ext("KHR_materials_clearcoat")) {
        // docs/materials.md, "Clearcoat". Textures: R of clearcoatTexture, G of
        // clearcoatRoughnessTexture (linear), and the coat's own normal map.
        const char* cc = "KHR_materials_clearcoat";
        m.clearcoat = factor(number(*e, cc, "clearcoatFactor", 0.0), who + ": KHR_materials_clearcoat.clearcoatFactor", 0.0, 1.0);
        m.clearcoatRoughness = factor(number(*e, cc, "clearcoatRoughnessFactor", 0.0),
                                      who + ": KHR_materials_clearcoat.clearcoatRoughnessFactor", 0.0, 1.0);
        if (m.clearcoat > 0.f) {
            m.clearcoatTexture = extTexture(*e, cc, "clearcoatTexture", false);
            m.clearcoatRoughnessTexture = extTexture(*e, cc, "clearcoatRoughnessTexture", false);
            m.clearcoatNormalTexture = extTexture(*e, cc, "clearcoatNormalTexture", false);
            if (m.clearcoatNormalTexture.valid()) {
                const tinygltf::Value& info = e->Get("clearcoatNormalTexture");
                if (info.Has("scale")) {
                    if (!info.Get("scale").IsNumber()) fail(who + ": KHR_materials_clearcoat.clearcoatNormalTexture.scale is not a number");
                    m.clearcoatNormalScale = factor(info.Get("scale").GetNumberAsDouble(),
                                                    who + ": KHR_materials_clearcoat.clearcoatNormalTexture.scale",
                                                    -std::numeric_limits<double>::max(), std::numeric_limits<double>::max());
                }
                // One tangent frame per vertex: the coat's map must read the TEXCOORD set the
                // tangents are made for (those of normalTexture, when the material has one).
                if (m.normalTexture.valid() && m.normalTexture.texCoord != m.clearcoatNormalTexture.texCoord)
                    fail(who + ": clearcoatNormalTexture reads TEXCOORD_" + std::to_string(m.clearcoatNormalTexture.texCoord) +
                         " but normalTexture reads TEXCOORD_" + std::to_string(m.normalTexture.texCoord) +
                         ": two tangent frames per vertex are not supported; use one TEXCOORD set for both normal maps");
            }
            if (!isBlack(m.emission)) {
                // The extension darkens emission under the coat by (1 - clearcoat F_c(V.n_c)); the
                // area lights here emit the base emission (docs/materials.md, "Clearcoat").
                warn(who, "KHR_materials_clearcoat over emission: the coat's darkening of the emission is not modelled "
                          "(the emitter is rendered without it)");
                scene_.info.ignoredFeatures.push_back(who + ": clearcoat darkening of emission");
            }
            useFeature("KHR_materials_clearcoat");
        }
    }
    // Rough transmission (roughness > 0, factor x metallicRoughnessTexture G) is the GGX microfacet
    // BTDF combined with the base as KHR_materials_transmission specifies (docs/materials.md).
    if (m.transmission > 0.f && m.ior == 0.f) fail(who + ": KHR_materials_ior.ior = 0 cannot be combined with transmission");
    return m;
}

// KHR_materials_volume: the absorption coefficient of the medium inside the material's meshes,
// sigma_a = -ln(attenuationColor) / attenuationDistance (docs/materials.md, "Volume absorption").
// thicknessFactor and thicknessTexture are a rasterizer's estimate of the distance through the
// mesh; the paths here measure the real distance, so they are validated and not used.
void Loader::volume(const std::string& who, const tinygltf::Value& e, bool transmissive, Material* m) {
    const std::string w = who + ": KHR_materials_volume";
    if (!e.IsObject()) fail(w + " must be an object");
    auto number = [&](const char* key, double def) {
        if (!e.Has(key)) return def;
        const tinygltf::Value& v = e.Get(key);
        if (!v.IsNumber()) fail(w + "." + key + " is not a number");
        return v.GetNumberAsDouble();
    };
    const double thickness = number("thicknessFactor", 0.0);
    if (!std::isfinite(thickness) || thickness < 0.0)
        fail(w + ".thicknessFactor = " + fmt(thickness) + " is invalid (must be a finite number >= 0)");
    const bool hasDistance = e.Has("attenuationDistance");
    const double distance = number("attenuationDistance", 0.0);
    if (hasDistance && !(distance > 0.0 && std::isfinite(float(distance)) && float(distance) > 0.f))
        fail(w + ".attenuationDistance = " + fmt(distance) +
             " is invalid (must be a positive world-space distance; leave it out for no absorption)");
    Rgb color(1.f);
    if (e.Has("attenuationColor")) {
        const tinygltf::Value& a = e.Get("attenuationColor");
        if (!a.IsArray() || a.ArrayLen() != 3) fail(w + ".attenuationColor must be an array of 3 numbers");
        for (int c = 0; c < 3; ++c) {
            if (!a.Get(c).IsNumber()) fail(w + ".attenuationColor must be an array of 3 numbers");
            color[c] = factor(a.Get(c).GetNumberAsDouble(), w + ".attenuationColor[" + std::to_string(c) + "]", 0.0, 1.0);
        }
    }
    if (e.Has("thicknessFactor") || e.Has("thicknessTexture"))
        warn(who, "KHR_materials_volume thicknessFactor/thicknessTexture ignored (the distance through the mesh is traced)");
    if (!transmissive) {
        warn(who, "KHR_materials_volume ignored: the material has no KHR_materials_transmission, so no path enters its volume");
        return;
    }
    if (!hasDistance || color == Rgb(1.f)) return;  // attenuationDistance +inf or a white colour: no absorption
    if (thickness == 0.0)
        warn(who, "KHR_materials_volume with thicknessFactor 0 (thin-walled in the glTF specification) absorbs like any "
                  "volume here: transmissive surfaces are always volume boundaries (docs/materials.md)");
    for (int c = 0; c < 3; ++c) {  // attenuationColor 0 (or a sigma beyond float): +inf, nothing gets through
        const double sigma = color[c] > 0.f ? -std::log(double(color[c])) / distance : double(kInfinity);
        m->absorption[c] = sigma < double(std::numeric_limits<float>::max()) ? float(sigma) : kInfinity;
    }
    useFeature("KHR_materials_volume");
}

}  // namespace gltfload
}  // namespace bdptref
