// Texture storage at the source precision, decoding to linear and filtering.
// Conventions: docs/materials.md ("Textures").
//
// Texels stay as the file stores them (an 8-bit RGB 2048^2 image is 12 MiB, not the 64 MiB of
// float RGBA) and are decoded when read. The decoded values are bit-identical to decoding on load
// as this renderer used to: channel = float(double(v) / (2^bits - 1)), then srgbToLinear on that
// float for sRGB colour channels. 8-bit values go through a 256-entry table per colour space and
// 16-bit sRGB through a 65536-entry table built on first use.
#include "bdptref/material.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace bdptref {

namespace {

struct Unorm8Tables {
    float linear[256];
    float srgb[256];
};

const Unorm8Tables& unorm8Tables() {
    static const Unorm8Tables t = [] {
        Unorm8Tables r{};
        for (int v = 0; v < 256; ++v) {
            r.linear[v] = float(double(v) / 255.0);
            r.srgb[v] = srgbToLinear(r.linear[v]);
        }
        return r;
    }();
    return t;
}

const std::vector<float>& unorm16SrgbTable() {
    static const std::vector<float> t = [] {
        std::vector<float> r(65536);
        for (size_t v = 0; v < r.size(); ++v) r[v] = srgbToLinear(float(double(v) / 65535.0));
        return r;
    }();
    return t;
}

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

Texture Texture::fromLinear(int width, int height, const std::vector<Vec4>& rgba) {
    Texture t;
    t.width = width;
    t.height = height;
    t.channels = 4;
    t.format = Format::Float32;
    auto bytes = std::make_shared<std::vector<uint8_t>>(rgba.size() * sizeof(Vec4));
    static_assert(sizeof(Vec4) == 4 * sizeof(float), "Vec4 is four packed floats");
    if (!rgba.empty()) std::memcpy(bytes->data(), rgba.data(), bytes->size());
    t.data = std::move(bytes);
    return t;
}

size_t Texture::bytesPerTexel() const {
    const size_t c = size_t(channels);
    return format == Format::Unorm8 ? c : format == Format::Unorm16 ? 2 * c : 4 * c;
}

bool Texture::valid() const {
    if (width <= 0 || height <= 0 || channels < 1 || channels > 4 || !data) return false;
    return data->size() / bytesPerTexel() / size_t(width) >= size_t(height);
}

Vec4 Texture::texel(int x, int y) const {
    const size_t bpt = bytesPerTexel();
    const uint8_t* p = data->data() + (size_t(y) * size_t(width) + size_t(x)) * bpt;
    // Channel c of the texel, linear; `colour` says whether sRGB decoding applies to it.
    auto channel = [&](int c, bool colour) -> float {
        switch (format) {
            case Format::Unorm8: {
                const Unorm8Tables& t = unorm8Tables();
                return srgb && colour ? t.srgb[p[c]] : t.linear[p[c]];
            }
            case Format::Unorm16: {
                uint16_t v;
                std::memcpy(&v, p + 2 * c, 2);
                return srgb && colour ? unorm16SrgbTable()[v] : float(double(v) / 65535.0);
            }
            case Format::Float32:
            default: {
                float v;
                std::memcpy(&v, p + 4 * c, 4);
                return srgb && colour ? srgbToLinear(v) : v;
            }
        }
    };
    switch (channels) {
        case 1: {
            const float g = channel(0, true);
            return Vec4(g, g, g, 1.f);
        }
        case 2: {
            const float g = channel(0, true);
            return Vec4(g, g, g, channel(1, false));
        }
        case 3: return Vec4(channel(0, true), channel(1, true), channel(2, true), 1.f);
        default: return Vec4(channel(0, true), channel(1, true), channel(2, true), channel(3, false));
    }
}

Vec4 Texture::lookup(Vec2 uv) const {
    if (!valid()) return Vec4(1.f);
    const double u = std::isfinite(uv.x) ? double(uv.x) : 0.0;
    const double v = std::isfinite(uv.y) ? double(uv.y) : 0.0;
    auto at = [&](int x, int y) { return glm::dvec4(texel(x, y)); };
    if (nearest) {
        const double fx = reduceIndex(std::floor(u * width), width, wrapS);
        const double fy = reduceIndex(std::floor(v * height), height, wrapT);
        return Vec4(at(wrapIndex(fx, width, wrapS), wrapIndex(fy, height, wrapT)));
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
    const glm::dvec4 top = at(i0, j0) * (1.0 - tx) + at(i1, j0) * tx;
    const glm::dvec4 bottom = at(i0, j1) * (1.0 - tx) + at(i1, j1) * tx;
    return Vec4(top * (1.0 - ty) + bottom * ty);
}

}  // namespace bdptref
