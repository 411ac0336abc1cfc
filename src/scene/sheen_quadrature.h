// The part of the sheen lobe (src/scene/bsdf_sheen.cpp) that the albedo table is computed from:
// the Charlie D and Lambda, the table's nodes and the quadrature of E at a node. It needs only glm
// and <cmath>, because it is compiled twice: into the library (so tests can run the quadrature) and
// into bdptref_sheen_table_gen (tools/sheen_table_gen.cpp), which writes the table at build time.
// docs/materials.md, "Sheen".
#pragma once

#include <glm/vec3.hpp>

namespace bdptref {
namespace bsdf_detail {

// Smallest sheen roughness used (sheenRoughness is floored to it; alpha = roughness^2): below it
// the lobe is a ring at grazing angles narrower than the albedo table resolves.
constexpr float kMinSheenRoughness = 0.07f;

// D(h) = (2 + 1/alpha) (1 - (n.h)^2)^(1 / (2 alpha)) / (2 pi), cosH = n.h.
double charlieD(double cosH, double alpha);
// Lambda of the Charlie masking (the extension's fit of Estevez & Kulla), cosTheta in (0, 1].
double charlieLambda(double cosTheta, double alpha);

// The albedo table: ln E at kTableMu x kTableRoughness nodes, node (i, j) at index j * kTableMu + i.
constexpr int kTableMu = 48, kTableRoughness = 48;
// Nodes: mu_i = i / 47 for i >= 1 and mu_0 = 1 / 94 (the albedo grows steeply only as mu -> 0),
// roughness_j = kMin + (1 - kMin) j / 47.
inline double tableMu(int i) { return i == 0 ? 0.5 / (kTableMu - 1) : double(i) / (kTableMu - 1); }
inline double tableRoughness(int j) {
    return kMinSheenRoughness + (1.0 - kMinSheenRoughness) * j / (kTableRoughness - 1);
}

// E(mu, roughness), the directional albedo of the sheen BRDF for n.v = mu, by the midpoint rule
// (96 x 48 cells). The table entry of node (i, j) is
// float(log(max(albedoQuadrature(tableMu(i), tableRoughness(j)), 1e-30))).
double albedoQuadrature(double mu, double roughness);

}  // namespace bsdf_detail
}  // namespace bdptref
