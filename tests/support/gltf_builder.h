// Builds small glTF documents in tests (JSON + base64 data-URI buffer, PNG images) and writes them
// to a per-process temporary folder. Shared by the loader tests and the render tests.
#pragma once

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <unistd.h>

namespace bdptref::test {

using json = nlohmann::json;
namespace fs = std::filesystem;

// NOLINTBEGIN: small inline helpers, header-only on purpose (tests only).
// ----- files

// One private directory per test process (CTest runs test cases as separate processes).
struct TempDir {
    fs::path path;
    TempDir() {
        path = fs::temp_directory_path() /
               ("bdptref-gltf-test-" + std::to_string(::getpid()) + "-" +
                std::to_string(std::chrono::steady_clock::now().time_since_epoch().count()));
        fs::create_directories(path);
    }
    ~TempDir() {
        std::error_code ec;
        fs::remove_all(path, ec);
    }
};

inline const fs::path& tempDir() {
    static const TempDir dir;
    return dir.path;
}

inline std::string writeFile(const std::string& name, const std::vector<unsigned char>& bytes) {
    const fs::path p = tempDir() / name;
    std::ofstream out(p, std::ios::binary);
    out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    return p.string();
}

inline std::string writeFile(const std::string& name, const std::string& text) {
    return writeFile(name, std::vector<unsigned char>(text.begin(), text.end()));
}

inline std::vector<unsigned char> readFile(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::vector<unsigned char>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

inline std::string base64(const std::vector<unsigned char>& d) {
    static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string s;
    size_t i = 0;
    for (; i + 2 < d.size(); i += 3) {
        const uint32_t v = (uint32_t(d[i]) << 16) | (uint32_t(d[i + 1]) << 8) | d[i + 2];
        s += t[(v >> 18) & 63];
        s += t[(v >> 12) & 63];
        s += t[(v >> 6) & 63];
        s += t[v & 63];
    }
    if (i + 1 == d.size()) {
        const uint32_t v = uint32_t(d[i]) << 16;
        s += t[(v >> 18) & 63];
        s += t[(v >> 12) & 63];
        s += "==";
    } else if (i + 2 == d.size()) {
        const uint32_t v = (uint32_t(d[i]) << 16) | (uint32_t(d[i + 1]) << 8);
        s += t[(v >> 18) & 63];
        s += t[(v >> 12) & 63];
        s += t[(v >> 6) & 63];
        s += '=';
    }
    return s;
}

// ----- a minimal PNG writer (stored deflate blocks), so texture tests need no image library

inline uint32_t crc32(const unsigned char* p, size_t n, uint32_t crc = 0) {
    crc = ~crc;
    for (size_t i = 0; i < n; ++i) {
        crc ^= p[i];
        for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
    }
    return ~crc;
}

inline void put32be(std::vector<unsigned char>& v, uint32_t x) {
    for (int s = 24; s >= 0; s -= 8) v.push_back((unsigned char)(x >> s));
}

inline void pngChunk(std::vector<unsigned char>& png, const char* type, const std::vector<unsigned char>& data) {
    put32be(png, uint32_t(data.size()));
    std::vector<unsigned char> td(type, type + 4);
    td.insert(td.end(), data.begin(), data.end());
    png.insert(png.end(), td.begin(), td.end());
    put32be(png, crc32(td.data(), td.size()));
}

// samples: row-major, `channels` per pixel, each 8 or 16 bit (values given as integers).
inline std::vector<unsigned char> makePng(int w, int h, int channels, int bits, const std::vector<uint16_t>& samples) {
    const int colorType = channels == 1 ? 0 : channels == 2 ? 4 : channels == 3 ? 2 : 6;
    std::vector<unsigned char> raw;
    size_t k = 0;
    for (int y = 0; y < h; ++y) {
        raw.push_back(0);  // filter: none
        for (int x = 0; x < w * channels; ++x, ++k) {
            if (bits == 16) raw.push_back((unsigned char)(samples[k] >> 8));
            raw.push_back((unsigned char)(samples[k] & 0xFF));
        }
    }
    std::vector<unsigned char> z = {0x78, 0x01, 0x01};
    const uint16_t len = uint16_t(raw.size()), nlen = uint16_t(~len);
    z.push_back((unsigned char)(len & 0xFF));
    z.push_back((unsigned char)(len >> 8));
    z.push_back((unsigned char)(nlen & 0xFF));
    z.push_back((unsigned char)(nlen >> 8));
    z.insert(z.end(), raw.begin(), raw.end());
    uint32_t a = 1, b = 0;
    for (unsigned char c : raw) {
        a = (a + c) % 65521;
        b = (b + a) % 65521;
    }
    put32be(z, (b << 16) | a);
    std::vector<unsigned char> png = {0x89, 'P', 'N', 'G', 0x0D, 0x0A, 0x1A, 0x0A};
    std::vector<unsigned char> ihdr;
    put32be(ihdr, uint32_t(w));
    put32be(ihdr, uint32_t(h));
    ihdr.push_back((unsigned char)bits);
    ihdr.push_back((unsigned char)colorType);
    ihdr.push_back(0);
    ihdr.push_back(0);
    ihdr.push_back(0);
    pngChunk(png, "IHDR", ihdr);
    pngChunk(png, "IDAT", z);
    pngChunk(png, "IEND", {});
    return png;
}

// ----- a small glTF document builder

constexpr int kU8 = 5121, kU16 = 5123, kU32 = 5125, kF32 = 5126;

struct Doc {
    json j;
    std::vector<unsigned char> bin;

    Doc() {
        j["asset"] = {{"version", "2.0"}};
        j["scene"] = 0;
        j["scenes"] = json::array({json{{"nodes", json::array()}}});
        j["nodes"] = json::array();
        j["meshes"] = json::array();
        j["accessors"] = json::array();
        j["bufferViews"] = json::array();
    }

    int view(const void* data, size_t n, int stride = 0) {
        while (bin.size() % 4) bin.push_back(0);
        const size_t off = bin.size();
        const auto* p = static_cast<const unsigned char*>(data);
        bin.insert(bin.end(), p, p + n);
        json v = {{"buffer", 0}, {"byteOffset", off}, {"byteLength", n}};
        if (stride) v["byteStride"] = stride;
        j["bufferViews"].push_back(v);
        return int(j["bufferViews"].size()) - 1;
    }
    int accessor(int view, int componentType, size_t count, const char* type, size_t byteOffset = 0, bool normalized = false) {
        json a = {{"bufferView", view}, {"componentType", componentType}, {"count", count}, {"type", type}};
        if (byteOffset) a["byteOffset"] = byteOffset;
        if (normalized) a["normalized"] = true;
        j["accessors"].push_back(a);
        return int(j["accessors"].size()) - 1;
    }
    int floats(const std::vector<float>& v, const char* type) {
        const size_t nc = std::string(type) == "VEC3" ? 3 : std::string(type) == "VEC2" ? 2 : std::string(type) == "VEC4" ? 4 : 1;
        return accessor(view(v.data(), v.size() * 4), kF32, v.size() / nc, type);
    }
    template <typename T>
    int indices(const std::vector<T>& v) {
        const int ct = sizeof(T) == 1 ? kU8 : sizeof(T) == 2 ? kU16 : kU32;
        return accessor(view(v.data(), v.size() * sizeof(T)), ct, v.size(), "SCALAR");
    }
    static json prim(int pos, int idx = -1, int nrm = -1, int uv = -1, int mode = 4, int material = -1) {
        json p = {{"attributes", {{"POSITION", pos}}}};
        if (nrm >= 0) p["attributes"]["NORMAL"] = nrm;
        if (uv >= 0) p["attributes"]["TEXCOORD_0"] = uv;
        if (idx >= 0) p["indices"] = idx;
        if (mode != 4) p["mode"] = mode;
        if (material >= 0) p["material"] = material;
        return p;
    }
    int mesh(const json& primitive) {
        j["meshes"].push_back({{"primitives", json::array({primitive})}});
        return int(j["meshes"].size()) - 1;
    }
    int node(const json& n, bool root = true) {
        j["nodes"].push_back(n);
        const int i = int(j["nodes"].size()) - 1;
        if (root) j["scenes"][0]["nodes"].push_back(i);
        return i;
    }
    int material(const json& m) {
        j["materials"].push_back(m);
        return int(j["materials"].size()) - 1;
    }
    void use(const char* ext, bool required = false) {
        const json& used = j["extensionsUsed"];
        if (!used.is_array() || std::find(used.begin(), used.end(), ext) == used.end()) j["extensionsUsed"].push_back(ext);
        if (required) j["extensionsRequired"].push_back(ext);
    }
    // A triangle (0,0,0) (1,0,0) (0,1,0) facing +z on a root node; returns the node index.
    int triangleNode(json node = json::object(), bool withNormals = true) {
        const int pos = floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3");
        const int nrm = withNormals ? floats({0, 0, 1, 0, 0, 1, 0, 0, 1}, "VEC3") : -1;
        node["mesh"] = mesh(prim(pos, -1, nrm));
        return this->node(node);
    }
    json finished() const {
        json out = j;
        if (!bin.empty())
            out["buffers"] = json::array({json{{"byteLength", bin.size()}, {"uri", "data:application/octet-stream;base64," + base64(bin)}}});
        return out;
    }
    std::string write(const std::string& name) const { return writeFile(name, finished().dump()); }

    // ----- whole objects for scene-level tests (tests/stability)

    // A pure Lambert material (KHR_materials_specular 0: no specular lobe) with an optional
    // emission (radiance = emissive * strength, via KHR_materials_emissive_strength).
    int lambert(const std::array<double, 3>& albedo, const std::array<double, 3>& emissive = {0, 0, 0},
                double strength = 1.0, bool doubleSided = false) {
        use("KHR_materials_specular");
        json m = {{"pbrMetallicRoughness", {{"baseColorFactor", {albedo[0], albedo[1], albedo[2], 1}}, {"metallicFactor", 0}, {"roughnessFactor", 1}}},
                  {"extensions", {{"KHR_materials_specular", {{"specularFactor", 0}}}}}};
        if (emissive != std::array<double, 3>{0, 0, 0}) {
            m["emissiveFactor"] = {emissive[0], emissive[1], emissive[2]};
            if (strength != 1.0) {
                use("KHR_materials_emissive_strength");
                m["extensions"]["KHR_materials_emissive_strength"] = {{"emissiveStrength", strength}};
            }
        }
        if (doubleSided) m["doubleSided"] = true;
        return material(m);
    }
    // A metal (GGX, or an exact mirror at roughness 0) and a smooth glass (KHR_materials_transmission).
    int metal(const std::array<double, 3>& color, double roughness) {
        return material({{"pbrMetallicRoughness", {{"baseColorFactor", {color[0], color[1], color[2], 1}}, {"metallicFactor", 1}, {"roughnessFactor", roughness}}}});
    }
    int glass(double ior = 1.5) {
        use("KHR_materials_transmission");
        use("KHR_materials_ior");
        return material({{"pbrMetallicRoughness", {{"baseColorFactor", {1, 1, 1, 1}}, {"metallicFactor", 0}, {"roughnessFactor", 0}}},
                         {"extensions", {{"KHR_materials_transmission", {{"transmissionFactor", 1}}}, {"KHR_materials_ior", {{"ior", ior}}}}}});
    }
    // Triangles (3 positions each, world space, counter-clockwise = front) as one mesh on a root
    // node, flat normals from the winding. Returns the node index.
    int triangles(const std::vector<std::array<double, 3>>& p, int mat) {
        std::vector<float> pos;
        for (const auto& v : p)
            for (double c : v) pos.push_back(float(c));
        return node({{"mesh", mesh(prim(floats(pos, "VEC3"), -1, -1, -1, 4, mat))}});
    }
    // Quad p0 p1 p2 p3 (counter-clockwise seen from its front) as two triangles.
    int quad(const std::array<double, 3>& p0, const std::array<double, 3>& p1, const std::array<double, 3>& p2,
             const std::array<double, 3>& p3, int mat) {
        return triangles({p0, p1, p2, p0, p2, p3}, mat);
    }
    // Axis-aligned box [lo, hi] with outward-facing sides (open sides can be left out by index:
    // 0 -x, 1 +x, 2 -y, 3 +y, 4 -z, 5 +z); `inward` faces the sides to the inside instead.
    void box(const std::array<double, 3>& lo, const std::array<double, 3>& hi, int mat, bool inward = false,
             const std::vector<int>& omit = {}) {
        const double x0 = lo[0], y0 = lo[1], z0 = lo[2], x1 = hi[0], y1 = hi[1], z1 = hi[2];
        using P = std::array<double, 3>;
        const std::array<std::array<P, 4>, 6> sides = {{
            {{{x0, y0, z0}, {x0, y0, z1}, {x0, y1, z1}, {x0, y1, z0}}},  // -x, outward
            {{{x1, y0, z0}, {x1, y1, z0}, {x1, y1, z1}, {x1, y0, z1}}},  // +x
            {{{x0, y0, z0}, {x1, y0, z0}, {x1, y0, z1}, {x0, y0, z1}}},  // -y
            {{{x0, y1, z0}, {x0, y1, z1}, {x1, y1, z1}, {x1, y1, z0}}},  // +y
            {{{x0, y0, z0}, {x0, y1, z0}, {x1, y1, z0}, {x1, y0, z0}}},  // -z
            {{{x0, y0, z1}, {x1, y0, z1}, {x1, y1, z1}, {x0, y1, z1}}},  // +z
        }};
        for (int i = 0; i < 6; ++i) {
            if (std::find(omit.begin(), omit.end(), i) != omit.end()) continue;
            const auto& q = sides[size_t(i)];
            if (inward) quad(q[0], q[3], q[2], q[1], mat);
            else quad(q[0], q[1], q[2], q[3], mat);
        }
    }
    // UV sphere (outward facing, smooth normals) of `rings` x `segments` quads.
    int sphere(const std::array<double, 3>& c, double r, int mat, int rings = 24, int segments = 48) {
        std::vector<float> pos, nrm;
        std::vector<uint32_t> idx;
        const double pi = 3.14159265358979323846;
        for (int i = 0; i <= rings; ++i)
            for (int k2 = 0; k2 <= segments; ++k2) {
                const double th = pi * i / rings, ph = 2 * pi * k2 / segments;
                const double n[3] = {std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph)};
                for (int k = 0; k < 3; ++k) {
                    pos.push_back(float(c[size_t(k)] + r * n[k]));
                    nrm.push_back(float(n[k]));
                }
            }
        const auto at = [&](int i, int k2) { return uint32_t(i * (segments + 1) + k2); };
        for (int i = 0; i < rings; ++i)
            for (int k2 = 0; k2 < segments; ++k2) {
                // Counter-clockwise seen from outside (theta down from +y, phi towards +z).
                idx.insert(idx.end(), {at(i, k2), at(i, k2 + 1), at(i + 1, k2)});
                idx.insert(idx.end(), {at(i, k2 + 1), at(i + 1, k2 + 1), at(i + 1, k2)});
            }
        return node({{"mesh", mesh(prim(floats(pos, "VEC3"), indices(idx), floats(nrm, "VEC3"), -1, 4, mat))}});
    }
    // A KHR_lights_punctual light on a root node (`lightNode` holds translation / rotation).
    int punctual(const json& light, json lightNode) {
        use("KHR_lights_punctual");
        j["extensions"]["KHR_lights_punctual"]["lights"].push_back(light);
        lightNode["extensions"]["KHR_lights_punctual"]["light"] = int(j["extensions"]["KHR_lights_punctual"]["lights"].size()) - 1;
        return node(lightNode);
    }
};

// ----- textured quads (alpha tests: tests/scenes/test_alpha*.cpp)

// An embedded RGBA8 PNG texture (row-major, 4 values per texel) with a NEAREST / REPEAT sampler,
// so a texel's value holds exactly over its whole square. Returns the texture index.
inline int nearestTexture(Doc& d, int w, int h, const std::vector<uint16_t>& rgba) {
    d.j["images"].push_back({{"uri", "data:image/png;base64," + base64(makePng(w, h, 4, 8, rgba))}});
    d.j["samplers"].push_back({{"magFilter", 9728}, {"minFilter", 9728}, {"wrapS", 10497}, {"wrapT", 10497}});
    d.j["textures"].push_back({{"source", int(d.j["images"].size()) - 1}, {"sampler", int(d.j["samplers"].size()) - 1}});
    return int(d.j["textures"].size()) - 1;
}

// Quad p[0..3] (counter-clockwise seen from its front) with texture coordinates uv[k] at p[k], as
// two triangles with flat normals from the winding. Returns the node index.
inline int uvQuad(Doc& d, const std::array<std::array<double, 3>, 4>& p, const std::array<std::array<double, 2>, 4>& uv, int mat) {
    std::vector<float> pos, tex;
    for (int k : {0, 1, 2, 0, 2, 3}) {
        for (double c : p[size_t(k)]) pos.push_back(float(c));
        for (double c : uv[size_t(k)]) tex.push_back(float(c));
    }
    return d.node({{"mesh", d.mesh(Doc::prim(d.floats(pos, "VEC3"), -1, -1, d.floats(tex, "VEC2"), 4, mat))}});
}

// A quad p0..p3 (counter-clockwise seen from its front) as two triangles with TEXCOORD_0 uv0..uv3
// on a root node; returns the node index.
inline int texturedQuad(Doc& d, const std::array<std::array<double, 3>, 4>& p, const std::array<std::array<double, 2>, 4>& uv,
                        int mat) {
    std::vector<float> pos, tc;
    for (const auto& v : p)
        for (double c : v) pos.push_back(float(c));
    for (const auto& v : uv)
        for (double c : v) tc.push_back(float(c));
    const std::vector<uint16_t> idx = {0, 1, 2, 0, 2, 3};
    return d.node({{"mesh", d.mesh(Doc::prim(d.floats(pos, "VEC3"), d.indices(idx), -1, d.floats(tc, "VEC2"), 4, mat))}});
}

// An 8-bit PNG embedded as a data URI, as a texture (nearest or the default bilinear filter);
// returns the texture index.
inline int pngTexture(Doc& d, int w, int h, int channels, const std::vector<uint16_t>& samples, bool nearest) {
    d.j["images"].push_back({{"uri", "data:image/png;base64," + base64(makePng(w, h, channels, 8, samples))}});
    json t = {{"source", int(d.j["images"].size()) - 1}};
    if (nearest) {
        d.j["samplers"].push_back({{"magFilter", 9728}, {"minFilter", 9728}});  // NEAREST
        t["sampler"] = int(d.j["samplers"].size()) - 1;
    }
    d.j["textures"].push_back(t);
    return int(d.j["textures"].size()) - 1;
}

// NOLINTEND

}  // namespace bdptref::test
