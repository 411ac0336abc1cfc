// Which light next-event estimation picks at a shading point, and the probability of that pick,
// for either sampler (IntegratorSettings::lightSampler, --light-sampler): the power sampler ignores
// the point (Scene::lightSampler, bit-identical to the code before the tree existed); the tree
// (Scene::lightTree) weighs lights by their importance at (p, n). Every MIS density that contains
// the selection probability of a light chosen at a shading point asks lightChoicePmf with that
// point's p and geometric normal, so the density is the one the sampler realised
// (docs/lights.md, "Light tree"; docs/path-tracer.md).
#pragma once

#include "bdptref/light_tree.h"
#include "bdptref/scene.h"

namespace bdptref {

// The light index (-1: none) and its probability *pmf, using u.
inline int chooseLight(const Scene& scene, LightSamplerKind kind, const Vec3& p, const Vec3& ng, float u, float* pmf) {
    if (kind == LightSamplerKind::Tree) return scene.lightTree().sample(p, ng, u, pmf);
    return scene.lightSampler().sample(u, pmf);
}

// The probability that chooseLight(scene, kind, p, ng, ...) returns `light`.
inline float lightChoicePmf(const Scene& scene, LightSamplerKind kind, const Vec3& p, const Vec3& ng, int light) {
    if (kind == LightSamplerKind::Tree) return scene.lightTree().pmf(p, ng, light);
    return scene.lightSampler().pmf(light);
}

}  // namespace bdptref
