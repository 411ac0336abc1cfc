// The node graph and the meshes: node transforms, primitives, indices, morph targets at their
// default weights, and the transform into world space.

#include "scene/gltf_loader_internal.h"
#include "scene/tangents.h"

namespace bdptref {
namespace gltfload {

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
    return trsMatrix(t, q, s);
}

dmat4 trsMatrix(const dvec3& t, const double q[4], const dvec3& s) {
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
    parent_ = parent;

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
    // A node with a problem is recorded (attempt) and its subtree skipped; the others go on, so
    // one run reports every node's problems.
    std::vector<int> stack(roots.rbegin(), roots.rend());
    while (!stack.empty()) {
        const int node = stack.back();
        stack.pop_back();
        bool ok = false;
        attempt([&] {
            visitNode(node, nodeWorld(node));
            ok = true;
        });
        if (!ok) continue;
        const auto& ch = model_.nodes[size_t(node)].children;
        for (auto it = ch.rbegin(); it != ch.rend(); ++it) stack.push_back(*it);
    }
    if (mergedCopies_)
        warn(std::to_string(mergedCopies_) + " mesh copies placed exactly where an identical copy already is were merged into "
             "one (coincident identical surfaces render the same as one)");
}

dmat4 Loader::nodeWorld(int nodeIndex) {
    // Walk up to the nearest memoised ancestor (or a root), then down, memoising on the way.
    std::vector<int> chain;
    for (int x = nodeIndex; x >= 0 && !nodeWorld_.count(x); x = parent_.empty() ? -1 : parent_[size_t(x)]) chain.push_back(x);
    for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
        const int p = parent_.empty() ? -1 : parent_[size_t(*it)];
        nodeWorld_[*it] = (p >= 0 ? nodeWorld_.at(p) : dmat4(1.0)) * localTransform(*it);
    }
    return nodeWorld_.at(nodeIndex);
}

void Loader::visitNode(int nodeIndex, const dmat4& world) {
    const tinygltf::Node& node = model_.nodes[size_t(nodeIndex)];
    if (node.camera >= 0 || node.camera < -1) addCamera(nodeIndex, world);
    auto lightExt = node.extensions.find("KHR_lights_punctual");
    if (lightExt != node.extensions.end()) addLight(nodeIndex, lightExt->second, world);
    if (node.mesh >= 0 || node.mesh < -1) {
        auto inst = node.extensions.find("EXT_mesh_gpu_instancing");
        if (inst != node.extensions.end()) {
            if (node.skin >= 0)
                fail("node " + std::to_string(nodeIndex) + ": EXT_mesh_gpu_instancing on a skinned mesh is not supported");
            useFeature("EXT_mesh_gpu_instancing");
            for (const dmat4& local : gpuInstances(nodeIndex, inst->second)) addMesh(nodeIndex, node.mesh, world * local);
        } else {
            addMesh(nodeIndex, node.mesh, world);
        }
    } else if (node.skin >= 0 || node.skin < -1) {
        warn("node " + std::to_string(nodeIndex), "skin without a mesh ignored");
    }
}

// ----- geometry

void Loader::addMesh(int nodeIndex, int meshIndex, const dmat4& world) {
    if (meshIndex < 0 || size_t(meshIndex) >= model_.meshes.size())
        fail("node " + std::to_string(nodeIndex) + ": mesh " + std::to_string(meshIndex) + " does not exist (the file has " +
             std::to_string(model_.meshes.size()) + " meshes)");
    const tinygltf::Mesh& mesh = model_.meshes[size_t(meshIndex)];
    // The same mesh placed twice with the same matrix (e.g. a million coincident instances) is one
    // surface: later copies add nothing to the picture but would make every ray test them all.
    // (A skinned mesh ignores its node's matrix, so copies of it are never merged.)
    if (model_.nodes[size_t(nodeIndex)].skin < 0) {
        std::vector<double> key(&world[0][0], &world[0][0] + 16);
        if (!placedMeshes_.insert({meshIndex, std::move(key)}).second) {
            ++mergedCopies_;
            return;
        }
    }
    for (size_t p = 0; p < mesh.primitives.size(); ++p) addPrimitive(nodeIndex, meshIndex, int(p), world);
    if (scene_.mesh.indices.size() > kMaxSceneTriangles)
        fail("node " + std::to_string(nodeIndex) + ": the scene has more than " + std::to_string(kMaxSceneTriangles) +
             " triangles after placing mesh " + std::to_string(meshIndex) + " (instancing multiplies triangles; this renderer "
             "stores every placed triangle)");
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
    int uvIndex[kMaxTexCoordSets];
    for (int s = 0; s < kMaxTexCoordSets; ++s) uvIndex[s] = findAttr(("TEXCOORD_" + std::to_string(s)).c_str());
    const int colIndex = findAttr("COLOR_0");

    const AccessorFormat f32{TINYGLTF_COMPONENT_TYPE_FLOAT, false};
    const AccessorFormat u8n{TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, true};
    const AccessorFormat u16n{TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, true};
    const AccessorFormat s8n{TINYGLTF_COMPONENT_TYPE_BYTE, true};
    const AccessorFormat s16n{TINYGLTF_COMPONENT_TYPE_SHORT, true};

    DecodedAccessor pos = decode(posIndex, accName(posIndex, "POSITION"), {TINYGLTF_TYPE_VEC3}, {f32});
    const size_t nv = pos.count;
    DecodedAccessor nrm, uv[kMaxTexCoordSets], col;
    if (nrmIndex != -2) nrm = decode(nrmIndex, accName(nrmIndex, "NORMAL"), {TINYGLTF_TYPE_VEC3}, {f32});
    if (nrmIndex != -2 && nrm.count != nv)
        fail(accName(nrmIndex, "NORMAL") + " has count " + std::to_string(nrm.count) + " but POSITION has " + std::to_string(nv));
    const std::string uvName[kMaxTexCoordSets] = {"TEXCOORD_0", "TEXCOORD_1", "TEXCOORD_2", "TEXCOORD_3"};
    for (int s = 0; s < kMaxTexCoordSets; ++s) {
        if (uvIndex[s] == -2) continue;
        uv[s] = decode(uvIndex[s], accName(uvIndex[s], uvName[s].c_str()), {TINYGLTF_TYPE_VEC2}, {f32, u8n, u16n});
        if (uv[s].count != nv)
            fail(accName(uvIndex[s], uvName[s].c_str()) + " has count " + std::to_string(uv[s].count) + " but POSITION has " +
                 std::to_string(nv));
    }
    // COLOR_0 multiplies the base colour (RGB) and the coverage alpha (A) of the material.
    for (int s = 1; s < kMaxTexCoordSets; ++s)
        if (uvIndex[s] != -2) useFeature(uvName[s]);
    if (colIndex != -2) {
        useFeature("COLOR_0");
        col = decode(colIndex, accName(colIndex, "COLOR_0"), {TINYGLTF_TYPE_VEC3, TINYGLTF_TYPE_VEC4}, {f32, u8n, u16n});
        if (col.count != nv)
            fail(accName(colIndex, "COLOR_0") + " has count " + std::to_string(col.count) + " but POSITION has " + std::to_string(nv));
        for (size_t i = 0; i < col.values.size(); ++i)
            if (!(col.values[i] >= 0.0 && col.values[i] <= 1.0))
                fail(accName(colIndex, "COLOR_0") + ": value " + fmt(col.values[i]) + " at vertex " +
                     std::to_string(i / size_t(col.components)) + " is outside [0, 1]");
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
            useFeature("morph targets (default weights)");
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
                    } else if (attr.first.compare(0, 9, "TEXCOORD_") == 0 && attr.first.size() == 10 &&
                               attr.first[9] >= '0' && attr.first[9] < char('0' + kMaxTexCoordSets) &&
                               uvIndex[attr.first[9] - '0'] != -2) {
                        delta = decode(attr.second, an, {TINYGLTF_TYPE_VEC2}, {f32, s8n, s16n, u8n, u16n});
                        dst = &uv[attr.first[9] - '0'];
                    } else {
                        if (attr.first == "TANGENT" && findAttr("TANGENT") != -2)
                            warn(who, "TANGENT morph target ignored (the base TANGENT attribute is used unmorphed)");
                        continue;  // not used by this renderer
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
        for (int s = 0; s < kMaxTexCoordSets; ++s)
            if ((mat.texCoordSets >> unsigned(s)) & 1u && uvIndex[s] == -2)
                fail(who + ": material " + std::to_string(prim.material) + " uses a texture with texCoord " + std::to_string(s) +
                     " but the primitive has no " + uvName[s]);
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
    // A skinned primitive has a matrix per vertex (the node's own matrix is ignored, per the spec).
    const std::vector<dmat4> skin = skinMatrices(nodeIndex, prim, who, nv);
    auto cofactor = [](const dmat4& m, double* determinant) {
        const dmat3 a(m);
        *determinant = glm::determinant(a);
        const dmat3 c(glm::cross(a[1], a[2]), glm::cross(a[2], a[0]), glm::cross(a[0], a[1]));
        return *determinant < 0.0 ? -c : c;
    };
    double det = 0.0;
    const dmat3 nodeNormalMatrix = cofactor(world, &det);
    std::vector<uint8_t> mirrored;  // skinned: per vertex, whether its matrix mirrors

    TriangleMesh& out = scene_.mesh;
    const size_t base = out.positions.size();
    if (base + nv > size_t(std::numeric_limits<uint32_t>::max()))
        fail(who + ": the scene has more vertices than this renderer supports (2^32 - 1)");
    out.positions.reserve(base + nv);
    out.normals.reserve(base + nv);
    // Attribute arrays stay parallel to positions: a set first seen here is zero for earlier
    // vertices (their materials do not read it); COLOR_0 is 1 where a primitive lacks it.
    for (int s = 0; s < kMaxTexCoordSets; ++s)
        if (uvIndex[s] != -2 && out.uvSets.size() <= size_t(s)) out.uvSets.resize(size_t(s) + 1);
    for (std::vector<Vec2>& set : out.uvSets) {
        set.resize(base, Vec2(0.f));
        set.reserve(base + nv);
    }
    const bool withColors = colIndex != -2 || !out.colors.empty();
    if (withColors) {
        out.colors.resize(base, Vec4(1.f));
        out.colors.reserve(base + nv);
    }
    out.vertexHasNormal.reserve(base + nv);
    for (size_t i = 0; i < nv; ++i) {
        const dvec3 p(pos.at(i, 0), pos.at(i, 1), pos.at(i, 2));
        if (!(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)))
            fail(accName(posIndex, "POSITION") + ": vertex " + std::to_string(i) + " is not finite (NaN or infinity)");
        dmat3 normalMatrix = nodeNormalMatrix;
        const dmat4& vertexWorld = skin.empty() ? world : skin[i];
        if (!skin.empty()) {
            double d = 0.0;
            normalMatrix = cofactor(vertexWorld, &d);
            mirrored.push_back(d < 0.0 ? 1 : 0);
        }
        const dvec3 wp = dvec3(vertexWorld * dvec4(p, 1.0));
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

        for (size_t s = 0; s < out.uvSets.size(); ++s) {
            Vec2 t(0.f);
            if (uvIndex[s] != -2) {
                t = Vec2(float(uv[s].at(i, 0)), float(uv[s].at(i, 1)));
                if (!(std::isfinite(t.x) && std::isfinite(t.y)))
                    fail(accName(uvIndex[s], uvName[s].c_str()) + ": vertex " + std::to_string(i) + " is not finite");
            }
            out.uvSets[s].push_back(t);
        }
        if (withColors) {
            Vec4 c(1.f);
            if (colIndex != -2)
                for (int k = 0; k < col.components; ++k) c[k] = float(col.at(i, k));
            out.colors.push_back(c);
        }
    }

    addTangents(who, prim, mat, nrmIndex != -2 ? &nrm : nullptr, pos, uvIndex, uv, tris, dmat3(world), det, base, &skin);

    for (glm::uvec3 t : tris) {
        // A mirroring transform would turn front faces into back faces.
        if (skin.empty() ? det < 0.0 : mirrored[t.x] != 0) std::swap(t.y, t.z);
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

// Vertex tangents for a primitive whose material has a normal texture or a clearcoat normal texture
// (docs/materials.md, "Normal maps"): the TANGENT attribute when the primitive has it and NORMAL (the spec ignores
// tangents without normals), else generated (src/scene/tangents.cpp) from the object-space
// positions, normals and the normal texture's TEXCOORD set. Tangents are directions on the
// surface: transformed by the node's linear part; a mirroring transform flips the handedness.
void Loader::addTangents(const std::string& who, const tinygltf::Primitive& prim, const MaterialUse& mat,
                         const DecodedAccessor* nrm, const DecodedAccessor& pos, const int* uvIndex, const DecodedAccessor* uv,
                         const std::vector<glm::uvec3>& tris, const dmat3& linear, double det, size_t base,
                         const std::vector<dmat4>* skin) {
    TriangleMesh& out = scene_.mesh;
    // The normal maps share one tangent frame (the loader refuses two TEXCOORD sets for them).
    const Material& material = scene_.materials[size_t(mat.sceneIndex)];
    const TextureRef& ref = material.normalTexture.valid() || material.clearcoat <= 0.f ? material.normalTexture
                                                                                      : material.clearcoatNormalTexture;
    const size_t nv = pos.count;
    if (!ref.valid()) {
        if (!out.tangents.empty()) out.tangents.resize(base + nv, Vec4(0.f));
        return;
    }
    std::vector<Vec4> local(nv);
    auto it = prim.attributes.find("TANGENT");
    if (it != prim.attributes.end() && nrm) {
        const std::string an = who + ": accessor " + std::to_string(it->second) + " (TANGENT)";
        const DecodedAccessor t = decode(it->second, an, {TINYGLTF_TYPE_VEC4}, {{TINYGLTF_COMPONENT_TYPE_FLOAT, false}});
        if (t.count != nv) fail(an + " has count " + std::to_string(t.count) + " but POSITION has " + std::to_string(nv));
        for (size_t i = 0; i < nv; ++i) {
            const Vec4 v(float(t.at(i, 0)), float(t.at(i, 1)), float(t.at(i, 2)), float(t.at(i, 3)));
            if (!(isFinite(Vec3(v)) && std::isfinite(v.w))) fail(an + ": vertex " + std::to_string(i) + " is not finite");
            local[i] = Vec4(Vec3(v), v.w < 0.f ? -1.f : 1.f);
        }
    } else {
        if (uvIndex[ref.texCoord] == -2) return;  // reported by the caller's texCoord check
        std::vector<Vec3> p(nv), n(nv, Vec3(0.f));
        std::vector<Vec2> t(nv);
        for (size_t i = 0; i < nv; ++i) {
            p[i] = Vec3(float(pos.at(i, 0)), float(pos.at(i, 1)), float(pos.at(i, 2)));
            if (nrm) {
                const Vec3 v(float(nrm->at(i, 0)), float(nrm->at(i, 1)), float(nrm->at(i, 2)));
                const float len = glm::length(v);
                if (len > 0.f && std::isfinite(len)) n[i] = v / len;
            }
            t[i] = Vec2(float(uv[ref.texCoord].at(i, 0)), float(uv[ref.texCoord].at(i, 1)));
        }
        local = generateTangents(p, n, t, tris);
    }
    out.tangents.resize(base, Vec4(0.f));
    out.tangents.reserve(base + nv);
    for (size_t i = 0; i < local.size(); ++i) {
        const Vec4& v = local[i];
        // A skinned vertex has its own matrix (and may mirror on its own).
        const dmat3 m = skin && !skin->empty() ? dmat3((*skin)[i]) : linear;
        const double d = skin && !skin->empty() ? glm::determinant(m) : det;
        const dvec3 w = m * dvec3(Vec3(v));
        const double len = glm::length(w);
        const Vec3 dir = len > 0.0 && std::isfinite(len) ? Vec3(w / len) : Vec3(0.f);
        out.tangents.emplace_back(dir, d < 0.0 ? -v.w : v.w);
    }
}

}  // namespace gltfload
}  // namespace bdptref
