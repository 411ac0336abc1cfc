// Light selection that depends on the shading point: a bounding-volume hierarchy over the scene's
// finite lights (after pbrt-v4's BVHLightSampler and Cycles' light tree; docs/lights.md, "Light
// tree"). Each node bounds its lights' positions, their total power and the directions they emit
// in (a cone); a node's importance for a shading point (p, n) is an upper-bound-style estimate of
// what its lights send to p. `sample` walks from the root, choosing a child in proportion to its
// importance, and returns the light with the product of the choices; the tree is 4-wide (the four
// children's importances are evaluated at once). `pmf` walks the same
// root-to-leaf path of one light with the same arithmetic, so both give the same float for the same
// (p, n, light) (tests/unit/test_light_tree.cpp). Infinite lights (directional, environment) are
// chosen apart, with probability pInfinite = (number of them) / (number of them + 1 if the tree has
// lights), and among themselves in proportion to power.
//
// The tree is a pure function of the light list: building it twice gives the same tree (no
// randomness, no thread-dependent order), so every pmf is reproducible.
#pragma once

#include "bdptref/light.h"
#include "bdptref/math.h"
#include "bdptref/sampling.h"

#include <cstdint>
#include <string>
#include <vector>

namespace bdptref {

// Which light sampler next-event estimation uses (--light-sampler).
enum class LightSamplerKind : uint8_t { Power, Tree };
const char* lightSamplerName(LightSamplerKind k);  // "power", "tree"
// The sampler named "power" or "tree"; otherwise InputError "<what>: expected power or tree, got '<name>'".
LightSamplerKind parseLightSamplerKind(const std::string& name, const std::string& what);

// What a set of lights emits and where (docs/lights.md, "Light tree", "Light bounds").
struct LightBounds {
    Vec3 pMin{0.f}, pMax{0.f};  // box around the emitting points
    double phi = 0.0;           // power (Light::power summed): 0 = empty
    Vec3 w{0.f, 0.f, 1.f};      // cone axis: the normals lie within theta_o of w
    float cosTheta_o = 1.f;     // spread of the normals about w
    float cosTheta_e = 0.f;     // emission spread beyond a normal (pi/2 for a cosine emitter)
    bool twoSided = false;      // emits about -w too
};

// The bounds of one finite light (area, point, spot); phi = l.power.
LightBounds lightBounds(const Light& l);
LightBounds unionBounds(const LightBounds& a, const LightBounds& b);

// What the walk reads of a node's bounds, precomputed in float: the bounding sphere of the box,
// the cone's sines and cosines, and phi relative to the root's (so that phi / d^2 fits in float).
struct NodeBounds {
    Vec3 centre{0.f};
    float radius2 = 0.f;  // squared half-diagonal of the box
    Vec3 w{0.f, 0.f, 1.f};
    float phi = 0.f;      // phi / phiRoot, at least the smallest normal float when phi > 0
    float cosTheta_o = 1.f, sinTheta_o = 0.f, cosTheta_e = 0.f;
    bool twoSided = false;
};
NodeBounds nodeBounds(const LightBounds& b, double phiRoot);
// Importance of the lights inside `b` for a shading point p with normal n (n = 0: no normal);
// 0 when no light in b can send anything to p (formula I of docs/lights.md), in float.
float lightImportance(const NodeBounds& b, const Vec3& p, const Vec3& n);

class LightTree {
public:
    LightTree() = default;
    explicit LightTree(const std::vector<Light>& lights);
    // The chosen light index (or -1: none can light p) and its probability.
    int sample(const Vec3& p, const Vec3& n, float u, float* pmf) const;
    // The probability that sample(p, n, ., .) returns `light`, bit for bit the one sample returns.
    float pmf(const Vec3& p, const Vec3& n, int light) const;

    size_t nodeCount() const { return nodes_.size(); }
    int depth() const;  // the longest root-to-light path: the number of choices (nodes) on it

    // A node of the 4-wide tree: up to 4 children (lanes), each a node or a light, with their
    // NodeBounds stored lane by lane so that the walk evaluates the 4 importances at once
    // (docs/lights.md, "The 4-wide tree"). Unused lanes have phi 0 (importance 0).
    static constexpr int kWidth = 4;
    struct alignas(64) Node {  // 4 cache lines
        float centreX[kWidth] = {}, centreY[kWidth] = {}, centreZ[kWidth] = {}, radius2[kWidth] = {};
        float wX[kWidth] = {}, wY[kWidth] = {}, wZ[kWidth] = {}, phi[kWidth] = {};
        float cosTheta_o[kWidth] = {}, sinTheta_o[kWidth] = {}, cosTheta_e[kWidth] = {};
        float twoSided[kWidth] = {};      // 1: two-sided, 0: not
        int32_t child[kWidth] = {-1, -1, -1, -1};  // a node index, or a light index where `lightLanes` has the lane's bit
        uint8_t lightLanes = 0;
        uint8_t count = 0;                // lanes in use: 1..4, the first `count`
        // The lanes' bounds differ only in phi (e.g. a quad light's two triangles): their
        // importances are in the ratio of their phi at every p, so P(lane) = phi_k / sum phi is
        // stored here and no importance is evaluated (docs/lights.md). fixed = false: evaluate.
        bool fixed = false;
        double fixedP[kWidth] = {};
    };

    struct Binary;  // build only: the binary SAOH tree the 4-wide one is collapsed from (light_tree.cpp)

private:
    struct Trail {
        uint64_t lanes = 0;  // bits 2d, 2d+1: the lane taken at depth d
        int32_t depth = -1;  // choices on the path; -1: the light is not in the tree
    };
    static int buildBinary(std::vector<Binary>& bin, std::vector<std::pair<int, LightBounds>>& items, size_t begin, size_t end,
                           int depth);
    void collapse(const std::vector<Binary>& bin, int b, uint64_t lanes, int depth);
    double infiniteShare() const;
    int sampleInfinite(float u, double share, float* pmf) const;

    std::vector<Node> nodes_;
    std::vector<Trail> trails_;       // per light
    std::vector<int> infinite_;       // the infinite lights' indices
    std::vector<int> infiniteSlot_;   // per light: its index in infinite_, or -1
    Distribution1D infiniteDistribution_;
};

}  // namespace bdptref
