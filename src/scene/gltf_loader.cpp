// glTF 2.0 -> Scene. The contract (docs/scenes.md): everything in the file that would change the
// picture is either implemented exactly or rejected with an InputError that names the file, the
// glTF object and the problem. Things that cannot change the picture become info.warnings.
//
// tinygltf parses the JSON and loads buffers and images; it validates very little of what it
// reads, so every index, size and range is checked here before it is used.

#include "bdptref/gltf_loader.h"

#include "bdptref/errors.h"
#include "scene/gltf_input_checks.h"

#include <nlohmann/json.hpp>
#include <tiny_gltf.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace bdptref {
namespace {

using glm::dmat3;
using glm::dmat4;
using glm::dvec3;
using glm::dvec4;

const char* const kSupportedExtensions[] = {
    "KHR_lights_punctual",        "KHR_materials_emissive_strength", "KHR_materials_ior",
    "KHR_materials_transmission", "KHR_materials_specular",
};

bool isSupportedExtension(const std::string& name) {
    for (const char* s : kSupportedExtensions)
        if (name == s) return true;
    return false;
}

// ---------------------------------------------------------------------------------------------
// Small helpers

std::string fmt(double v) {
    std::ostringstream os;
    os.precision(9);
    os << v;
    return os.str();
}

std::string lower(std::string s) {
    for (char& ch : s) ch = char(std::tolower(static_cast<unsigned char>(ch)));
    return s;
}

bool endsWith(const std::string& s, const std::string& suffix) {
    return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// FNV-1a, 64 bit.
struct Fnv1a64 {
    uint64_t h = 14695981039346656037ull;
    void add(const unsigned char* p, size_t n) {
        for (size_t i = 0; i < n; ++i) {
            h ^= uint64_t(p[i]);
            h *= 1099511628211ull;
        }
    }
    std::string hex() const {
        char buf[17];
        std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
        return std::string(buf);
    }
};

bool mulOverflows(size_t a, size_t b, size_t* out) {
    if (a != 0 && b > std::numeric_limits<size_t>::max() / a) return true;
    *out = a * b;
    return false;
}
bool addOverflows(size_t a, size_t b, size_t* out) {
    if (b > std::numeric_limits<size_t>::max() - a) return true;
    *out = a + b;
    return false;
}

size_t componentSize(int ct) {
    switch (ct) {
        case TINYGLTF_COMPONENT_TYPE_BYTE:
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
        case TINYGLTF_COMPONENT_TYPE_SHORT:
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
        case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
        default: return 0;  // INT and DOUBLE are not valid glTF 2.0 accessor component types
    }
}

const char* componentTypeName(int ct) {
    switch (ct) {
        case TINYGLTF_COMPONENT_TYPE_BYTE: return "BYTE";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return "UNSIGNED_BYTE";
        case TINYGLTF_COMPONENT_TYPE_SHORT: return "SHORT";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return "UNSIGNED_SHORT";
        case TINYGLTF_COMPONENT_TYPE_INT: return "INT";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return "UNSIGNED_INT";
        case TINYGLTF_COMPONENT_TYPE_FLOAT: return "FLOAT";
        case TINYGLTF_COMPONENT_TYPE_DOUBLE: return "DOUBLE";
        default: return "unknown";
    }
}

int typeComponents(int type) {
    switch (type) {
        case TINYGLTF_TYPE_SCALAR: return 1;
        case TINYGLTF_TYPE_VEC2: return 2;
        case TINYGLTF_TYPE_VEC3: return 3;
        case TINYGLTF_TYPE_VEC4: return 4;
        case TINYGLTF_TYPE_MAT2: return 4;
        case TINYGLTF_TYPE_MAT3: return 9;
        case TINYGLTF_TYPE_MAT4: return 16;
        default: return 0;
    }
}

const char* typeName(int type) {
    switch (type) {
        case TINYGLTF_TYPE_SCALAR: return "SCALAR";
        case TINYGLTF_TYPE_VEC2: return "VEC2";
        case TINYGLTF_TYPE_VEC3: return "VEC3";
        case TINYGLTF_TYPE_VEC4: return "VEC4";
        case TINYGLTF_TYPE_MAT2: return "MAT2";
        case TINYGLTF_TYPE_MAT3: return "MAT3";
        case TINYGLTF_TYPE_MAT4: return "MAT4";
        default: return "unknown";
    }
}

const char* modeName(int mode) {
    switch (mode) {
        case TINYGLTF_MODE_POINTS: return "POINTS";
        case TINYGLTF_MODE_LINE: return "LINES";
        case TINYGLTF_MODE_LINE_LOOP: return "LINE_LOOP";
        case TINYGLTF_MODE_LINE_STRIP: return "LINE_STRIP";
        case TINYGLTF_MODE_TRIANGLES: return "TRIANGLES";
        case TINYGLTF_MODE_TRIANGLE_STRIP: return "TRIANGLE_STRIP";
        case TINYGLTF_MODE_TRIANGLE_FAN: return "TRIANGLE_FAN";
        default: return "unknown";
    }
}

// One component, decoded per the glTF spec (normalized integers map to [0,1] or [-1,1]).
double readComponent(const unsigned char* p, int ct, bool normalized) {
    switch (ct) {
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: {
            const uint8_t v = *p;
            return normalized ? double(v) / 255.0 : double(v);
        }
        case TINYGLTF_COMPONENT_TYPE_BYTE: {
            int8_t v;
            std::memcpy(&v, p, 1);
            return normalized ? std::max(double(v) / 127.0, -1.0) : double(v);
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
            uint16_t v;
            std::memcpy(&v, p, 2);
            return normalized ? double(v) / 65535.0 : double(v);
        }
        case TINYGLTF_COMPONENT_TYPE_SHORT: {
            int16_t v;
            std::memcpy(&v, p, 2);
            return normalized ? std::max(double(v) / 32767.0, -1.0) : double(v);
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
            uint32_t v;
            std::memcpy(&v, p, 4);
            return double(v);
        }
        case TINYGLTF_COMPONENT_TYPE_FLOAT: {
            float v;
            std::memcpy(&v, p, 4);
            return double(v);
        }
        default: return 0.0;
    }
}

// Nesting depth of a JSON text (brackets outside strings). tinygltf and nlohmann recurse per
// level, so absurdly deep nesting (e.g. in "extras") would overflow the stack; glTF needs < 10.
uint32_t u32Le(const unsigned char* p) {
    return uint32_t(p[0]) | (uint32_t(p[1]) << 8) | (uint32_t(p[2]) << 16) | (uint32_t(p[3]) << 24);
}

size_t jsonNestingDepth(const unsigned char* p, size_t n) {
    size_t depth = 0, maxDepth = 0;
    bool inString = false, escaped = false;
    for (size_t i = 0; i < n; ++i) {
        const unsigned char c = p[i];
        if (inString) {
            if (escaped) escaped = false;
            else if (c == '\\') escaped = true;
            else if (c == '"') inString = false;
        } else if (c == '"') {
            inString = true;
        } else if (c == '[' || c == '{') {
            maxDepth = std::max(maxDepth, ++depth);
        } else if ((c == ']' || c == '}') && depth > 0) {
            --depth;
        }
    }
    return maxDepth;
}

// ---------------------------------------------------------------------------------------------
// File access: everything tinygltf reads besides the scene file goes through these callbacks, so
// the content hash covers exactly the files that were loaded, and lookups stay in the scene's
// directory (tinygltf would otherwise also search the current working directory).

struct FileRecorder {
    std::string baseDir;
    Fnv1a64* hash = nullptr;
};

bool recordingFileExists(const std::string& absFilename, void* user) {
    const auto* rec = static_cast<const FileRecorder*>(user);
    if (!rec->baseDir.empty()) {
        const std::string prefix = rec->baseDir + "/";
        if (absFilename.compare(0, prefix.size(), prefix) != 0) return false;
    }
    return tinygltf::FileExists(absFilename, nullptr);
}

std::string recordingExpandFilePath(const std::string& path, void*) { return path; }

bool recordingReadWholeFile(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user) {
    auto* rec = static_cast<FileRecorder*>(user);
    // Not tinygltf::ReadWholeFile: it asks a directory for its size (2^63) and allocates that.
    const std::string problem = gltf::readRegularFile(path, gltf::kMaxBufferFileBytes, out);
    if (!problem.empty()) {
        if (err) *err += "'" + path + "' " + problem;
        return false;
    }
    if (rec->hash) rec->hash->add(out->data(), out->size());
    return true;
}

bool refusingWriteWholeFile(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
    if (err) *err += "writing is not allowed while loading";
    return false;
}

// What the image callback needs besides tinygltf's arguments: the model (for bufferView
// images), a name for each image (tinygltf only has its index at that point) and the scene's
// texel budget so far.
struct ImageLoadContext {
    const tinygltf::Model* model = nullptr;
    std::vector<std::string> labels;  // "image 2 ('wood.png') named 'oak'"
    uint64_t texels = 0;
};

// Images: every byte range, header and size is checked before tinygltf's decoder (stb_image)
// sees it, so a forged header cannot make it allocate gigabytes or accept a cut file.
bool checkedImageLoader(tinygltf::Image* image, const int imageIndex, std::string* err, std::string* warn, int reqWidth,
                        int reqHeight, const unsigned char* bytes, int size, void* user) {
    auto* ctx = static_cast<ImageLoadContext*>(user);
    const tinygltf::Model* model = ctx->model;
    const std::string label = imageIndex >= 0 && size_t(imageIndex) < ctx->labels.size() ? ctx->labels[size_t(imageIndex)]
                                                                                         : "image " + std::to_string(imageIndex);
    auto refuse = [&](const std::string& why) {
        if (err) *err += label + ": " + why + "\n";
        return false;
    };
    if (image->bufferView >= 0) {
        // tinygltf hands the decoder &buffer[byteOffset] with byteLength bytes without checking
        // that range against the buffer.
        const size_t v = size_t(image->bufferView);
        bool ok = v < model->bufferViews.size();
        if (ok) {
            const tinygltf::BufferView& bv = model->bufferViews[v];
            ok = bv.buffer >= 0 && size_t(bv.buffer) < model->buffers.size();
            size_t end = 0;
            ok = ok && !addOverflows(bv.byteOffset, bv.byteLength, &end) &&
                 end <= model->buffers[size_t(bv.buffer)].data.size() && bv.byteLength <= size_t(std::numeric_limits<int>::max());
        }
        if (!ok) return refuse("bufferView " + std::to_string(image->bufferView) + " does not lie within its buffer");
    }
    if (size <= 0 || !bytes) return refuse("no image data");
    gltf::ImageHeader header;
    const std::string problem = gltf::imageProblem(bytes, size_t(size), &header);
    if (!problem.empty()) return refuse(problem);
    const uint64_t texels = uint64_t(header.width) * uint64_t(header.height);
    if (ctx->texels + texels > gltf::kMaxSceneTexels)
        return refuse("the scene's images would hold " + std::to_string(ctx->texels + texels) + " texels; the limit is " +
                      std::to_string(gltf::kMaxSceneTexels) + " per scene");
    ctx->texels += texels;
    std::string decodeErr;
    const bool ok = tinygltf::LoadImageData(image, imageIndex, &decodeErr, warn, reqWidth, reqHeight, bytes, size, nullptr);
    if (!ok) return refuse("cannot be decoded (truncated or corrupt " + std::string(header.format) + ")");
    return true;
}

// ---------------------------------------------------------------------------------------------
// JSON schema subset. tinygltf silently falls back to defaults when a property has the wrong JSON
// type (e.g. "doubleSided": 1, "metallicFactor": "0.5", "material": 1.0, an extension that is not
// an object, a primitive whose attributes are not an object is dropped). Every property this
// loader consumes is therefore type-checked on the raw JSON first.

class SchemaCheck {
public:
    using Json = nlohmann::json;
    enum Kind { Index, Size, Number, Bool, String, Object, Array };

    explicit SchemaCheck(std::string path) : path_(std::move(path)) {}

    void run(const Json& root) {
        if (!root.is_object()) fail("the top-level JSON value is not an object");
        extensionsEverywhere(root, "");
        ints(root, "scene", "");
        strings(root, "extensionsUsed", "");
        strings(root, "extensionsRequired", "");
        each(root, "scenes", "", [&](const Json& o, const std::string& p) { intArray(o, "nodes", p); });
        each(root, "nodes", "", [&](const Json& o, const std::string& p) {
            for (const char* k : {"camera", "mesh", "skin"}) ints(o, k, p);
            intArray(o, "children", p);
            numbers(o, "matrix", 16, p);
            numbers(o, "translation", 3, p);
            numbers(o, "rotation", 4, p);
            numbers(o, "scale", 3, p);
            numbers(o, "weights", 0, p);
            if (const Json* e = member(o, "extensions", Object, p))
                if (const Json* l = member(*e, "KHR_lights_punctual", Object, p + ".extensions"))
                    required(*l, "light", Index, p + ".extensions.KHR_lights_punctual");
        });
        each(root, "meshes", "", [&](const Json& o, const std::string& p) {
            const Json& prims = required(o, "primitives", Array, p);
            if (prims.empty()) fail(p + ".primitives is empty");
            numbers(o, "weights", 0, p);
            each(o, "primitives", p, [&](const Json& pr, const std::string& pp) {
                intMap(required(pr, "attributes", Object, pp), pp + ".attributes");
                for (const char* k : {"indices", "material", "mode"}) ints(pr, k, pp);
                each(pr, "targets", pp, [&](const Json& t, const std::string& tp) { intMap(t, tp); });
            });
        });
        each(root, "accessors", "", [&](const Json& o, const std::string& p) {
            ints(o, "bufferView", p);
            sizes(o, "byteOffset", p);
            required(o, "componentType", Index, p);
            required(o, "count", Size, p);
            required(o, "type", String, p);
            member(o, "normalized", Bool, p);
            if (const Json* sp = member(o, "sparse", Object, p)) {
                const std::string sp0 = p + ".sparse";
                required(*sp, "count", Index, sp0);
                const Json& i = required(*sp, "indices", Object, sp0);
                required(i, "bufferView", Index, sp0 + ".indices");
                required(i, "componentType", Index, sp0 + ".indices");
                ints(i, "byteOffset", sp0 + ".indices");  // tinygltf stores these as int
                const Json& v = required(*sp, "values", Object, sp0);
                required(v, "bufferView", Index, sp0 + ".values");
                ints(v, "byteOffset", sp0 + ".values");
            }
        });
        each(root, "bufferViews", "", [&](const Json& o, const std::string& p) {
            required(o, "buffer", Index, p);
            required(o, "byteLength", Size, p);
            for (const char* k : {"byteOffset", "byteStride"}) sizes(o, k, p);
        });
        each(root, "buffers", "", [&](const Json& o, const std::string& p) {
            required(o, "byteLength", Size, p);
            member(o, "uri", String, p);
        });
        each(root, "materials", "", [&](const Json& o, const std::string& p) {
            if (const Json* pbr = member(o, "pbrMetallicRoughness", Object, p)) {
                const std::string pp = p + ".pbrMetallicRoughness";
                numbers(*pbr, "baseColorFactor", 4, pp);
                for (const char* k : {"metallicFactor", "roughnessFactor"}) member(*pbr, k, Number, pp);
                for (const char* k : {"baseColorTexture", "metallicRoughnessTexture"}) textureInfo(*pbr, k, pp);
            }
            numbers(o, "emissiveFactor", 3, p);
            member(o, "alphaMode", String, p);
            member(o, "alphaCutoff", Number, p);
            member(o, "doubleSided", Bool, p);
            for (const char* k : {"normalTexture", "occlusionTexture", "emissiveTexture"}) textureInfo(o, k, p);
            if (const Json* e = member(o, "extensions", Object, p)) {
                const std::string ep = p + ".extensions";
                if (const Json* x = member(*e, "KHR_materials_emissive_strength", Object, ep))
                    member(*x, "emissiveStrength", Number, ep + ".KHR_materials_emissive_strength");
                if (const Json* x = member(*e, "KHR_materials_ior", Object, ep)) member(*x, "ior", Number, ep + ".KHR_materials_ior");
                if (const Json* x = member(*e, "KHR_materials_transmission", Object, ep)) {
                    member(*x, "transmissionFactor", Number, ep + ".KHR_materials_transmission");
                    textureInfo(*x, "transmissionTexture", ep + ".KHR_materials_transmission");
                }
                if (const Json* x = member(*e, "KHR_materials_specular", Object, ep)) {
                    const std::string xp = ep + ".KHR_materials_specular";
                    member(*x, "specularFactor", Number, xp);
                    numbers(*x, "specularColorFactor", 3, xp);
                    textureInfo(*x, "specularTexture", xp);
                    textureInfo(*x, "specularColorTexture", xp);
                }
            }
        });
        each(root, "textures", "", [&](const Json& o, const std::string& p) {
            for (const char* k : {"sampler", "source"}) ints(o, k, p);
        });
        each(root, "samplers", "", [&](const Json& o, const std::string& p) {
            for (const char* k : {"magFilter", "minFilter", "wrapS", "wrapT"}) ints(o, k, p);
        });
        each(root, "images", "", [&](const Json& o, const std::string& p) {
            member(o, "uri", String, p);
            member(o, "mimeType", String, p);
            ints(o, "bufferView", p);
        });
        each(root, "cameras", "", [&](const Json& o, const std::string& p) {
            required(o, "type", String, p);
            if (const Json* q = member(o, "perspective", Object, p))
                for (const char* k : {"yfov", "znear", "zfar", "aspectRatio"}) member(*q, k, Number, p + ".perspective");
        });
        if (const Json* e = member(root, "extensions", Object, ""))
            if (const Json* l = member(*e, "KHR_lights_punctual", Object, "extensions"))
                each(*l, "lights", "extensions.KHR_lights_punctual", [&](const Json& o, const std::string& p) {
                    required(o, "type", String, p);
                    numbers(o, "color", 3, p);
                    for (const char* k : {"intensity", "range"}) member(o, k, Number, p);
                    if (const Json* sp = member(o, "spot", Object, p))
                        for (const char* k : {"innerConeAngle", "outerConeAngle"}) member(*sp, k, Number, p + ".spot");
                });
    }

private:
    [[noreturn]] void fail(const std::string& what) const { throw InputError(path_ + ": invalid glTF: " + what); }

    static const char* kindName(Kind k) {
        switch (k) {
            case Index: return "an integer in [0, 2^31)";
            case Size: return "a non-negative integer";
            case Number: return "a number";
            case Bool: return "a boolean";
            case String: return "a string";
            case Object: return "an object";
            default: return "an array";
        }
    }
    static bool is(const Json& v, Kind k) {
        switch (k) {
            case Index: return v.is_number_integer() && v.get<int64_t>() >= 0 && v.get<int64_t>() <= std::numeric_limits<int>::max();
            case Size: return v.is_number_unsigned() || (v.is_number_integer() && v.get<int64_t>() >= 0);
            case Number: return v.is_number();
            case Bool: return v.is_boolean();
            case String: return v.is_string();
            case Object: return v.is_object();
            default: return v.is_array();
        }
    }
    static std::string join(const std::string& path, const std::string& key) { return path.empty() ? key : path + "." + key; }

    const Json* member(const Json& o, const char* key, Kind k, const std::string& path) const {
        auto it = o.find(key);
        if (it == o.end()) return nullptr;
        if (!is(*it, k)) fail(join(path, key) + " must be " + kindName(k) + " (it is " + it->type_name() + ")");
        return &*it;
    }
    const Json& required(const Json& o, const char* key, Kind k, const std::string& path) const {
        const Json* v = member(o, key, k, path);
        if (!v) fail(join(path, key) + " is missing");
        return *v;
    }
    void ints(const Json& o, const char* key, const std::string& path) const { member(o, key, Index, path); }
    void sizes(const Json& o, const char* key, const std::string& path) const { member(o, key, Size, path); }
    void numbers(const Json& o, const char* key, size_t n, const std::string& path) const {
        const Json* a = member(o, key, Array, path);
        if (!a) return;
        if (n && a->size() != n) fail(join(path, key) + " must have " + std::to_string(n) + " elements (it has " + std::to_string(a->size()) + ")");
        for (const Json& v : *a)
            if (!v.is_number()) fail(join(path, key) + " must contain only numbers");
    }
    void intArray(const Json& o, const char* key, const std::string& path) const {
        if (const Json* a = member(o, key, Array, path))
            for (const Json& v : *a)
                if (!is(v, Index)) fail(join(path, key) + " must contain only integers in [0, 2^31)");
    }
    void strings(const Json& o, const char* key, const std::string& path) const {
        if (const Json* a = member(o, key, Array, path))
            for (const Json& v : *a)
                if (!v.is_string()) fail(join(path, key) + " must contain only strings");
    }
    void intMap(const Json& o, const std::string& path) const {
        if (!o.is_object()) fail(path + " must be an object");
        for (auto it = o.begin(); it != o.end(); ++it)
            if (!is(*it, Index)) fail(path + "." + it.key() + " must be an accessor index (an integer in [0, 2^31))");
    }
    void textureInfo(const Json& o, const char* key, const std::string& path) const {
        if (const Json* t = member(o, key, Object, path)) {
            required(*t, "index", Index, join(path, key));
            ints(*t, "texCoord", join(path, key));
        }
    }
    template <typename F>
    void each(const Json& o, const char* key, const std::string& path, F fn) const {
        const Json* a = member(o, key, Array, path);
        if (!a) return;
        for (size_t i = 0; i < a->size(); ++i) {
            const std::string p = join(path, key) + "[" + std::to_string(i) + "]";
            if (!(*a)[i].is_object()) fail(p + " must be an object");
            fn((*a)[i], p);
        }
    }
    // Every "extensions" property (outside "extras") must be an object of objects.
    void extensionsEverywhere(const Json& v, const std::string& path) const {
        if (v.is_object()) {
            for (auto it = v.begin(); it != v.end(); ++it) {
                if (it.key() == "extras") continue;
                const std::string p = join(path, it.key());
                if (it.key() == "extensions") {
                    if (!it->is_object()) fail(p + " must be an object");
                    for (auto e = it->begin(); e != it->end(); ++e)
                        if (!e->is_object()) fail(p + "." + e.key() + " must be an object");
                }
                extensionsEverywhere(*it, p);
            }
        } else if (v.is_array()) {
            for (size_t i = 0; i < v.size(); ++i) extensionsEverywhere(v[i], path + "[" + std::to_string(i) + "]");
        }
    }

    std::string path_;
};

// ---------------------------------------------------------------------------------------------
// The loader proper

struct DecodedAccessor {
    std::vector<double> values;  // count * components
    size_t count = 0;
    int components = 0;
    double at(size_t i, int c) const { return values[i * size_t(components) + size_t(c)]; }
};

struct AccessorFormat {
    int componentType;
    bool normalized;
};

struct TextureKey {
    int texture;
    bool srgb;
    bool operator<(const TextureKey& o) const { return texture != o.texture ? texture < o.texture : srgb < o.srgb; }
};

struct MaterialUse {
    int sceneIndex = -1;
    bool usesTexture = false;
};

class Loader {
public:
    Loader(std::string path, const LoadOptions& options) : path_(std::move(path)), options_(options) {}

    Scene load();

private:
    [[noreturn]] void fail(const std::string& what) const { throw InputError(path_ + ": " + what); }
    // Warnings are collected and written to info.warnings at the end, one line per distinct
    // problem: the same problem on 149 materials is one line with a count, not 149 lines.
    void warn(const std::string& what) { warn("", what); }
    void warn(const std::string& who, const std::string& what);
    void flushWarnings();

    void readAndParse();
    void checkAsset();
    void checkExtensions();
    void traverse();
    void visitNode(int nodeIndex, const dmat4& world);
    dmat4 localTransform(int nodeIndex) const;
    void addMesh(int nodeIndex, int meshIndex, const dmat4& world);
    void addPrimitive(int nodeIndex, int meshIndex, int primIndex, const dmat4& world);
    void addLight(int nodeIndex, const tinygltf::Value& ext, const dmat4& world);
    void addCamera(int nodeIndex, const dmat4& world);
    void defaultCamera();

    const tinygltf::Accessor& accessor(int index, const std::string& who) const;
    DecodedAccessor decode(int index, const std::string& who, const std::vector<int>& types,
                           const std::vector<AccessorFormat>& formats) const;
    const unsigned char* viewBytes(int viewIndex, const std::string& who, size_t* length, size_t* stride) const;

    MaterialUse material(int gltfIndex);
    Material convertMaterial(int gltfIndex, bool* usesTexture);
    int texture(const std::string& who, int index, int texCoord, const tinygltf::ExtensionMap& extensions, bool srgb);
    float factor(double v, const std::string& who, double lo, double hi) const;

    std::string path_;
    LoadOptions options_;
    tinygltf::Model model_;
    Scene scene_;
    Fnv1a64 hash_;
    ImageLoadContext imageContext_;
    std::map<int, MaterialUse> materialMap_;
    MaterialUse defaultMaterial_;
    std::map<TextureKey, int> textureMap_;
    int cameraNode_ = -1;
    int extraCameraNodes_ = 0;
    size_t degenerateTriangles_ = 0;
    size_t zeroNormals_ = 0;
    std::vector<std::pair<std::string, std::vector<std::string>>> warnings_;  // what -> who, in first-seen order
};

void Loader::warn(const std::string& who, const std::string& what) {
    for (auto& w : warnings_)
        if (w.first == what) {
            w.second.push_back(who);
            return;
        }
    warnings_.push_back({what, {who}});
}

void Loader::flushWarnings() {
    constexpr size_t kNamed = 3;  // objects named in an aggregated line
    for (const auto& [what, whos] : warnings_) {
        if (whos.size() == 1) {
            scene_.info.warnings.push_back(whos[0].empty() ? what : whos[0] + ": " + what);
            continue;
        }
        // "149 materials" when every object is of one kind ("material 3 ('x')"), else "149 times".
        auto kind = [](const std::string& who) { return who.substr(0, who.find(' ')); };
        bool oneKind = !whos[0].empty();
        for (const std::string& w : whos) oneKind = oneKind && kind(w) == kind(whos[0]);
        std::string line = what + " (" + std::to_string(whos.size()) + (oneKind ? " " + kind(whos[0]) + "s" : " times");
        if (!whos[0].empty()) {
            line += ": ";
            for (size_t i = 0; i < std::min(kNamed, whos.size()); ++i) line += (i ? ", " : "") + whos[i];
            if (whos.size() > kNamed) line += " and " + std::to_string(whos.size() - kNamed) + " more";
        }
        scene_.info.warnings.push_back(line + ")");
    }
    warnings_.clear();
}

// ----- reading and parsing

void Loader::readAndParse() {
    // What the path is comes first: a directory, FIFO or device is refused before anything opens it.
    uint64_t fileSize = 0;
    if (const std::string p = gltf::regularFileProblem(path_, std::numeric_limits<uint64_t>::max(), &fileSize); !p.empty())
        fail(p);
    const std::string ext = lower(path_);
    const bool binary = endsWith(ext, ".glb");
    if (!binary && !endsWith(ext, ".gltf"))
        fail("unknown scene file type (expected a .gltf or .glb file name extension)");
    if (fileSize >= gltf::kMaxSceneFileBytes) fail("the file is too large (4 GiB or more)");

    std::vector<unsigned char> bytes;
    if (const std::string p = gltf::readRegularFile(path_, gltf::kMaxSceneFileBytes - 1, &bytes); !p.empty()) fail(p);
    if (bytes.empty()) fail("the file is empty");
    hash_.add(bytes.data(), bytes.size());

    if (binary) {
        // tinygltf checks most of the GLB header; these two it does not.
        auto u32 = [&](size_t off) { return u32Le(bytes.data() + off); };
        if (bytes.size() < 20 || std::memcmp(bytes.data(), "glTF", 4) != 0)
            fail("not a binary glTF file (bad GLB header)");
        if (u32(4) != 2) fail("GLB container version " + std::to_string(u32(4)) + " is not supported (expected 2)");
        const uint64_t length = u32(8);
        const uint64_t jsonEnd = 20ull + u32(12);
        if (length <= bytes.size() && jsonEnd + 8 <= length && jsonEnd + 8 + uint64_t(u32(size_t(jsonEnd))) > length)
            fail("GLB BIN chunk extends past the end of the file");
    }
    {
        size_t jsonBegin = 0, jsonLength = bytes.size();  // only the JSON chunk of a GLB
        if (binary) {
            jsonBegin = 20;
            jsonLength = std::min<size_t>(bytes.size() - 20, u32Le(bytes.data() + 12));
        }
        if (jsonNestingDepth(bytes.data() + jsonBegin, jsonLength) > 256) fail("JSON nested more than 256 levels deep");
    }

    std::string baseDir;
    const size_t slash = path_.find_last_of("/\\");
    if (slash != std::string::npos) baseDir = path_.substr(0, slash);

    // The raw JSON, when it parses, is used to check every external file before tinygltf reads it
    // (tinygltf reports a syntax error better, so a text that does not parse is left to it).
    nlohmann::json root;
    {
        size_t jsonBegin = 0, jsonLength = bytes.size();
        if (binary) {
            jsonBegin = 20;
            jsonLength = std::min<size_t>(bytes.size() - 20, u32Le(bytes.data() + 12));
        }
        const auto* text = reinterpret_cast<const char*>(bytes.data()) + jsonBegin;
        root = nlohmann::json::parse(text, text + jsonLength, nullptr, false);
        if (!root.is_discarded() && root.is_object()) imageContext_.labels = gltf::checkExternalFiles(root, baseDir, path_);
    }

    FileRecorder recorder{baseDir, &hash_};
    tinygltf::TinyGLTF gltf;
    tinygltf::FsCallbacks fs{};
    fs.FileExists = &recordingFileExists;
    fs.ExpandFilePath = &recordingExpandFilePath;
    fs.ReadWholeFile = &recordingReadWholeFile;
    fs.WriteWholeFile = &refusingWriteWholeFile;
    fs.user_data = &recorder;
    gltf.SetFsCallbacks(fs);
    imageContext_.model = &model_;
    gltf.SetImageLoader(&checkedImageLoader, &imageContext_);

    std::string err, warnings;
    bool ok = false;
    try {
        if (binary)
            ok = gltf.LoadBinaryFromMemory(&model_, &err, &warnings, bytes.data(), unsigned(bytes.size()), baseDir);
        else
            ok = gltf.LoadASCIIFromString(&model_, &err, &warnings, reinterpret_cast<const char*>(bytes.data()),
                                          unsigned(bytes.size()), baseDir);
    } catch (const std::exception& e) {
        err += e.what();
        ok = false;
    }
    auto trim = [](std::string s) {
        while (!s.empty() && (s.back() == '\n' || s.back() == ' ' || s.back() == '\r')) s.pop_back();
        for (char& ch : s)
            if (ch == '\n') ch = ';';
        if (s.size() > 400) s = s.substr(0, 400) + "...";
        return s;
    };
    if (!ok) {
        std::string msg = trim(err);
        if (msg.empty()) msg = trim(warnings);
        if (msg.empty()) msg = "the glTF parser failed without a message";
        fail("glTF parse error: " + msg);
    }
    // Type-check the raw JSON (see SchemaCheck); tinygltf has already validated the syntax.
    if (root.is_discarded()) fail("glTF parse error: invalid JSON");
    SchemaCheck(path_).run(root);

    std::istringstream ws(warnings);
    for (std::string line; std::getline(ws, line);)
        if (!trim(line).empty()) warn("tinygltf: " + trim(line));
}

void Loader::checkAsset() {
    const std::string& v = model_.asset.version;
    if (v.empty()) fail("asset.version is missing");
    if (v.compare(0, 2, "2.") != 0) fail("glTF version '" + v + "' is not supported (expected 2.x)");
    const std::string& mv = model_.asset.minVersion;
    if (!mv.empty() && mv != "2.0") fail("asset.minVersion '" + mv + "' is not supported (expected 2.0)");
}

void Loader::checkExtensions() {
    for (const std::string& r : model_.extensionsRequired)
        if (!isSupportedExtension(r))
            fail("extension '" + r + "' is required by the file but not implemented (supported: KHR_lights_punctual, "
                 "KHR_materials_emissive_strength, KHR_materials_ior, KHR_materials_transmission, KHR_materials_specular)");

    scene_.info.extensionsUsed = model_.extensionsUsed;
    std::set<std::string> used(model_.extensionsUsed.begin(), model_.extensionsUsed.end());
    std::set<std::string> found;
    auto scan = [&](const tinygltf::ExtensionMap& m) {
        for (const auto& kv : m) found.insert(kv.first);
    };
    scan(model_.extensions);
    for (const auto& x : model_.scenes) scan(x.extensions);
    for (const auto& x : model_.nodes) scan(x.extensions);
    for (const auto& x : model_.meshes) {
        scan(x.extensions);
        for (const auto& p : x.primitives) scan(p.extensions);
    }
    for (const auto& x : model_.materials) {
        scan(x.extensions);
        scan(x.pbrMetallicRoughness.extensions);
        scan(x.pbrMetallicRoughness.baseColorTexture.extensions);
        scan(x.pbrMetallicRoughness.metallicRoughnessTexture.extensions);
        scan(x.normalTexture.extensions);
        scan(x.occlusionTexture.extensions);
        scan(x.emissiveTexture.extensions);
    }
    for (const auto& x : model_.textures) scan(x.extensions);
    for (const auto& x : model_.images) scan(x.extensions);
    for (const auto& x : model_.samplers) scan(x.extensions);
    for (const auto& x : model_.cameras) scan(x.extensions);
    for (const auto& x : model_.accessors) scan(x.extensions);
    for (const auto& x : model_.bufferViews) scan(x.extensions);
    for (const auto& x : model_.buffers) scan(x.extensions);
    for (const auto& x : model_.lights) scan(x.extensions);
    for (const auto& x : model_.skins) scan(x.extensions);
    for (const auto& x : model_.animations) scan(x.extensions);

    for (const std::string& f : found)
        if (!used.count(f)) {
            scene_.info.extensionsUsed.push_back(f);
            warn("extension '" + f + "' appears in the file but is not listed in extensionsUsed");
            used.insert(f);
        }
    for (const std::string& u : used)
        if (!isSupportedExtension(u)) {
            scene_.info.extensionsIgnored.push_back(u);
            warn("extension '" + u + "' is not implemented and not required: ignored (the file's core glTF data is rendered)");
        }
}

// ----- accessors

const unsigned char* Loader::viewBytes(int viewIndex, const std::string& who, size_t* length, size_t* stride) const {
    if (viewIndex < 0 || size_t(viewIndex) >= model_.bufferViews.size())
        fail(who + ": bufferView " + std::to_string(viewIndex) + " does not exist (the file has " +
             std::to_string(model_.bufferViews.size()) + ")");
    const tinygltf::BufferView& bv = model_.bufferViews[size_t(viewIndex)];
    const std::string vname = "bufferView " + std::to_string(viewIndex);
    if (bv.buffer < 0 || size_t(bv.buffer) >= model_.buffers.size())
        fail(who + ": " + vname + " refers to buffer " + std::to_string(bv.buffer) + ", which does not exist");
    const tinygltf::Buffer& buf = model_.buffers[size_t(bv.buffer)];
    if (bv.byteLength == 0) fail(who + ": " + vname + " has byteLength 0");
    size_t end = 0;
    if (addOverflows(bv.byteOffset, bv.byteLength, &end) || end > buf.data.size())
        fail(who + ": " + vname + " extends past the end of buffer " + std::to_string(bv.buffer) + " (needs " +
             (end ? std::to_string(end) : std::string("more than 2^64")) + " bytes, has " + std::to_string(buf.data.size()) + ")");
    *length = bv.byteLength;
    *stride = bv.byteStride;
    return buf.data.data() + bv.byteOffset;
}

const tinygltf::Accessor& Loader::accessor(int index, const std::string& who) const {
    if (index < 0 || size_t(index) >= model_.accessors.size())
        fail(who + " does not exist (the file has " + std::to_string(model_.accessors.size()) + " accessors)");
    return model_.accessors[size_t(index)];
}

DecodedAccessor Loader::decode(int index, const std::string& who, const std::vector<int>& types,
                               const std::vector<AccessorFormat>& formats) const {
    const tinygltf::Accessor& acc = accessor(index, who);

    bool typeOk = false;
    for (int t : types) typeOk = typeOk || t == acc.type;
    if (!typeOk) {
        std::string expected;
        for (int t : types) expected += (expected.empty() ? "" : " or ") + std::string(typeName(t));
        fail(who + " has type " + typeName(acc.type) + "; expected " + expected);
    }
    bool formatOk = false;
    for (const AccessorFormat& f : formats) formatOk = formatOk || (f.componentType == acc.componentType && f.normalized == acc.normalized);
    if (!formatOk) {
        std::string expected;
        for (const AccessorFormat& f : formats)
            expected += (expected.empty() ? "" : " or ") + std::string(componentTypeName(f.componentType)) +
                        (f.normalized ? " normalized" : "");
        fail(who + " has componentType " + componentTypeName(acc.componentType) + (acc.normalized ? " normalized" : "") +
             "; expected " + expected);
    }
    const int nc = typeComponents(acc.type);
    const size_t cs = componentSize(acc.componentType);
    const size_t elementSize = cs * size_t(nc);
    if (acc.count == 0) fail(who + " has count 0");
    // Every vertex or index ends up in uint32 indices; beyond that the file cannot be represented.
    if (acc.count > size_t(std::numeric_limits<uint32_t>::max()))
        fail(who + " has count " + std::to_string(acc.count) + ", more than this renderer supports (2^32 - 1)");

    DecodedAccessor out;
    out.count = acc.count;
    out.components = nc;

    if (acc.bufferView >= 0) {
        size_t viewLength = 0, viewStride = 0;
        const unsigned char* base = viewBytes(acc.bufferView, who, &viewLength, &viewStride);
        const size_t stride = viewStride ? viewStride : elementSize;
        if (stride < elementSize)
            fail(who + ": bufferView " + std::to_string(acc.bufferView) + " has byteStride " + std::to_string(viewStride) +
                 ", smaller than the element size " + std::to_string(elementSize) + " bytes");
        size_t needed = 0, span = 0;
        if (mulOverflows(stride, acc.count - 1, &span) || addOverflows(span, elementSize, &span) ||
            addOverflows(span, acc.byteOffset, &needed) || needed > viewLength)
            fail(who + " reads past the end of bufferView " + std::to_string(acc.bufferView) + " (needs " +
                 (needed ? std::to_string(needed) : std::string("more than 2^64")) + " bytes, has " +
                 std::to_string(viewLength) + ")");
        out.values.resize(acc.count * size_t(nc));
        const unsigned char* p = base + acc.byteOffset;
        for (size_t i = 0; i < acc.count; ++i, p += stride)
            for (int c = 0; c < nc; ++c)
                out.values[i * size_t(nc) + size_t(c)] = readComponent(p + size_t(c) * cs, acc.componentType, acc.normalized);
    } else {
        if (!acc.sparse.isSparse) fail(who + " has neither a bufferView nor sparse data");
        out.values.assign(acc.count * size_t(nc), 0.0);  // spec: zeros, then the sparse substitution
    }

    if (acc.sparse.isSparse) {
        const std::string sw = who + " sparse";
        const auto& sp = acc.sparse;
        if (sp.count <= 0 || size_t(sp.count) > acc.count)
            fail(sw + ".count " + std::to_string(sp.count) + " is not in [1, " + std::to_string(acc.count) + "]");
        const int ict = sp.indices.componentType;
        if (ict != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && ict != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
            ict != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
            fail(sw + ".indices has componentType " + componentTypeName(ict) + "; expected an unsigned integer type");
        if (sp.indices.byteOffset < 0 || sp.values.byteOffset < 0) fail(sw + " has a negative byteOffset");
        const size_t n = size_t(sp.count);
        size_t len = 0, vstride = 0, need = 0;
        const unsigned char* ib = viewBytes(sp.indices.bufferView, sw + ".indices", &len, &vstride);
        const size_t ics = componentSize(ict);
        if (mulOverflows(n, ics, &need) || addOverflows(need, size_t(sp.indices.byteOffset), &need) || need > len)
            fail(sw + ".indices reads past the end of bufferView " + std::to_string(sp.indices.bufferView) + " (needs " +
                 std::to_string(need) + " bytes, has " + std::to_string(len) + ")");
        std::vector<size_t> idx(n);
        for (size_t i = 0; i < n; ++i) {
            const double d = readComponent(ib + size_t(sp.indices.byteOffset) + i * ics, ict, false);
            idx[i] = size_t(d);
            if (idx[i] >= acc.count)
                fail(sw + ".indices[" + std::to_string(i) + "] = " + std::to_string(idx[i]) + " is out of range (count " +
                     std::to_string(acc.count) + ")");
            if (i > 0 && idx[i] <= idx[i - 1]) fail(sw + ".indices are not strictly increasing at position " + std::to_string(i));
        }
        const unsigned char* vb = viewBytes(sp.values.bufferView, sw + ".values", &len, &vstride);
        if (mulOverflows(n, elementSize, &need) || addOverflows(need, size_t(sp.values.byteOffset), &need) || need > len)
            fail(sw + ".values reads past the end of bufferView " + std::to_string(sp.values.bufferView) + " (needs " +
                 std::to_string(need) + " bytes, has " + std::to_string(len) + ")");
        for (size_t i = 0; i < n; ++i)
            for (int c = 0; c < nc; ++c)
                out.values[idx[i] * size_t(nc) + size_t(c)] = readComponent(
                    vb + size_t(sp.values.byteOffset) + i * elementSize + size_t(c) * cs, acc.componentType, acc.normalized);
    }
    return out;
}

// ----- node graph

dmat4 Loader::localTransform(int nodeIndex) const {
    const tinygltf::Node& n = model_.nodes[size_t(nodeIndex)];
    const std::string who = "node " + std::to_string(nodeIndex);
    if (!n.matrix.empty()) {
        if (n.matrix.size() != 16) fail(who + ": matrix has " + std::to_string(n.matrix.size()) + " elements (expected 16)");
        dmat4 m(1.0);
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r) m[c][r] = n.matrix[size_t(c * 4 + r)];  // column-major, as glTF stores it
        for (int i = 0; i < 16; ++i)
            if (!std::isfinite(n.matrix[size_t(i)])) fail(who + ": matrix has a non-finite element");
        if (m[0][3] != 0.0 || m[1][3] != 0.0 || m[2][3] != 0.0 || m[3][3] != 1.0)
            fail(who + ": matrix is not affine (its last row must be 0, 0, 0, 1)");
        return m;
    }
    dvec3 t(0.0), s(1.0);
    double q[4] = {0.0, 0.0, 0.0, 1.0};  // x, y, z, w
    if (!n.translation.empty()) {
        if (n.translation.size() != 3) fail(who + ": translation must have 3 elements");
        t = dvec3(n.translation[0], n.translation[1], n.translation[2]);
    }
    if (!n.scale.empty()) {
        if (n.scale.size() != 3) fail(who + ": scale must have 3 elements");
        s = dvec3(n.scale[0], n.scale[1], n.scale[2]);
    }
    if (!n.rotation.empty()) {
        if (n.rotation.size() != 4) fail(who + ": rotation must have 4 elements (a quaternion x, y, z, w)");
        for (int i = 0; i < 4; ++i) q[i] = n.rotation[size_t(i)];
        const double len = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
        if (!(std::abs(len - 1.0) <= 1e-3))
            fail(who + ": rotation quaternion is not unit length (length " + fmt(len) + ")");
        for (double& x : q) x /= len;
    }
    if (!(std::isfinite(t.x) && std::isfinite(t.y) && std::isfinite(t.z) && std::isfinite(s.x) && std::isfinite(s.y) &&
          std::isfinite(s.z)))
        fail(who + ": translation or scale is not finite");
    const double x = q[0], y = q[1], z = q[2], w = q[3];
    dmat4 m(1.0);  // m[column][row] = T * R * S
    m[0] = dvec4(1 - 2 * (y * y + z * z), 2 * (x * y + z * w), 2 * (x * z - y * w), 0.0) * s.x;
    m[1] = dvec4(2 * (x * y - z * w), 1 - 2 * (x * x + z * z), 2 * (y * z + x * w), 0.0) * s.y;
    m[2] = dvec4(2 * (x * z + y * w), 2 * (y * z - x * w), 1 - 2 * (x * x + y * y), 0.0) * s.z;
    m[3] = dvec4(t, 1.0);
    return m;
}

void Loader::traverse() {
    const size_t n = model_.nodes.size();
    // The node graph must be a forest: children in range, at most one parent, no cycles.
    std::vector<int> parent(n, -1);
    for (size_t i = 0; i < n; ++i)
        for (int ch : model_.nodes[i].children) {
            if (ch < 0 || size_t(ch) >= n)
                fail("node " + std::to_string(i) + ": child " + std::to_string(ch) + " does not exist (the file has " +
                     std::to_string(n) + " nodes)");
            if (size_t(ch) == i) fail("node " + std::to_string(i) + " is its own child (cycle in the node graph)");
            if (parent[size_t(ch)] >= 0)
                fail("node " + std::to_string(ch) + " has more than one parent (nodes " + std::to_string(parent[size_t(ch)]) +
                     " and " + std::to_string(i) + "); glTF nodes must form strict trees");
            parent[size_t(ch)] = int(i);
        }
    std::vector<uint8_t> state(n, 0);  // 0 unknown, 1 on the current upward walk, 2 reaches a root
    for (size_t i = 0; i < n; ++i) {
        std::vector<int> walk;
        int x = int(i);
        while (x >= 0 && state[size_t(x)] == 0) {
            state[size_t(x)] = 1;
            walk.push_back(x);
            x = parent[size_t(x)];
        }
        if (x >= 0 && state[size_t(x)] == 1) fail("cycle in the node graph through node " + std::to_string(x));
        for (int w : walk) state[size_t(w)] = 2;
    }

    std::vector<int> roots;
    if (!model_.scenes.empty()) {
        int s = model_.defaultScene;
        if (s >= 0 && size_t(s) >= model_.scenes.size())
            fail("default scene " + std::to_string(s) + " does not exist (the file has " + std::to_string(model_.scenes.size()) + " scenes)");
        if (s < 0) {
            s = 0;
            if (model_.scenes.size() > 1)
                warn("no default scene is set; scene 0 of " + std::to_string(model_.scenes.size()) + " is rendered");
        }
        roots = model_.scenes[size_t(s)].nodes;
        std::set<int> seen;
        for (int r : roots) {
            if (r < 0 || size_t(r) >= n)
                fail("scene " + std::to_string(s) + ": node " + std::to_string(r) + " does not exist (the file has " +
                     std::to_string(n) + " nodes)");
            if (parent[size_t(r)] >= 0)
                fail("scene " + std::to_string(s) + ": node " + std::to_string(r) + " is listed as a root but is a child of node " +
                     std::to_string(parent[size_t(r)]));
            if (!seen.insert(r).second) fail("scene " + std::to_string(s) + ": node " + std::to_string(r) + " is listed twice");
        }
    } else {
        for (size_t i = 0; i < n; ++i)
            if (parent[i] < 0) roots.push_back(int(i));
        if (!roots.empty()) warn("the file has no scenes; all root nodes are rendered");
    }
    if (!model_.animations.empty())
        warn("animations are ignored: the static pose given by the node transforms is rendered");

    // Iterative pre-order depth-first traversal (children in file order), transforms in double.
    std::vector<std::pair<int, dmat4>> stack;
    for (auto it = roots.rbegin(); it != roots.rend(); ++it) stack.emplace_back(*it, dmat4(1.0));
    while (!stack.empty()) {
        const auto [node, parentWorld] = stack.back();
        stack.pop_back();
        const dmat4 world = parentWorld * localTransform(node);
        visitNode(node, world);
        const auto& ch = model_.nodes[size_t(node)].children;
        for (auto it = ch.rbegin(); it != ch.rend(); ++it) stack.emplace_back(*it, world);
    }
}

void Loader::visitNode(int nodeIndex, const dmat4& world) {
    const tinygltf::Node& node = model_.nodes[size_t(nodeIndex)];
    if (node.camera >= 0 || node.camera < -1) addCamera(nodeIndex, world);
    auto lightExt = node.extensions.find("KHR_lights_punctual");
    if (lightExt != node.extensions.end()) addLight(nodeIndex, lightExt->second, world);
    if (node.mesh >= 0 || node.mesh < -1) {
        if (node.skin >= 0)
            warn("node " + std::to_string(nodeIndex) + ": skin " + std::to_string(node.skin) +
                 " is ignored; the mesh is rendered unskinned (its bind pose) with the node's transform");
        addMesh(nodeIndex, node.mesh, world);
    }
}

// ----- geometry

void Loader::addMesh(int nodeIndex, int meshIndex, const dmat4& world) {
    if (meshIndex < 0 || size_t(meshIndex) >= model_.meshes.size())
        fail("node " + std::to_string(nodeIndex) + ": mesh " + std::to_string(meshIndex) + " does not exist (the file has " +
             std::to_string(model_.meshes.size()) + " meshes)");
    const tinygltf::Mesh& mesh = model_.meshes[size_t(meshIndex)];
    for (size_t p = 0; p < mesh.primitives.size(); ++p) addPrimitive(nodeIndex, meshIndex, int(p), world);
}

void Loader::addPrimitive(int nodeIndex, int meshIndex, int primIndex, const dmat4& world) {
    const tinygltf::Node& node = model_.nodes[size_t(nodeIndex)];
    const tinygltf::Mesh& mesh = model_.meshes[size_t(meshIndex)];
    const tinygltf::Primitive& prim = mesh.primitives[size_t(primIndex)];
    const std::string who = "mesh " + std::to_string(meshIndex) + " primitive " + std::to_string(primIndex);
    auto accName = [&](int index, const char* role) { return who + ": accessor " + std::to_string(index) + " (" + role + ")"; };

    const int mode = prim.mode;
    if (mode >= TINYGLTF_MODE_POINTS && mode <= TINYGLTF_MODE_LINE_STRIP) {
        warn(who, std::string("mode ") + modeName(mode) + " skipped (points and lines have zero area and are invisible to light transport)");
        return;
    }
    if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP && mode != TINYGLTF_MODE_TRIANGLE_FAN)
        fail(who + ": invalid primitive mode " + std::to_string(mode));

    const auto findAttr = [&](const char* name) {
        auto it = prim.attributes.find(name);
        return it == prim.attributes.end() ? -2 : it->second;  // -2: absent
    };
    const int posIndex = findAttr("POSITION");
    if (posIndex == -2) fail(who + ": has no POSITION attribute");
    const int nrmIndex = findAttr("NORMAL");
    const int uvIndex = findAttr("TEXCOORD_0");
    const int colIndex = findAttr("COLOR_0");

    const AccessorFormat f32{TINYGLTF_COMPONENT_TYPE_FLOAT, false};
    const AccessorFormat u8n{TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, true};
    const AccessorFormat u16n{TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, true};
    const AccessorFormat s8n{TINYGLTF_COMPONENT_TYPE_BYTE, true};
    const AccessorFormat s16n{TINYGLTF_COMPONENT_TYPE_SHORT, true};

    DecodedAccessor pos = decode(posIndex, accName(posIndex, "POSITION"), {TINYGLTF_TYPE_VEC3}, {f32});
    const size_t nv = pos.count;
    DecodedAccessor nrm, uv;
    if (nrmIndex != -2) nrm = decode(nrmIndex, accName(nrmIndex, "NORMAL"), {TINYGLTF_TYPE_VEC3}, {f32});
    if (uvIndex != -2) uv = decode(uvIndex, accName(uvIndex, "TEXCOORD_0"), {TINYGLTF_TYPE_VEC2}, {f32, u8n, u16n});
    if (nrmIndex != -2 && nrm.count != nv)
        fail(accName(nrmIndex, "NORMAL") + " has count " + std::to_string(nrm.count) + " but POSITION has " + std::to_string(nv));
    if (uvIndex != -2 && uv.count != nv)
        fail(accName(uvIndex, "TEXCOORD_0") + " has count " + std::to_string(uv.count) + " but POSITION has " + std::to_string(nv));

    // Vertex colours multiply the base colour; not representable here, so only all-white passes.
    if (colIndex != -2) {
        DecodedAccessor col = decode(colIndex, accName(colIndex, "COLOR_0"), {TINYGLTF_TYPE_VEC3, TINYGLTF_TYPE_VEC4}, {f32, u8n, u16n});
        if (col.count != nv)
            fail(accName(colIndex, "COLOR_0") + " has count " + std::to_string(col.count) + " but POSITION has " + std::to_string(nv));
        for (size_t i = 0; i < col.values.size(); ++i)
            if (col.values[i] != 1.0)
                fail(accName(colIndex, "COLOR_0") + ": vertex colours are not implemented (they multiply the base colour); "
                     "only all-white COLOR_0 is accepted");
    }

    // Morph targets at the default weights (node.weights, else mesh.weights, else all zero).
    if (!prim.targets.empty()) {
        const std::vector<double>& weights = !node.weights.empty() ? node.weights : mesh.weights;
        if (!weights.empty() && weights.size() != prim.targets.size())
            fail(who + ": " + std::to_string(weights.size()) + " morph weights for " + std::to_string(prim.targets.size()) + " targets");
        bool any = false;
        for (double w : weights) {
            if (!std::isfinite(w)) fail(who + ": non-finite morph target weight");
            any = any || w != 0.0;
        }
        if (!any) {
            warn(who, "morph targets present with all default weights 0; the base shape is rendered");
        } else {
            warn(who, "morph targets applied at the default weights (static pose; animations are not evaluated)");
            for (size_t t = 0; t < prim.targets.size(); ++t) {
                const double w = weights[t];
                if (w == 0.0) continue;
                const std::string tw = who + " target " + std::to_string(t);
                for (const auto& attr : prim.targets[t]) {
                    DecodedAccessor* dst = nullptr;
                    DecodedAccessor delta;
                    const std::string an = tw + ": accessor " + std::to_string(attr.second) + " (" + attr.first + ")";
                    if (attr.first == "POSITION") {
                        delta = decode(attr.second, an, {TINYGLTF_TYPE_VEC3}, {f32, s8n, s16n});
                        dst = &pos;
                    } else if (attr.first == "NORMAL" && nrmIndex != -2) {
                        delta = decode(attr.second, an, {TINYGLTF_TYPE_VEC3}, {f32, s8n, s16n});
                        dst = &nrm;
                    } else if (attr.first == "TEXCOORD_0" && uvIndex != -2) {
                        delta = decode(attr.second, an, {TINYGLTF_TYPE_VEC2}, {f32, s8n, s16n, u8n, u16n});
                        dst = &uv;
                    } else {
                        continue;  // TANGENT etc.: not used by this renderer
                    }
                    if (delta.count != nv)
                        fail(an + " has count " + std::to_string(delta.count) + " but POSITION has " + std::to_string(nv));
                    for (size_t i = 0; i < dst->values.size(); ++i) dst->values[i] += w * delta.values[i];
                }
            }
        }
    }

    // Indices (or the implicit 0..n-1).
    std::vector<uint32_t> idx;
    if (prim.indices >= 0 || prim.indices < -1) {
        const std::string an = accName(prim.indices, "indices");
        const tinygltf::Accessor& ia = accessor(prim.indices, an);
        if (ia.bufferView >= 0 && size_t(ia.bufferView) < model_.bufferViews.size() &&
            model_.bufferViews[size_t(ia.bufferView)].byteStride != 0 &&
            model_.bufferViews[size_t(ia.bufferView)].byteStride != componentSize(ia.componentType))
            fail(an + ": index data must be tightly packed (bufferView " + std::to_string(ia.bufferView) + " has byteStride " +
                 std::to_string(model_.bufferViews[size_t(ia.bufferView)].byteStride) + ")");
        DecodedAccessor d = decode(prim.indices, an, {TINYGLTF_TYPE_SCALAR},
                                   {{TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, false},
                                    {TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, false},
                                    {TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, false}});
        idx.resize(d.count);
        for (size_t i = 0; i < d.count; ++i) {
            const double v = d.values[i];
            if (v >= double(nv))
                fail(an + ": index " + std::to_string(uint64_t(v)) + " at position " + std::to_string(i) +
                     " is out of range (the primitive has " + std::to_string(nv) + " vertices)");
            idx[i] = uint32_t(v);
        }
    } else {
        idx.resize(nv);
        for (size_t i = 0; i < nv; ++i) idx[i] = uint32_t(i);
    }

    std::vector<glm::uvec3> tris;
    if (mode == TINYGLTF_MODE_TRIANGLES) {
        if (idx.size() % 3 != 0)
            fail(who + ": mode TRIANGLES needs a multiple of 3 " + std::string(prim.indices >= 0 ? "indices" : "vertices") + ", got " +
                 std::to_string(idx.size()));
        for (size_t i = 0; i + 2 < idx.size(); i += 3) tris.emplace_back(idx[i], idx[i + 1], idx[i + 2]);
    } else if (idx.size() < 3) {
        warn(who, std::string(modeName(mode)) + " with fewer than 3 vertices draws nothing");
    } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
        // glTF 2.0 spec: p_i = {v_i, v_{i+(1+i%2)}, v_{i+(2-i%2)}} keeps the winding consistent.
        for (size_t i = 0; i + 2 < idx.size(); ++i) {
            const size_t odd = i % 2;
            tris.emplace_back(idx[i], idx[i + 1 + odd], idx[i + 2 - odd]);
        }
    } else {
        // TRIANGLE_FAN: p_i = {v_{i+1}, v_{i+2}, v_0}.
        for (size_t i = 0; i + 2 < idx.size(); ++i) tris.emplace_back(idx[i + 1], idx[i + 2], idx[0]);
    }

    // Material (converted on first use).
    MaterialUse mat;
    if (prim.material >= 0 || prim.material < -1) {
        if (size_t(prim.material) >= model_.materials.size() || prim.material < 0)
            fail(who + ": material " + std::to_string(prim.material) + " does not exist (the file has " +
                 std::to_string(model_.materials.size()) + " materials)");
        mat = material(prim.material);
        if (mat.usesTexture && uvIndex == -2)
            fail(who + ": material " + std::to_string(prim.material) + " uses a texture but the primitive has no TEXCOORD_0");
    } else {
        if (defaultMaterial_.sceneIndex < 0) {
            Material m;  // glTF defaults: base colour 1, metallic 1, roughness 1
            m.name = "glTF default material";
            defaultMaterial_.sceneIndex = int(scene_.materials.size());
            scene_.materials.push_back(m);
        }
        mat = defaultMaterial_;
    }

    // Transform into world space. Normals use the cofactor matrix (inverse-transpose up to the
    // positive factor |det|), signed so that it equals the inverse-transpose's direction.
    const dmat3 a(world);
    const double det = glm::determinant(a);
    dmat3 normalMatrix(glm::cross(a[1], a[2]), glm::cross(a[2], a[0]), glm::cross(a[0], a[1]));
    if (det < 0.0) normalMatrix = -normalMatrix;

    TriangleMesh& out = scene_.mesh;
    const size_t base = out.positions.size();
    if (base + nv > size_t(std::numeric_limits<uint32_t>::max()))
        fail(who + ": the scene has more vertices than this renderer supports (2^32 - 1)");
    out.positions.reserve(base + nv);
    out.normals.reserve(base + nv);
    out.uvs.reserve(base + nv);
    out.vertexHasNormal.reserve(base + nv);
    for (size_t i = 0; i < nv; ++i) {
        const dvec3 p(pos.at(i, 0), pos.at(i, 1), pos.at(i, 2));
        if (!(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)))
            fail(accName(posIndex, "POSITION") + ": vertex " + std::to_string(i) + " is not finite (NaN or infinity)");
        const dvec3 wp = dvec3(world * dvec4(p, 1.0));
        const Vec3 fp(wp);
        if (!isFinite(fp))
            fail(accName(posIndex, "POSITION") + ": vertex " + std::to_string(i) + " is not finite after node " +
                 std::to_string(nodeIndex) + "'s transform");
        out.positions.push_back(fp);

        Vec3 fn(0.f);
        uint8_t has = 0;
        if (nrmIndex != -2) {
            const dvec3 nn(nrm.at(i, 0), nrm.at(i, 1), nrm.at(i, 2));
            if (!(std::isfinite(nn.x) && std::isfinite(nn.y) && std::isfinite(nn.z)))
                fail(accName(nrmIndex, "NORMAL") + ": vertex " + std::to_string(i) + " is not finite (NaN or infinity)");
            const dvec3 wn = normalMatrix * nn;
            const double len = glm::length(wn);
            if (len > 0.0 && std::isfinite(len)) {
                fn = Vec3(wn / len);
                has = isFinite(fn) ? 1 : 0;
                if (!has) fn = Vec3(0.f);
            }
            if (!has) ++zeroNormals_;
        }
        out.normals.push_back(fn);
        out.vertexHasNormal.push_back(has);

        Vec2 t(0.f);
        if (uvIndex != -2) {
            t = Vec2(float(uv.at(i, 0)), float(uv.at(i, 1)));
            if (!(std::isfinite(t.x) && std::isfinite(t.y)))
                fail(accName(uvIndex, "TEXCOORD_0") + ": vertex " + std::to_string(i) + " is not finite");
        }
        out.uvs.push_back(t);
    }

    for (glm::uvec3 t : tris) {
        if (det < 0.0) std::swap(t.y, t.z);  // a mirroring transform would turn front faces into back faces
        const Vec3& p0 = out.positions[base + t.x];
        const Vec3& p1 = out.positions[base + t.y];
        const Vec3& p2 = out.positions[base + t.z];
        const float area = 0.5f * glm::length(glm::cross(p1 - p0, p2 - p0));
        if (!std::isfinite(area))
            fail(who + ": a triangle's area overflows single precision (coordinates too large)");
        if (!(area > 0.f)) {
            ++degenerateTriangles_;
            continue;
        }
        out.indices.emplace_back(uint32_t(base) + t.x, uint32_t(base) + t.y, uint32_t(base) + t.z);
        out.triangleMaterial.push_back(uint32_t(mat.sceneIndex));
        out.triangleLight.push_back(-1);
    }
}

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
    bool usesTexture = false;
    Material m = convertMaterial(gltfIndex, &usesTexture);
    use.sceneIndex = int(scene_.materials.size());
    use.usesTexture = usesTexture;
    scene_.materials.push_back(std::move(m));
    materialMap_[gltfIndex] = use;
    return use;
}

int Loader::texture(const std::string& who, int index, int texCoord, const tinygltf::ExtensionMap& extensions, bool srgb) {
    if (index < 0 || size_t(index) >= model_.textures.size())
        fail(who + ": texture " + std::to_string(index) + " does not exist (the file has " + std::to_string(model_.textures.size()) +
             " textures)");
    if (texCoord != 0)
        fail(who + ": uses texCoord " + std::to_string(texCoord) + "; only TEXCOORD_0 is supported");
    if (extensions.count("KHR_texture_transform"))
        fail(who + ": KHR_texture_transform is not supported (it would change the picture)");
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
    }

    const tinygltf::Image& img = model_.images[size_t(tex.source)];
    const std::string iw = tw + ": image " + std::to_string(tex.source) + (img.uri.empty() || img.uri.compare(0, 5, "data:") == 0
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
    out.width = img.width;
    out.height = img.height;
    out.texels.resize(texels);
    const double maxv = img.bits == 8 ? 255.0 : 65535.0;
    auto channel = [&](size_t texel, int c) {
        const unsigned char* p = img.image.data() + (texel * size_t(img.component) + size_t(c)) * bytesPer;
        if (bytesPer == 1) return float(double(*p) / maxv);
        uint16_t v;
        std::memcpy(&v, p, 2);
        return float(double(v) / maxv);
    };
    for (size_t i = 0; i < texels; ++i) {
        Vec4 v(0.f, 0.f, 0.f, 1.f);
        switch (img.component) {
            case 1: v = Vec4(channel(i, 0), channel(i, 0), channel(i, 0), 1.f); break;
            case 2: v = Vec4(channel(i, 0), channel(i, 0), channel(i, 0), channel(i, 1)); break;
            case 3: v = Vec4(channel(i, 0), channel(i, 1), channel(i, 2), 1.f); break;
            default: v = Vec4(channel(i, 0), channel(i, 1), channel(i, 2), channel(i, 3)); break;
        }
        if (srgb) v = Vec4(srgbToLinear(v.r), srgbToLinear(v.g), srgbToLinear(v.b), v.a);
        out.texels[i] = v;
    }
    const int sceneIndex = int(scene_.textures.size());
    scene_.textures.push_back(std::move(out));
    textureMap_[key] = sceneIndex;
    return sceneIndex;
}

Material Loader::convertMaterial(int gi, bool* usesTexture) {
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

    if (g.alphaMode == "MASK" || g.alphaMode == "BLEND")
        warn(who, "alphaMode " + g.alphaMode + " is not implemented; alpha is ignored and the surface rendered opaque");
    else if (g.alphaMode != "OPAQUE")
        fail(who + ": invalid alphaMode '" + g.alphaMode + "'");
    m.doubleSided = g.doubleSided;

    if (pbr.baseColorTexture.index >= 0) {
        m.baseColorTexture = texture(who + " baseColorTexture", pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord,
                                     pbr.baseColorTexture.extensions, true);
        *usesTexture = true;
    }
    if (pbr.metallicRoughnessTexture.index >= 0) {
        m.metallicRoughnessTexture = texture(who + " metallicRoughnessTexture", pbr.metallicRoughnessTexture.index,
                                             pbr.metallicRoughnessTexture.texCoord, pbr.metallicRoughnessTexture.extensions, false);
        *usesTexture = true;
    }
    if (g.normalTexture.index >= 0)
        warn(who, "normalTexture ignored (normal mapping is not implemented)");
    if (g.occlusionTexture.index >= 0)
        warn(who, "occlusionTexture ignored (occlusion is computed by the light transport itself)");

    // Reads a number from an extension object; absent -> def.
    auto number = [&](const tinygltf::Value& obj, const char* ext, const char* key, double def) {
        if (!obj.IsObject() || !obj.Has(key)) return def;
        const tinygltf::Value& v = obj.Get(key);
        if (!v.IsNumber()) fail(who + ": " + ext + "." + key + " is not a number");
        return v.GetNumberAsDouble();
    };
    auto noTexture = [&](const tinygltf::Value& obj, const char* ext, const char* key) {
        if (obj.IsObject() && obj.Has(key)) fail(who + ": " + ext + "." + key + " is not supported (textures for this parameter are not implemented)");
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
        if (!isBlack(m.emission))
            fail(who + ": emissiveTexture is not supported (it would change the emitted radiance)");
        warn(who, "emissiveTexture ignored (the emissive factor is zero, so it has no effect)");
    }

    if (const tinygltf::Value* e = ext("KHR_materials_ior")) {
        const double ior = number(*e, "KHR_materials_ior", "ior", 1.5);
        if (!std::isfinite(ior) || !std::isfinite(float(ior))) fail(who + ": KHR_materials_ior.ior is not finite");
        if (ior != 0.0 && ior < 1.0)
            fail(who + ": KHR_materials_ior.ior = " + fmt(ior) + " is invalid (must be >= 1, or exactly 0)");
        m.ior = float(ior);
    }
    if (const tinygltf::Value* e = ext("KHR_materials_transmission")) {
        noTexture(*e, "KHR_materials_transmission", "transmissionTexture");
        m.transmission = factor(number(*e, "KHR_materials_transmission", "transmissionFactor", 0.0),
                                who + ": KHR_materials_transmission.transmissionFactor", 0.0, 1.0);
    }
    if (const tinygltf::Value* e = ext("KHR_materials_specular")) {
        noTexture(*e, "KHR_materials_specular", "specularTexture");
        noTexture(*e, "KHR_materials_specular", "specularColorTexture");
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
    if (m.transmission > 0.f) {
        if (m.roughness > 0.f)
            fail(who + ": rough transmission is not implemented (transmissionFactor " + fmt(double(m.transmission)) +
                 " with roughnessFactor " + fmt(pbr.roughnessFactor) + "; only roughness 0 glass is supported)");
        if (m.ior == 0.f) fail(who + ": KHR_materials_ior.ior = 0 cannot be combined with transmission");
    }
    return m;
}

// ----- lights and cameras

void Loader::addLight(int nodeIndex, const tinygltf::Value& ext, const dmat4& world) {
    const std::string nw = "node " + std::to_string(nodeIndex);
    if (!ext.IsObject() || !ext.Has("light") || !ext.Get("light").IsInt())
        fail(nw + ": KHR_lights_punctual has no integer 'light' index");
    const int li = ext.Get("light").Get<int>();
    if (li < 0 || size_t(li) >= model_.lights.size())
        fail(nw + ": KHR_lights_punctual light " + std::to_string(li) + " does not exist (the file has " +
             std::to_string(model_.lights.size()) + " lights)");
    const tinygltf::Light& g = model_.lights[size_t(li)];
    const std::string who = nw + ": KHR_lights_punctual light " + std::to_string(li) + (g.name.empty() ? "" : " ('" + g.name + "')");

    Light l;
    if (g.type == "point")
        l.type = LightType::Point;
    else if (g.type == "spot")
        l.type = LightType::Spot;
    else if (g.type == "directional")
        l.type = LightType::Directional;
    else
        fail(who + ": unknown light type '" + g.type + "'");

    Rgb color(1.f);
    if (!g.color.empty()) {
        if (g.color.size() != 3) fail(who + ": color must have 3 elements");
        for (int c = 0; c < 3; ++c)
            color[c] = factor(g.color[size_t(c)], who + ": color[" + std::to_string(c) + "]", 0.0, std::numeric_limits<double>::max());
    }
    const float intensity = factor(g.intensity, who + ": intensity", 0.0, std::numeric_limits<double>::max());
    for (int c = 0; c < 3; ++c)
        l.emission[c] = factor(double(color[c]) * double(intensity), who + ": color * intensity", 0.0, std::numeric_limits<double>::max());
    if (g.range > 0.0)
        warn(who + " (range " + fmt(g.range) + ")", "range ignored (physically based inverse-square falloff is used)");
    else if (g.range < 0.0 || !std::isfinite(g.range))
        fail(who + ": invalid range " + fmt(g.range));

    const dvec3 p = dvec3(world[3]);
    const dvec3 d = dmat3(world) * dvec3(0.0, 0.0, -1.0);
    const double dl = glm::length(d);
    if (!(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z))) fail(who + ": position is not finite");
    l.position = Vec3(p);
    if (l.type != LightType::Point) {
        if (!(dl > 0.0) || !std::isfinite(dl)) fail(who + ": the node's transform collapses the light direction (zero scale)");
        l.direction = Vec3(d / dl);
    }
    if (l.type == LightType::Spot) {
        const double inner = g.spot.innerConeAngle, outer = g.spot.outerConeAngle;
        const double halfPi = 1.57079632679489661923;
        if (!std::isfinite(inner) || !std::isfinite(outer) || inner < 0.0 || outer <= 0.0 || outer > halfPi + 1e-9 || inner >= outer)
            fail(who + ": spot cone angles must satisfy 0 <= innerConeAngle < outerConeAngle <= pi/2 (got inner " + fmt(inner) +
                 ", outer " + fmt(outer) + ")");
        l.cosInner = float(std::cos(inner));
        l.cosOuter = float(std::cos(std::min(outer, halfPi)));
    }
    scene_.lights.push_back(l);
    scene_.lightNames.resize(scene_.lights.size() - 1);  // lights added without a name stay unnamed
    scene_.lightNames.push_back(who);
}

void Loader::addCamera(int nodeIndex, const dmat4& world) {
    const tinygltf::Node& node = model_.nodes[size_t(nodeIndex)];
    const std::string nw = "node " + std::to_string(nodeIndex);
    if (node.camera < 0 || size_t(node.camera) >= model_.cameras.size())
        fail(nw + ": camera " + std::to_string(node.camera) + " does not exist (the file has " + std::to_string(model_.cameras.size()) +
             " cameras)");
    const tinygltf::Camera& cam = model_.cameras[size_t(node.camera)];
    const std::string who = nw + ": camera " + std::to_string(node.camera);
    if (cam.type == "orthographic") fail(who + ": orthographic cameras are not implemented");
    if (cam.type != "perspective") fail(who + ": unknown camera type '" + cam.type + "'");
    if (cameraNode_ >= 0) {
        ++extraCameraNodes_;
        return;
    }
    const double yfov = cam.perspective.yfov;
    if (!(yfov > 0.0) || !(yfov < 3.14159265358979323846))
        fail(who + ": perspective.yfov " + fmt(yfov) + " is not in (0, pi)");
    const dvec3 p(world[3]);
    const dmat3 a(world);
    const double det = glm::determinant(a);
    if (!(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)) || !(std::abs(det) > 0.0) || !std::isfinite(det))
        fail(who + ": the node's transform is degenerate (non-finite or zero scale)");
    if (det < 0.0) warn(who, "the node's transform mirrors (negative determinant); the camera is rendered unmirrored");
    const double aspect = double(options_.width) / double(options_.height);
    if (cam.perspective.aspectRatio > 0.0 && std::abs(cam.perspective.aspectRatio - aspect) > 1e-3 * aspect)
        warn(who, "aspectRatio " + fmt(cam.perspective.aspectRatio) + " differs from the image's " + fmt(aspect) +
             "; the vertical field of view is kept");
    scene_.camera = Camera::fromMatrix(Mat4(world), float(yfov), options_.width, options_.height);
    scene_.hasSceneCamera = true;
    cameraNode_ = nodeIndex;
    scene_.info.cameraSource = "scene node " + (node.name.empty() ? std::string() : "'" + node.name + "' ") + "(node " +
                               std::to_string(nodeIndex) + ", camera " + std::to_string(node.camera) +
                               (cam.name.empty() ? std::string() : " '" + cam.name + "'") + ")";
}

void Loader::defaultCamera() {
    const TriangleMesh& m = scene_.mesh;
    dvec3 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
    bool any = false;
    for (const glm::uvec3& t : m.indices)
        for (int k = 0; k < 3; ++k) {
            const dvec3 p(m.positions[t[k]]);
            lo = glm::min(lo, p);
            hi = glm::max(hi, p);
            any = true;
        }
    dvec3 center(0.0);
    double radius = 1.0;
    if (any) {
        center = 0.5 * (lo + hi);
        double r2 = 0.0;
        for (const glm::uvec3& t : m.indices)
            for (int k = 0; k < 3; ++k) {
                const dvec3 d = dvec3(m.positions[t[k]]) - center;
                r2 = std::max(r2, glm::dot(d, d));
            }
        radius = std::sqrt(r2);
        if (!(radius > 0.0)) radius = 1.0;
    }
    const double yfov = 45.0 * 3.14159265358979323846 / 180.0;
    const double aspect = double(options_.width) / double(options_.height);
    const double tanHalfY = std::tan(0.5 * yfov);
    const double halfMin = std::min(0.5 * yfov, std::atan(tanHalfY * aspect));
    const double distance = radius / std::sin(halfMin);
    const Vec3 target(center);
    const Vec3 eye(center + dvec3(0.0, 0.0, distance));
    scene_.camera = Camera::lookAt(eye, target, Vec3(0.f, 1.f, 0.f), float(yfov), options_.width, options_.height);
    scene_.hasSceneCamera = false;
    scene_.info.cameraSource = "default (no camera in the scene)";
}

Scene Loader::load() {
    if (options_.width <= 0 || options_.height <= 0)
        fail("invalid image size " + std::to_string(options_.width) + "x" + std::to_string(options_.height));
    scene_.info.path = path_;
    readAndParse();
    scene_.info.contentHash = hash_.hex();
    checkAsset();
    checkExtensions();
    traverse();
    if (degenerateTriangles_)
        warn(std::to_string(degenerateTriangles_) + " degenerate (zero-area) triangles skipped");
    if (zeroNormals_)
        warn(std::to_string(zeroNormals_) +
             " vertices have a zero-length normal; the geometric normal is used there (vertexHasNormal = 0)");
    if (extraCameraNodes_)
        warn(std::to_string(extraCameraNodes_ + 1) + " camera nodes in the scene; the first in traversal order is used");
    if (cameraNode_ < 0) defaultCamera();
    flushWarnings();
    return std::move(scene_);
}

}  // namespace

Scene loadGltfScene(const std::string& path, const LoadOptions& options) {
    Loader loader(path, options);
    return loader.load();
}

}  // namespace bdptref
