// Texture::lookup (wrap modes, bilinear and nearest filtering, orientation), resolveMaterial and
// srgbToLinear (src/scene/material.cpp; conventions in docs/materials.md "Textures").
#include "bdptref/material.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <memory>
#include <limits>

using namespace bdptref;

namespace {

// A width x height texture whose texel (i, j) holds (i, j, 10 i + j, 1): values identify texels.
Texture indexTexture(int width, int height, Texture::Wrap wrap, bool nearest) {
    std::vector<Vec4> texels;
    for (int j = 0; j < height; ++j) {
        for (int i = 0; i < width; ++i) texels.push_back(Vec4(float(i), float(j), float(10 * i + j), 1.f));
    }
    Texture t = Texture::fromLinear(width, height, texels);
    t.wrapS = t.wrapT = wrap;
    t.nearest = nearest;
    return t;
}

Vec4 texel(int i, int j) { return Vec4(float(i), float(j), float(10 * i + j), 1.f); }

bool near(const Vec4& a, const Vec4& b, float tol = 1e-5f) {
    return std::abs(a.x - b.x) <= tol && std::abs(a.y - b.y) <= tol && std::abs(a.z - b.z) <= tol &&
           std::abs(a.w - b.w) <= tol;
}

}  // namespace

TEST_CASE("Texture: uv (0,0) is the top-left corner, texel centres return texels exactly", "[texture]") {
    for (Texture::Wrap wrap : {Texture::Wrap::Repeat, Texture::Wrap::ClampToEdge, Texture::Wrap::MirroredRepeat}) {
        for (bool nearest : {false, true}) {
            const Texture t = indexTexture(4, 3, wrap, nearest);
            for (int j = 0; j < 3; ++j) {
                for (int i = 0; i < 4; ++i) {
                    const Vec2 centre((i + 0.5f) / 4.f, (j + 0.5f) / 3.f);
                    INFO("wrap " << int(wrap) << " nearest " << nearest << " texel " << i << "," << j);
                    // (j + 0.5) / 3 is not a float: the bilinear weights are exact to ~1e-7 only.
                    CHECK(near(t.lookup(centre), texel(i, j)));
                }
            }
            if (nearest) {  // row 0 is the top of the image: v just below 1/3 is still row 0
                CHECK(t.lookup(Vec2(0.125f, 0.33f)) == texel(0, 0));
                CHECK(t.lookup(Vec2(0.125f, 0.34f)) == texel(0, 1));
            }
        }
    }
}

TEST_CASE("Texture: bilinear weights between texel centres", "[texture]") {
    const Texture t = indexTexture(4, 3, Texture::Wrap::ClampToEdge, false);
    // Between the outermost texel centres, bilinear filtering of the index channels is linear:
    // channel x = u * width - 0.5 and channel y = v * height - 0.5 (v grows downwards).
    for (float u = 0.125f; u <= 0.875f; u += 0.0625f) {
        for (float v = 0.5f / 3.f; v <= 2.5f / 3.f; v += 0.05f) {
            const Vec4 l = t.lookup(Vec2(u, v));
            INFO("uv " << u << "," << v);
            CHECK(l.x == Approx(u * 4.f - 0.5f).margin(1e-5));
            CHECK(l.y == Approx(v * 3.f - 0.5f).margin(1e-5));
        }
    }
    // A quarter of the way from centre (1,1) towards centre (2,1) and half way towards (1,2).
    const Vec2 uv((1.5f + 0.25f) / 4.f, (1.5f + 0.5f) / 3.f);
    const Vec4 expected = 0.75f * 0.5f * texel(1, 1) + 0.25f * 0.5f * texel(2, 1) + 0.75f * 0.5f * texel(1, 2) +
                          0.25f * 0.5f * texel(2, 2);
    CHECK(near(t.lookup(uv), expected));
}

TEST_CASE("Texture: REPEAT wraps texel indices modulo the size (both ways)", "[texture]") {
    const Texture bl = indexTexture(4, 3, Texture::Wrap::Repeat, false);
    const Texture nn = indexTexture(4, 3, Texture::Wrap::Repeat, true);
    for (const Vec2 uv : {Vec2(0.3f, 0.4f), Vec2(0.9f, 0.1f), Vec2(0.05f, 0.95f)}) {
        for (const Vec2 shift : {Vec2(1.f, 0.f), Vec2(-1.f, 2.f), Vec2(-3.f, -5.f), Vec2(7.f, 1.f)}) {
            INFO("uv " << uv.x << "," << uv.y << " shift " << shift.x << "," << shift.y);
            CHECK(near(bl.lookup(uv + shift), bl.lookup(uv), 1e-4f));
            CHECK(nn.lookup(uv + shift) == nn.lookup(uv));
        }
    }
    // On the left edge the bilinear filter blends the first and the last column equally.
    CHECK(near(bl.lookup(Vec2(0.f, 0.5f / 3.f)), 0.5f * (texel(0, 0) + texel(3, 0))));
    // On the top edge: the first and the last row.
    CHECK(near(bl.lookup(Vec2(0.5f / 4.f, 0.f)), 0.5f * (texel(0, 0) + texel(0, 2))));
}

TEST_CASE("Texture: CLAMP_TO_EDGE clamps texel indices", "[texture]") {
    const Texture bl = indexTexture(4, 3, Texture::Wrap::ClampToEdge, false);
    const Texture nn = indexTexture(4, 3, Texture::Wrap::ClampToEdge, true);
    CHECK(near(bl.lookup(Vec2(0.f, 0.5f / 3.f)), texel(0, 0)));
    CHECK(bl.lookup(Vec2(-5.f, -5.f)) == texel(0, 0));
    CHECK(near(bl.lookup(Vec2(5.f, 0.5f / 3.f)), texel(3, 0)));
    CHECK(bl.lookup(Vec2(1.f, 1.f)) == texel(3, 2));
    CHECK(nn.lookup(Vec2(-0.01f, 2.f)) == texel(0, 2));
    CHECK(nn.lookup(Vec2(1e9f, -1e9f)) == texel(3, 0));
}

TEST_CASE("Texture: MIRRORED_REPEAT mirrors every other period", "[texture]") {
    const Texture nn = indexTexture(4, 1, Texture::Wrap::MirroredRepeat, true);
    const Texture bl = indexTexture(4, 1, Texture::Wrap::MirroredRepeat, false);
    // Period [1, 2) runs backwards, [2, 3) forwards again, [-1, 0) backwards.
    CHECK(nn.lookup(Vec2(1.1f, 0.5f)) == texel(3, 0));
    CHECK(nn.lookup(Vec2(1.9f, 0.5f)) == texel(0, 0));
    CHECK(nn.lookup(Vec2(2.1f, 0.5f)) == texel(0, 0));
    CHECK(nn.lookup(Vec2(-0.1f, 0.5f)) == texel(0, 0));
    CHECK(nn.lookup(Vec2(-0.9f, 0.5f)) == texel(3, 0));
    // Mirror symmetry about u = 1 and u = 0, and continuity (no blend with the far edge) at u = 1.
    for (float u : {0.03f, 0.2f, 0.41f, 0.77f, 0.95f}) {
        INFO("u " << u);
        CHECK(near(bl.lookup(Vec2(1.f + u, 0.5f)), bl.lookup(Vec2(1.f - u, 0.5f)), 1e-4f));
        CHECK(near(bl.lookup(Vec2(-u, 0.5f)), bl.lookup(Vec2(u, 0.5f)), 1e-4f));
    }
    CHECK(bl.lookup(Vec2(1.f, 0.5f)) == texel(3, 0));
    CHECK(bl.lookup(Vec2(0.f, 0.5f)) == texel(0, 0));
}

TEST_CASE("Texture: nearest picks the texel containing uv", "[texture]") {
    const Texture nn = indexTexture(4, 3, Texture::Wrap::Repeat, true);
    CHECK(nn.lookup(Vec2(0.2499f, 0.f)) == texel(0, 0));
    CHECK(nn.lookup(Vec2(0.25f, 0.f)) == texel(1, 0));
    CHECK(nn.lookup(Vec2(0.99f, 0.999f)) == texel(3, 2));
    CHECK(nn.lookup(Vec2(0.5f, 0.34f)) == texel(2, 1));
}

TEST_CASE("Texture: degenerate inputs stay finite", "[texture]") {
    const Texture bl = indexTexture(4, 3, Texture::Wrap::Repeat, false);
    const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
    for (const Vec2 uv : {Vec2(nan, 0.5f), Vec2(inf, -inf), Vec2(1e30f, -1e30f), Vec2(-1e-30f, 1e-30f)}) {
        const Vec4 v = bl.lookup(uv);
        CHECK((std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z) && std::isfinite(v.w)));
        CHECK((v.x >= 0.f && v.x <= 3.f && v.y >= 0.f && v.y <= 2.f));
    }
    CHECK(Texture().lookup(Vec2(0.5f)) == Vec4(1.f));  // no image: the identity for multiplication
}

TEST_CASE("resolveMaterial: textures multiply the factors (B = metallic, G = roughness)", "[texture][material]") {
    const Texture base = Texture::fromLinear(1, 1, {Vec4(0.5f, 0.25f, 2.f, 1.f)});
    const Texture mr = Texture::fromLinear(1, 1, {Vec4(0.3f, 0.6f, 0.8f, 1.f)});  // R (occlusion in glTF) must be ignored
    Material m;
    m.baseColor = Rgb(0.8f, 0.4f, 0.2f);
    m.metallic = 0.5f;
    m.roughness = 0.9f;
    m.ior = 1.4f;
    m.transmission = 0.25f;
    m.specular = 0.7f;
    m.specularColor = Rgb(1.f, 0.5f, 0.25f);
    const std::vector<Texture> textures = {base, mr};

    SurfaceAttributes at;
    at.uv[0] = Vec2(0.3f, 0.7f);
    MaterialParams p = resolveMaterial(m, textures, at);
    CHECK(p.baseColor == Rgb(0.8f, 0.4f, 0.2f));  // no textures referenced yet
    CHECK(p.metallic == 0.5f);
    CHECK(p.roughness == 0.9f);
    CHECK(p.ior == 1.4f);
    CHECK(p.transmission == 0.25f);
    CHECK(p.specular == 0.7f);
    CHECK(p.specularColor == Rgb(1.f, 0.5f, 0.25f));

    m.baseColorTexture.texture = 0;
    m.metallicRoughnessTexture.texture = 1;
    p = resolveMaterial(m, textures, at);
    CHECK(p.baseColor.r == Approx(0.4f));
    CHECK(p.baseColor.g == Approx(0.1f));
    CHECK(p.baseColor.b == Approx(0.4f));
    CHECK(p.metallic == Approx(0.5f * 0.8f));
    CHECK(p.roughness == Approx(0.9f * 0.6f));
}

TEST_CASE("srgbToLinear: the exact sRGB EOTF", "[texture]") {
    CHECK(srgbToLinear(0.f) == 0.f);
    CHECK(srgbToLinear(1.f) == 1.f);
    CHECK(srgbToLinear(0.5f) == Approx(0.21404114048223255).epsilon(1e-6));
    CHECK(srgbToLinear(0.2f) == Approx(0.033104766570885055).epsilon(1e-6));
    CHECK(srgbToLinear(128.f / 255.f) == Approx(0.21586050011389926).epsilon(1e-6));
    CHECK(srgbToLinear(0.04045f) == Approx(0.0031308049535603713).epsilon(1e-6));  // linear segment
    CHECK(srgbToLinear(0.02f) == Approx(0.02 / 12.92).epsilon(1e-6));
    // Continuous at the breakpoint and strictly increasing over the 8-bit codes.
    CHECK(srgbToLinear(std::nextafter(0.04045f, 1.f)) == Approx(srgbToLinear(0.04045f)).epsilon(1e-5));
    for (int i = 1; i < 256; ++i) CHECK(srgbToLinear(i / 255.f) > srgbToLinear((i - 1) / 255.f));
}

namespace {

// A 1 x n texture of the given format from raw channel values.
template <typename T>
Texture rawTexture(int n, int channels, Texture::Format format, bool srgb, const std::vector<T>& values) {
    Texture t;
    t.width = n;
    t.height = 1;
    t.channels = channels;
    t.format = format;
    t.srgb = srgb;
    auto bytes = std::make_shared<std::vector<uint8_t>>(values.size() * sizeof(T));
    std::memcpy(bytes->data(), values.data(), bytes->size());
    t.data = std::move(bytes);
    return t;
}

}  // namespace

TEST_CASE("Texture storage: 8-bit texels decode bit-identically to the former decode-on-load", "[texture]") {
    // The former loader stored float(double(v) / 255) and, for sRGB colour, srgbToLinear of that
    // float; the tables must reproduce those floats exactly (so renders do not change).
    std::vector<uint8_t> rgba;
    for (int v = 0; v < 256; ++v) rgba.insert(rgba.end(), {uint8_t(v), uint8_t(255 - v), uint8_t(v), uint8_t(v)});
    const Texture srgb = rawTexture(256, 4, Texture::Format::Unorm8, true, rgba);
    Texture lin = srgb;
    lin.srgb = false;
    CHECK(lin.data == srgb.data);  // a copy shares the bytes
    for (int v = 0; v < 256; ++v) {
        const float l = float(double(v) / 255.0), l2 = float(double(255 - v) / 255.0);
        INFO("code " << v);
        const Vec4 s = srgb.texel(v, 0), t = lin.texel(v, 0);
        CHECK(s.r == srgbToLinear(l));
        CHECK(s.g == srgbToLinear(l2));
        CHECK(s.a == l);  // alpha is never sRGB
        CHECK(t.r == l);
        CHECK(t.g == l2);
        CHECK(t.a == l);
    }
}

TEST_CASE("Texture storage: 16-bit and float texels, and channel counts", "[texture]") {
    const std::vector<uint16_t> codes = {0, 1, 100, 2650, 32768, 50000, 65534, 65535};
    const Texture s16 = rawTexture(int(codes.size()), 1, Texture::Format::Unorm16, true, codes);
    for (size_t i = 0; i < codes.size(); ++i) {
        const float l = float(double(codes[i]) / 65535.0);
        const Vec4 v = s16.texel(int(i), 0);
        INFO("code " << codes[i]);
        CHECK(v.r == srgbToLinear(l));  // grey -> RGB, bit-identical to srgbToLinear of the float
        CHECK(v.g == v.r);
        CHECK(v.b == v.r);
        CHECK(v.a == 1.f);
    }
    // Grey + alpha (8 bit, sRGB): the second channel is alpha and stays linear.
    const Texture ga = rawTexture(1, 2, Texture::Format::Unorm8, true, std::vector<uint8_t>{128, 128});
    CHECK(ga.texel(0, 0).b == srgbToLinear(float(128.0 / 255.0)));
    CHECK(ga.texel(0, 0).a == float(128.0 / 255.0));
    // RGB: alpha 1.
    const Texture rgb = rawTexture(1, 3, Texture::Format::Unorm16, false, std::vector<uint16_t>{65535, 0, 32768});
    CHECK(rgb.texel(0, 0) == Vec4(1.f, 0.f, float(32768.0 / 65535.0), 1.f));
    // Float: values as stored (linear), also above 1.
    const Texture f = Texture::fromLinear(1, 1, {Vec4(2.5f, -0.f, 0.125f, 0.5f)});
    CHECK(f.texel(0, 0) == Vec4(2.5f, 0.f, 0.125f, 0.5f));
    CHECK(f.bytesPerTexel() == 16);
    // Too little data for the claimed size: not valid, lookups return the multiplicative identity.
    Texture shortData = rgb;
    shortData.width = 2;
    CHECK_FALSE(shortData.valid());
    CHECK(shortData.lookup(Vec2(0.5f)) == Vec4(1.f));
}
