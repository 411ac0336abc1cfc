// Reading a glTF file: file access confined to the scene directory (and hashed), checked image
// decoding, the JSON schema subset tinygltf does not check, the asset version and extensions.

#include "scene/gltf_loader_internal.h"

namespace bdptref {
namespace gltfload {
namespace {


const char* const kSupportedExtensions[] = {
    "KHR_lights_punctual",        "KHR_materials_emissive_strength", "KHR_materials_ior",
    "KHR_materials_transmission", "KHR_materials_specular",      "KHR_materials_volume",
    "KHR_materials_clearcoat",    "KHR_materials_sheen",
    "EXT_mesh_gpu_instancing",
    "KHR_texture_transform",
};

std::string supportedExtensionList() {
    std::string s;
    for (const char* e : kSupportedExtensions) s += (s.empty() ? "" : ", ") + std::string(e);
    return s;
}

bool isSupportedExtension(const std::string& name) {
    for (const char* s : kSupportedExtensions)
        if (name == s) return true;
    return false;
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
    // The file's channel count, not forced RGBA (texels are kept as decoded: a third less memory for
    // RGB). tinygltf reads this option through its user pointer as its LoadImageDataOption, a struct
    // of one bool that the installed header only declares inside the library's implementation
    // section; this has the same first member, and zeroed room in case later versions add fields.
    struct KeepChannels {
        bool preserveChannels = true;
        unsigned char reserved[63] = {};
    } keepChannels;
    const bool ok = tinygltf::LoadImageData(image, imageIndex, &decodeErr, warn, reqWidth, reqHeight, bytes, size, &keepChannels);
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
                if (const Json* x = member(*e, "KHR_materials_volume", Object, ep)) {
                    const std::string xp = ep + ".KHR_materials_volume";
                    for (const char* k : {"thicknessFactor", "attenuationDistance"}) member(*x, k, Number, xp);
                    numbers(*x, "attenuationColor", 3, xp);
                    textureInfo(*x, "thicknessTexture", xp);
                }
                if (const Json* x = member(*e, "KHR_materials_sheen", Object, ep)) {
                    const std::string xp = ep + ".KHR_materials_sheen";
                    numbers(*x, "sheenColorFactor", 3, xp);
                    member(*x, "sheenRoughnessFactor", Number, xp);
                    for (const char* k : {"sheenColorTexture", "sheenRoughnessTexture"}) textureInfo(*x, k, xp);
                }
                if (const Json* x = member(*e, "KHR_materials_clearcoat", Object, ep)) {
                    const std::string xp = ep + ".KHR_materials_clearcoat";
                    for (const char* k : {"clearcoatFactor", "clearcoatRoughnessFactor"}) member(*x, k, Number, xp);
                    for (const char* k : {"clearcoatTexture", "clearcoatRoughnessTexture", "clearcoatNormalTexture"})
                        textureInfo(*x, k, xp);
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


}  // namespace

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
            attempt([&] {
                fail("extension '" + r + "' is required by the file but not implemented (supported: " + supportedExtensionList() +
                     ")");
            });

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
            scene_.info.ignoredFeatures.push_back("extension " + u);
            warn("extension '" + u + "' is not implemented and not required: ignored (the file's core glTF data is rendered)");
        }
}


}  // namespace gltfload
}  // namespace bdptref
