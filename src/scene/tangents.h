// Vertex tangents for normal mapping, generated the way the glTF specification asks for when a
// primitive has no TANGENT attribute (MikkTSpace-equivalent; what is implemented and where it may
// differ from the reference MikkTSpace: docs/materials.md, "Normal maps").
#pragma once

#include "bdptref/math.h"

#include <vector>

namespace bdptref {

// Tangents of one primitive, parallel to `positions`, in glTF TANGENT form: xyz unit and
// orthogonal to the vertex normal, w = +-1 with bitangent B = w * cross(N, T) (B points "up" in
// the image, i.e. towards decreasing glTF v). `normals[i]` may be the zero vector (the primitive
// has no NORMAL): such a corner uses its face normal. `triangles` index `positions`.
std::vector<Vec4> generateTangents(const std::vector<Vec3>& positions, const std::vector<Vec3>& normals,
                                   const std::vector<Vec2>& uvs, const std::vector<glm::uvec3>& triangles);

}  // namespace bdptref
