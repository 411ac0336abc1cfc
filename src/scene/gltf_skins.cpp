// Skinned meshes in the file's rest pose and EXT_mesh_gpu_instancing: both turn into plain
// world-space triangles here (docs/scenes.md, "Skins and instancing").

#include "scene/gltf_loader_internal.h"

namespace bdptref {
namespace gltfload {

namespace {

const AccessorFormat kF32{TINYGLTF_COMPONENT_TYPE_FLOAT, false};
const AccessorFormat kU8{TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, false};
const AccessorFormat kU16{TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, false};
const AccessorFormat kU8n{TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, true};
const AccessorFormat kU16n{TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, true};
const AccessorFormat kS8n{TINYGLTF_COMPONENT_TYPE_BYTE, true};
const AccessorFormat kS16n{TINYGLTF_COMPONENT_TYPE_SHORT, true};

}  // namespace

std::vector<dmat4> Loader::skinMatrices(int nodeIndex, const tinygltf::Primitive& prim, const std::string& who, size_t nv) {
    const tinygltf::Node& node = model_.nodes[size_t(nodeIndex)];
    if (node.skin == -1) return {};
    const std::string sw = "node " + std::to_string(nodeIndex) + ": skin " + std::to_string(node.skin);
    if (node.skin < 0 || size_t(node.skin) >= model_.skins.size())
        fail(sw + " does not exist (the file has " + std::to_string(model_.skins.size()) + " skins)");
    const tinygltf::Skin& skin = model_.skins[size_t(node.skin)];
    if (skin.joints.empty()) fail(sw + " has no joints");

    // Joint matrices: world(joint) * inverseBindMatrix (identity when the file gives none).
    std::vector<dmat4> joint(skin.joints.size(), dmat4(1.0));
    DecodedAccessor ibm;
    if (skin.inverseBindMatrices >= 0 || skin.inverseBindMatrices < -1) {
        ibm = decode(skin.inverseBindMatrices, sw + ": accessor " + std::to_string(skin.inverseBindMatrices) + " (inverseBindMatrices)",
                     {TINYGLTF_TYPE_MAT4}, {kF32});
        if (ibm.count < skin.joints.size())
            fail(sw + ": inverseBindMatrices has " + std::to_string(ibm.count) + " matrices for " +
                 std::to_string(skin.joints.size()) + " joints");
    }
    for (size_t j = 0; j < skin.joints.size(); ++j) {
        const int jn = skin.joints[j];
        if (jn < 0 || size_t(jn) >= model_.nodes.size()) fail(sw + ": joint " + std::to_string(jn) + " is not a node");
        dmat4 inv(1.0);
        if (ibm.count)
            for (int c = 0; c < 4; ++c)
                for (int r = 0; r < 4; ++r) inv[c][r] = ibm.at(j, c * 4 + r);
        joint[j] = nodeWorld(jn) * inv;
    }

    // Vertex matrices: the weighted sum over every JOINTS_n / WEIGHTS_n set.
    std::vector<dmat4> out(nv, dmat4(0.0));
    std::vector<double> weightSum(nv, 0.0);
    int sets = 0;
    for (int s = 0;; ++s) {
        const auto ji = prim.attributes.find("JOINTS_" + std::to_string(s));
        const auto wi = prim.attributes.find("WEIGHTS_" + std::to_string(s));
        if (ji == prim.attributes.end() && wi == prim.attributes.end()) break;
        if (ji == prim.attributes.end() || wi == prim.attributes.end())
            fail(who + ": JOINTS_" + std::to_string(s) + " and WEIGHTS_" + std::to_string(s) + " must come together");
        const std::string jname = who + ": accessor " + std::to_string(ji->second) + " (JOINTS_" + std::to_string(s) + ")";
        const std::string wname = who + ": accessor " + std::to_string(wi->second) + " (WEIGHTS_" + std::to_string(s) + ")";
        const DecodedAccessor js = decode(ji->second, jname, {TINYGLTF_TYPE_VEC4}, {kU8, kU16});
        const DecodedAccessor ws = decode(wi->second, wname, {TINYGLTF_TYPE_VEC4}, {kF32, kU8n, kU16n});
        if (js.count != nv || ws.count != nv)
            fail(who + ": JOINTS_" + std::to_string(s) + "/WEIGHTS_" + std::to_string(s) + " count differs from POSITION's " +
                 std::to_string(nv));
        for (size_t i = 0; i < nv; ++i)
            for (int k = 0; k < 4; ++k) {
                const double w = ws.at(i, k);
                if (!(w >= 0.0) || !std::isfinite(w)) fail(wname + ": weight " + fmt(w) + " at vertex " + std::to_string(i) + " is invalid");
                if (w == 0.0) continue;
                const double j = js.at(i, k);
                if (j >= double(joint.size()))
                    fail(jname + ": joint " + fmt(j) + " at vertex " + std::to_string(i) + " is out of range (the skin has " +
                         std::to_string(joint.size()) + " joints)");
                out[i] += joint[size_t(j)] * w;
                weightSum[i] += w;
            }
        ++sets;
    }
    if (sets == 0) fail(who + ": the node has skin " + std::to_string(node.skin) + " but the primitive has no JOINTS_0/WEIGHTS_0");
    // Weights must sum to 1 (spec); quantised weights miss by a rounding step, so renormalise, and
    // refuse only a vertex no joint moves.
    size_t renormalised = 0;
    for (size_t i = 0; i < nv; ++i) {
        if (!(weightSum[i] > 0.0)) fail(who + ": vertex " + std::to_string(i) + " has skin weights summing to 0");
        if (std::abs(weightSum[i] - 1.0) > 1e-2) ++renormalised;
        out[i] = out[i] * (1.0 / weightSum[i]);
    }
    if (renormalised)
        warn(who, std::to_string(renormalised) + " vertices' skin weights do not sum to 1; renormalised");
    useFeature("skins (rest pose)");
    warn(who, "skinned mesh posed by its joints' node transforms (the file's rest pose; animations are not evaluated)");
    return out;
}

std::vector<dmat4> Loader::gpuInstances(int nodeIndex, const tinygltf::Value& ext) {
    const std::string who = "node " + std::to_string(nodeIndex) + ": EXT_mesh_gpu_instancing";
    if (!ext.IsObject() || !ext.Has("attributes") || !ext.Get("attributes").IsObject()) fail(who + " has no 'attributes' object");
    const tinygltf::Value& attrs = ext.Get("attributes");
    DecodedAccessor t, r, s;
    size_t count = 0;
    bool any = false;
    auto get = [&](const char* name, int type, const std::vector<AccessorFormat>& formats, DecodedAccessor* out) {
        if (!attrs.Has(name)) return;
        const tinygltf::Value& v = attrs.Get(name);
        if (!v.IsInt()) fail(who + ": attributes." + name + " must be an accessor index");
        *out = decode(v.Get<int>(), who + " accessor " + std::to_string(v.Get<int>()) + " (" + name + ")", {type}, formats);
        if (any && out->count != count)
            fail(who + ": attributes." + name + " has " + std::to_string(out->count) + " instances, another attribute " +
                 std::to_string(count));
        count = out->count;
        any = true;
    };
    get("TRANSLATION", TINYGLTF_TYPE_VEC3, {kF32}, &t);
    get("ROTATION", TINYGLTF_TYPE_VEC4, {kF32, kS8n, kS16n}, &r);
    get("SCALE", TINYGLTF_TYPE_VEC3, {kF32}, &s);
    if (!any) fail(who + " has none of TRANSLATION, ROTATION, SCALE");
    std::vector<dmat4> out;
    out.reserve(count);
    for (size_t i = 0; i < count; ++i) {
        dvec3 tr(0.0), sc(1.0);
        double q[4] = {0.0, 0.0, 0.0, 1.0};
        if (t.count) tr = dvec3(t.at(i, 0), t.at(i, 1), t.at(i, 2));
        if (s.count) sc = dvec3(s.at(i, 0), s.at(i, 1), s.at(i, 2));
        if (r.count) {
            double len = 0.0;
            for (int k = 0; k < 4; ++k) len += r.at(i, k) * r.at(i, k);
            len = std::sqrt(len);
            if (!(std::abs(len - 1.0) <= 1e-2))
                fail(who + ": instance " + std::to_string(i) + "'s rotation is not a unit quaternion (length " + fmt(len) + ")");
            for (int k = 0; k < 4; ++k) q[k] = r.at(i, k) / len;
        }
        for (double v : {tr.x, tr.y, tr.z, sc.x, sc.y, sc.z})
            if (!std::isfinite(v)) fail(who + ": instance " + std::to_string(i) + " has a non-finite translation or scale");
        out.push_back(trsMatrix(tr, q, sc));
    }
    return out;
}

}  // namespace gltfload
}  // namespace bdptref
