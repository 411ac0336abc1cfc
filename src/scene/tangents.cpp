// MikkTSpace-equivalent tangent generation (docs/materials.md, "Normal maps", "Generated
// tangents"): per-corner tangent from the uv derivatives, projected onto the corner's normal
// plane, summed with the corner's angle as weight over the corners that share position, normal,
// uv and uv orientation, orthogonalised and normalised.
#include "scene/tangents.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <map>

namespace bdptref {

namespace {

using dvec2 = glm::dvec2;
using dvec3 = glm::dvec3;

uint32_t bitsOf(float f) {
    if (f == 0.f) f = 0.f;  // -0 and +0 weld, as equal values
    uint32_t u;
    std::memcpy(&u, &f, 4);
    return u;
}

// Vertices weld by exact value (as MikkTSpace does): position, normal, uv, orientation.
using Key = std::array<uint32_t, 9>;

struct Group {
    dvec3 sum{0.0};
    dvec3 normal{0.0};
    double weight = 0.0;
    bool orient = false;  // uv orientation positive (det > 0 in glTF uv)
};

// v minus its component along the unit vector n, normalised; false when that is zero or not finite.
bool projectNormalised(const dvec3& v, const dvec3& n, dvec3* out) {
    const dvec3 p = v - n * glm::dot(n, v);
    const double len = glm::length(p);
    if (!(len > 0.0) || !std::isfinite(len)) return false;
    *out = p / len;
    return true;
}

}  // namespace

std::vector<Vec4> generateTangents(const std::vector<Vec3>& positions, const std::vector<Vec3>& normals,
                                   const std::vector<Vec2>& uvs, const std::vector<glm::uvec3>& triangles) {
    const size_t nv = positions.size();
    std::map<Key, size_t> groupOf;
    std::vector<Group> groups;
    std::vector<std::vector<uint32_t>> vertexGroups(nv);

    for (const glm::uvec3& tri : triangles) {
        const dvec3 p[3] = {dvec3(positions[tri.x]), dvec3(positions[tri.y]), dvec3(positions[tri.z])};
        const dvec2 t[3] = {dvec2(uvs[tri.x]), dvec2(uvs[tri.y]), dvec2(uvs[tri.z])};
        const dvec3 e1 = p[1] - p[0], e2 = p[2] - p[0];
        const dvec2 d1 = t[1] - t[0], d2 = t[2] - t[0];
        const double det = d1.x * d2.y - d2.x * d1.y;  // twice the signed uv area
        const dvec3 c = glm::cross(e1, e2);
        const double clen = glm::length(c);
        // Degenerate in uv or in space: the triangle contributes nothing (its vertices take their
        // tangents from the other triangles that share them).
        if (!(det != 0.0) || !std::isfinite(det) || !(clen > 0.0) || !std::isfinite(clen)) continue;
        const dvec3 faceNormal = c / clen;
        // dp/du up to a positive factor: (d2.y e1 - d1.y e2) / det.
        const dvec3 dpdu = (d2.y * e1 - d1.y * e2) * (det > 0.0 ? 1.0 : -1.0);
        const bool orient = det > 0.0;
        const uint32_t idx[3] = {tri.x, tri.y, tri.z};
        for (int k = 0; k < 3; ++k) {
            const uint32_t v = idx[k];
            const Vec3 nf = normals[v] != Vec3(0.f) ? normals[v] : Vec3(faceNormal);
            const dvec3 n = glm::normalize(dvec3(nf));
            dvec3 tangent, a, b;
            if (!projectNormalised(dpdu, n, &tangent)) continue;
            // The corner's angle, measured between its edges projected onto the normal's plane.
            if (!projectNormalised(p[(k + 1) % 3] - p[k], n, &a) || !projectNormalised(p[(k + 2) % 3] - p[k], n, &b)) continue;
            const double angle = std::acos(std::clamp(glm::dot(a, b), -1.0, 1.0));
            const Vec3& pos = positions[v];
            const Key key = {bitsOf(pos.x), bitsOf(pos.y), bitsOf(pos.z), bitsOf(nf.x), bitsOf(nf.y), bitsOf(nf.z),
                             bitsOf(uvs[v].x), bitsOf(uvs[v].y), orient ? 1u : 0u};
            auto [it, inserted] = groupOf.emplace(key, groups.size());
            if (inserted) {
                Group g;
                g.normal = n;
                g.orient = orient;
                groups.push_back(g);
            }
            Group& g = groups[it->second];
            g.sum += angle * tangent;
            g.weight += angle;
            std::vector<uint32_t>& vg = vertexGroups[v];
            if (std::find(vg.begin(), vg.end(), uint32_t(it->second)) == vg.end()) vg.push_back(uint32_t(it->second));
        }
    }

    std::vector<Vec4> out(nv);
    for (size_t v = 0; v < nv; ++v) {
        // One tangent per vertex: where the corners of a vertex fall into several groups (a uv
        // mirror seam through a shared vertex, or face normals of a primitive without NORMAL), the
        // group with the largest angle sum wins; MikkTSpace would split the vertex instead.
        const Group* best = nullptr;
        for (uint32_t g : vertexGroups[v])
            if (!best || groups[g].weight > best->weight) best = &groups[g];
        dvec3 tangent;
        if (best && best->weight > 0.0 && projectNormalised(best->sum, best->normal, &tangent)) {
            // glTF's v runs down the image while the map's +Y is up: the sign is MikkTSpace's
            // (+1 for a positive uv orientation) negated.
            out[v] = Vec4(Vec3(tangent), best->orient ? -1.f : 1.f);
        } else {
            // No usable triangle: any unit vector orthogonal to the normal.
            const Vec3 n = normals[v] != Vec3(0.f) ? glm::normalize(normals[v]) : Vec3(0.f, 0.f, 1.f);
            out[v] = Vec4(Frame(n).s, 1.f);
        }
    }
    return out;
}

}  // namespace bdptref
