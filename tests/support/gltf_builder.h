// Builds small glTF documents in tests (JSON + base64 data-URI buffer, PNG images) and writes them
// to a per-process temporary folder. Shared by the loader tests and the render tests.
#pragma once

#include <nlohmann/json.hpp>

#include <chrono>
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
        j["extensionsUsed"].push_back(ext);
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
};

// NOLINTEND

}  // namespace bdptref::test
