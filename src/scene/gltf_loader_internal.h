// Internal to the glTF loader (src/scene/gltf_*.cpp): the Loader class and the accessor helpers
// its parts share. The loader is split by glTF concept: gltf_read.cpp (reading, the JSON schema
// check, extensions), gltf_accessors.cpp (binary data), gltf_geometry.cpp (node graph and
// meshes), gltf_materials.cpp (materials and textures), gltf_lights.cpp, gltf_cameras.cpp, and
// gltf_loader.cpp (the driver and warnings). The contract is in docs/scenes.md.
#pragma once

#include "bdptref/gltf_loader.h"

#include "bdptref/errors.h"
#include "core/fnv1a64.h"
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
namespace gltfload {

using glm::dmat3;
using glm::dmat4;
using glm::dvec3;
using glm::dvec4;

// Placed triangles a scene may hold (every instance is stored flat; see docs/scenes.md).
constexpr size_t kMaxSceneTriangles = size_t(1) << 26;

// T * R * S from a translation, a unit quaternion (x, y, z, w) and a scale (gltf_geometry.cpp).
dmat4 trsMatrix(const dvec3& t, const double q[4], const dvec3& s);

// Small helpers (gltf_accessors.cpp).
std::string fmt(double v);
std::string lower(std::string s);
bool endsWith(const std::string& s, const std::string& suffix);
bool mulOverflows(size_t a, size_t b, size_t* out);
bool addOverflows(size_t a, size_t b, size_t* out);
size_t componentSize(int componentType);
const char* componentTypeName(int componentType);
int typeComponents(int type);
const char* typeName(int type);
const char* modeName(int mode);
// One component, decoded per the glTF spec (normalized integers map to [0,1] or [-1,1]).
double readComponent(const unsigned char* p, int componentType, bool normalized);

// What the image callback needs besides tinygltf's arguments: the model (for bufferView
// images), a name for each image (tinygltf only has its index at that point) and the scene's
// texel budget so far.
struct ImageLoadContext {
    const tinygltf::Model* model = nullptr;
    std::vector<std::string> labels;  // "image 2 ('wood.png') named 'oak'"
    uint64_t texels = 0;
};

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
    unsigned texCoordSets = 0;  // bit n: a texture of the material reads TEXCOORD_n
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
    // World transform of any node (also joints outside the rendered scene), memoised.
    dmat4 nodeWorld(int nodeIndex);
    // Per-vertex world matrices of a skinned primitive (gltf_skins.cpp): sum_k w_k * world(joint_k)
    // * inverseBind(joint_k); empty when the node has no skin.
    std::vector<dmat4> skinMatrices(int nodeIndex, const tinygltf::Primitive& prim, const std::string& who, size_t vertexCount);
    // EXT_mesh_gpu_instancing: the instances' local matrices T * R * S (gltf_skins.cpp).
    std::vector<dmat4> gpuInstances(int nodeIndex, const tinygltf::Value& ext);
    // Runs one independent part of the file (a node, a material); an InputError it throws is
    // recorded and loading goes on, so one run reports every problem (thrown together at the end).
    template <class F>
    void attempt(F&& f) {
        try {
            f();
        } catch (const InputError& e) {
            std::string what = e.what();
            const std::string prefix = path_ + ": ";
            if (what.compare(0, prefix.size(), prefix) == 0) what = what.substr(prefix.size());
            if (std::find(errors_.begin(), errors_.end(), what) == errors_.end()) errors_.push_back(what);
        }
    }
    void throwCollectedErrors() const;
    // Records a rendered feature for `bdptref info` (SceneInfo::featuresUsed), once.
    void useFeature(const std::string& feature) {
        auto& v = scene_.info.featuresUsed;
        if (std::find(v.begin(), v.end(), feature) == v.end()) v.push_back(feature);
    }
    void addLight(int nodeIndex, const tinygltf::Value& ext, const dmat4& world);
    void addCamera(int nodeIndex, const dmat4& world);
    void defaultCamera();
    int chooseCamera();      // index into info.cameras, -1 for none
    void resolveCameras();   // after the traversal: the camera to render, problems of the others
    void imageSize(double aspect, const std::string& who, const std::string& what, int* width, int* height);

    const tinygltf::Accessor& accessor(int index, const std::string& who) const;
    DecodedAccessor decode(int index, const std::string& who, const std::vector<int>& types,
                           const std::vector<AccessorFormat>& formats) const;
    const unsigned char* viewBytes(int viewIndex, const std::string& who, size_t* length, size_t* stride) const;

    MaterialUse material(int gltfIndex);
    Material convertMaterial(int gltfIndex, unsigned* texCoordSets);
    // KHR_materials_volume of material `who` into m->absorption (transmissive: it has KHR_materials_transmission).
    void volume(const std::string& who, const tinygltf::Value& ext, bool transmissive, Material* m);
    // A material's texture slot: the scene texture (decoded once per texture and colour space), its
    // TEXCOORD set (recorded in *texCoordSets) and transform.
    TextureRef textureRef(const std::string& who, int index, int texCoord, const tinygltf::ExtensionMap& extensions, bool srgb,
                          unsigned* texCoordSets);
    void textureTransform(const std::string& who, const tinygltf::Value& ext, TextureRef* ref, int* texCoord) const;
    int texture(const std::string& who, int index, bool srgb);
    void addTangents(const std::string& who, const tinygltf::Primitive& prim, const MaterialUse& mat, const DecodedAccessor* nrm,
                     const DecodedAccessor& pos, const int* uvIndex, const DecodedAccessor* uv, const std::vector<glm::uvec3>& tris,
                     const dmat3& linear, double det, size_t base, const std::vector<dmat4>* skin = nullptr);
    const Texture& image(const std::string& who, int source);
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
    std::vector<std::string> errors_;             // every problem found so far (see attempt)
    std::vector<int> parent_;                     // node graph (a forest), -1 for roots
    std::map<int, dmat4> nodeWorld_;              // memo of nodeWorld
    std::set<std::pair<int, std::vector<double>>> placedMeshes_;  // (mesh, world matrix): coincident copies are merged
    size_t mergedCopies_ = 0;
    std::vector<dmat4> cameraWorlds_;  // parallel to scene_.info.cameras
    std::map<int, Texture> images_;  // decoded image data by glTF image index (shared by textures)
    size_t degenerateTriangles_ = 0;
    size_t zeroNormals_ = 0;
    std::vector<std::pair<std::string, std::vector<std::string>>> warnings_;  // what -> who, in first-seen order
};

}  // namespace gltfload
}  // namespace bdptref
