// The light tree (include/bdptref/light_tree.h): bounds, cones, importance, the build and the
// two walks that must agree (sample and pmf). Formulas and their names: docs/lights.md, "Light tree".
#include "bdptref/light_tree.h"
#include "bdptref/errors.h"

#include "scene/light_importance4.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace bdptref {

namespace {

using DVec3 = glm::dvec3;
constexpr double kPi = 3.14159265358979323846;
constexpr double kOneMinusEpsilon = 0x1.fffffffffffffp-1;

double clampCos(double c) { return std::min(1.0, std::max(-1.0, c)); }
// Rotates v by `angle` about the unit axis k (Rodrigues).
DVec3 rotateAbout(const DVec3& v, const DVec3& k, double angle) {
    const double c = std::cos(angle), s = std::sin(angle);
    return v * c + glm::cross(k, v) * s + k * glm::dot(k, v) * (1.0 - c);
}

struct Cone {
    DVec3 w;
    double cosTheta;
};

// The smallest cone (of this construction) holding both cones: pbrt-v4's DirectionCone Union.
Cone unionCones(const Cone& a, const Cone& b) {
    const double thetaA = std::acos(clampCos(a.cosTheta)), thetaB = std::acos(clampCos(b.cosTheta));
    const double thetaD = std::acos(clampCos(glm::dot(a.w, b.w)));
    if (std::min(thetaD + thetaB, kPi) <= thetaA) return a;
    if (std::min(thetaD + thetaA, kPi) <= thetaB) return b;
    const double thetaO = (thetaA + thetaD + thetaB) / 2;
    const Cone sphere{a.w, -1.0};
    if (thetaO >= kPi) return sphere;
    const DVec3 axis = glm::cross(a.w, b.w);
    if (glm::dot(axis, axis) == 0.0) return sphere;
    const DVec3 w = glm::normalize(rotateAbout(a.w, glm::normalize(axis), thetaO - thetaA));
    return Cone{w, std::cos(thetaO)};
}

// M_Omega of docs/lights.md: the solid-angle measure of the cone (theta_o, theta_e).
double orientationMeasure(const LightBounds& b) {
    const double thetaO = std::acos(clampCos(b.cosTheta_o)), thetaE = std::acos(clampCos(b.cosTheta_e));
    const double thetaW = std::min(thetaO + thetaE, kPi);
    const double sinO = std::sin(thetaO), cosO = std::cos(thetaO);
    return 2 * kPi * (1 - cosO) + kPi / 2 * (2 * thetaW * sinO - std::cos(thetaO - 2 * thetaW) - 2 * thetaO * sinO + cosO);
}

double surfaceArea(const LightBounds& b) {
    const DVec3 d = DVec3(b.pMax) - DVec3(b.pMin);
    return 2 * (d.x * d.y + d.y * d.z + d.z * d.x);
}

Vec3 centroid(const LightBounds& b) { return (b.pMin + b.pMax) * 0.5f; }

// Cost of a child in the surface-area-orientation heuristic (SAOH; formula C of docs/lights.md).
double splitCost(const LightBounds& b, const Vec3& nodeDiagonal, int dim) {
    const float maxExtent = std::max(nodeDiagonal.x, std::max(nodeDiagonal.y, nodeDiagonal.z));
    const double kr = double(maxExtent) / double(nodeDiagonal[dim]);
    return b.phi * orientationMeasure(b) * kr * surfaceArea(b);
}

int ceilLog2(size_t n) {
    int k = 0;
    while ((size_t(1) << k) < n) ++k;
    return k;
}

using Item = std::pair<int, LightBounds>;

struct SplitChoice {
    int dim = -1, bucket = 0;
    double cost = 0;
};

constexpr int kBuckets = 12;

int bucketOf(const Vec3& c, const Vec3& lo, const Vec3& hi, int dim) {
    const float t = (c[dim] - lo[dim]) / (hi[dim] - lo[dim]);
    return std::min(kBuckets - 1, std::max(0, int(float(kBuckets) * t)));
}

// The best bucket boundary along `dim` by SAOH, or none (dim = -1).
SplitChoice bestSplitAlong(const std::vector<Item>& items, size_t begin, size_t end, const LightBounds& node, const Vec3& lo,
                           const Vec3& hi, int dim) {
    std::array<LightBounds, kBuckets> buckets{};
    std::array<size_t, kBuckets> counts{};
    for (size_t i = begin; i < end; ++i) {
        const int k = bucketOf(centroid(items[i].second), lo, hi, dim);
        buckets[size_t(k)] = unionBounds(buckets[size_t(k)], items[i].second);
        ++counts[size_t(k)];
    }
    SplitChoice best;
    const Vec3 diagonal = node.pMax - node.pMin;
    for (int split = 1; split < kBuckets; ++split) {
        LightBounds below, above;
        size_t nBelow = 0, nAbove = 0;
        for (int k = 0; k < split; ++k) below = unionBounds(below, buckets[size_t(k)]), nBelow += counts[size_t(k)];
        for (int k = split; k < kBuckets; ++k) above = unionBounds(above, buckets[size_t(k)]), nAbove += counts[size_t(k)];
        if (nBelow == 0 || nAbove == 0) continue;
        const double cost = splitCost(below, diagonal, dim) + splitCost(above, diagonal, dim);
        if (best.dim < 0 || cost < best.cost) best = SplitChoice{dim, split, cost};
    }
    return best;
}

// Sorts items[begin, end) by centroid along the widest axis (index breaks ties) and halves them.
size_t medianSplit(std::vector<Item>& items, size_t begin, size_t end, const Vec3& lo, const Vec3& hi) {
    const Vec3 extent = hi - lo;
    const int dim = extent.x >= extent.y && extent.x >= extent.z ? 0 : extent.y >= extent.z ? 1 : 2;
    std::sort(items.begin() + std::ptrdiff_t(begin), items.begin() + std::ptrdiff_t(end), [dim](const Item& a, const Item& b) {
        const float ca = centroid(a.second)[dim], cb = centroid(b.second)[dim];
        return ca < cb || (ca == cb && a.first < b.first);
    });
    return begin + (end - begin) / 2;
}

// Where to cut items[begin, end): the SAOH split when one helps and the depth allows, else the median.
size_t splitPoint(std::vector<Item>& items, size_t begin, size_t end, int depth) {
    LightBounds node;
    Vec3 lo(kInfinity), hi(-kInfinity);
    for (size_t i = begin; i < end; ++i) {
        node = unionBounds(node, items[i].second);
        lo = glm::min(lo, centroid(items[i].second));
        hi = glm::max(hi, centroid(items[i].second));
    }
    // A trail holds 64 bits: near the limit only balanced cuts, which finish within ceil(log2 n).
    if (depth + ceilLog2(end - begin) + 1 >= 64) return medianSplit(items, begin, end, lo, hi);
    SplitChoice best;
    for (int dim = 0; dim < 3; ++dim) {
        if (!(hi[dim] > lo[dim])) continue;
        const SplitChoice c = bestSplitAlong(items, begin, end, node, lo, hi, dim);
        if (c.dim >= 0 && (best.dim < 0 || c.cost < best.cost)) best = c;
    }
    if (best.dim < 0 || !(best.cost > 0)) return medianSplit(items, begin, end, lo, hi);
    const auto mid = std::stable_partition(items.begin() + std::ptrdiff_t(begin), items.begin() + std::ptrdiff_t(end),
                                           [&](const Item& it) { return bucketOf(centroid(it.second), lo, hi, best.dim) < best.bucket; });
    const size_t m = size_t(mid - items.begin());
    return m == begin || m == end ? medianSplit(items, begin, end, lo, hi) : m;
}

bool sameWalkBoundsButPhi(const NodeBounds& a, const NodeBounds& b) {
    return a.centre == b.centre && a.radius2 == b.radius2 && a.w == b.w && a.cosTheta_o == b.cosTheta_o &&
           a.sinTheta_o == b.sinTheta_o && a.cosTheta_e == b.cosTheta_e && a.twoSided == b.twoSided;
}

}  // namespace

const char* lightSamplerName(LightSamplerKind k) { return k == LightSamplerKind::Tree ? "tree" : "power"; }

LightSamplerKind parseLightSamplerKind(const std::string& name, const std::string& what) {
    if (name == "power") return LightSamplerKind::Power;
    if (name == "tree") return LightSamplerKind::Tree;
    throw InputError(what + ": expected power or tree, got '" + name + "'");
}

LightBounds lightBounds(const Light& l) {
    LightBounds b;
    b.phi = l.power;
    switch (l.type) {
    case LightType::Area:
        b.pMin = glm::min(l.v0, glm::min(l.v1, l.v2));
        b.pMax = glm::max(l.v0, glm::max(l.v1, l.v2));
        b.w = l.normal;
        b.cosTheta_o = 1.f;
        b.cosTheta_e = 0.f;
        b.twoSided = l.twoSided;
        break;
    case LightType::Point:
        b.pMin = b.pMax = l.position;
        b.cosTheta_o = -1.f;  // normals everywhere
        b.cosTheta_e = 0.f;
        break;
    case LightType::Spot: {
        b.pMin = b.pMax = l.position;
        b.w = l.direction;
        const double inner = std::acos(clampCos(l.cosInner)), outer = std::acos(clampCos(l.cosOuter));
        b.cosTheta_o = float(std::cos(std::min(inner, outer)));
        b.cosTheta_e = float(std::cos(std::max(0.0, outer - inner)));
        break;
    }
    case LightType::Directional:
    case LightType::Environment: throw std::logic_error("lightBounds: infinite lights have no bounds");
    }
    return b;
}

LightBounds unionBounds(const LightBounds& a, const LightBounds& b) {
    if (a.phi == 0.0) return b;
    if (b.phi == 0.0) return a;
    const Cone cone = unionCones(Cone{DVec3(a.w), a.cosTheta_o}, Cone{DVec3(b.w), b.cosTheta_o});
    LightBounds u;
    u.pMin = glm::min(a.pMin, b.pMin);
    u.pMax = glm::max(a.pMax, b.pMax);
    u.phi = a.phi + b.phi;
    u.w = Vec3(cone.w);
    u.cosTheta_o = float(cone.cosTheta);
    u.cosTheta_e = std::min(a.cosTheta_e, b.cosTheta_e);
    u.twoSided = a.twoSided || b.twoSided;
    return u;
}

NodeBounds nodeBounds(const LightBounds& b, double phiRoot) {
    NodeBounds n;
    n.centre = (b.pMin + b.pMax) * 0.5f;
    const Vec3 half = (b.pMax - b.pMin) * 0.5f;
    n.radius2 = glm::dot(half, half);
    n.w = b.w;
    const double phi = phiRoot > 0 ? b.phi / phiRoot : 0.0;
    n.phi = b.phi > 0 ? std::max(float(phi), std::numeric_limits<float>::min()) : 0.f;
    n.cosTheta_o = b.cosTheta_o;
    n.sinTheta_o = safeSqrt(1.f - b.cosTheta_o * b.cosTheta_o);
    n.cosTheta_e = b.cosTheta_e;
    n.twoSided = b.twoSided;
    return n;
}

namespace {
float cosSubClampedF(float sinA, float cosA, float sinB, float cosB) { return cosA > cosB ? 1.f : cosA * cosB + sinA * sinB; }
float sinSubClampedF(float sinA, float cosA, float sinB, float cosB) { return cosA > cosB ? 0.f : sinA * cosB - cosA * sinB; }
float clampCosF(float c) { return std::min(1.f, std::max(-1.f, c)); }
}  // namespace

float lightImportance(const NodeBounds& b, const Vec3& p, const Vec3& n) {
    if (!(b.phi > 0.f)) return 0.f;
    const Vec3 toP = p - b.centre;
    const float d2Centre = glm::dot(toP, toP);
    const float d2 = std::max(std::max(d2Centre, b.radius2), 1e-20f);  // I = phi cos(theta') cos(theta_i') / d2
    const float invD = d2Centre > 0.f ? 1.f / std::sqrt(d2Centre) : 0.f;
    // theta_w: the cone axis to the direction from the centre to p.
    float cosW = d2Centre > 0.f ? clampCosF(glm::dot(b.w, toP) * invD) : 1.f;
    if (b.twoSided) cosW = std::abs(cosW);
    const float sinW = safeSqrt(1.f - cosW * cosW);
    // theta_b: half-angle of the cone from p holding the bounding sphere (pi when p is inside it).
    const bool inside = d2Centre <= b.radius2;
    const float sin2B = inside ? 0.f : b.radius2 / d2Centre;
    const float cosB = inside ? -1.f : safeSqrt(1.f - sin2B), sinB = inside ? 0.f : std::sqrt(sin2B);
    // theta' = max(0, theta_w - theta_o - theta_b): the smallest angle to the cone from any point of the box.
    const float cosX = cosSubClampedF(sinW, cosW, b.sinTheta_o, b.cosTheta_o);
    const float sinX = sinSubClampedF(sinW, cosW, b.sinTheta_o, b.cosTheta_o);
    const float cosP = cosSubClampedF(sinX, cosX, sinB, cosB);
    if (cosP <= b.cosTheta_e) return 0.f;
    float importance = b.phi * cosP / d2;
    const float nn = glm::dot(n, n);
    if (nn > 0.f && d2Centre > 0.f) {
        // theta_i' = max(0, theta_i - theta_b), |cos| (the receiver may transmit).
        const float cosI = clampCosF(std::abs(glm::dot(toP, n)) * invD / std::sqrt(nn));
        importance *= cosSubClampedF(safeSqrt(1.f - cosI * cosI), cosI, sinB, cosB);
    }
    return std::max(importance, 0.f);
}

// A node of the binary SAOH tree (one light per leaf) that the 4-wide tree is collapsed from.
struct LightTree::Binary {
    LightBounds bounds;
    int second = -1;    // interior: the second child (the first is this node + 1)
    int light = -1;     // leaf: the light index
    size_t lights = 1;  // lights below
};

namespace {
using lighttree_detail::Query4;

// The binary nodes that become the lanes of the wide node made from binary interior node b: its two
// children, then repeatedly the interior lane with the most lights (the first on a tie) replaced by
// its two children, in order, until 4 lanes. Every path through a wide node so crosses at least
// two binary levels unless it ends at a light, so the wide depth is at most ceil(binary depth / 2).
std::vector<int> laneSources(const std::vector<LightTree::Binary>& bin, int b) {
    std::vector<int> lanes{b + 1, bin[size_t(b)].second};
    while (lanes.size() < size_t(LightTree::kWidth)) {
        int best = -1;
        for (size_t i = 0; i < lanes.size(); ++i) {
            const LightTree::Binary& c = bin[size_t(lanes[i])];
            if (c.light < 0 && (best < 0 || c.lights > bin[size_t(lanes[size_t(best)])].lights)) best = int(i);
        }
        if (best < 0) break;
        const int src = lanes[size_t(best)];
        lanes[size_t(best)] = src + 1;
        lanes.insert(lanes.begin() + best + 1, bin[size_t(src)].second);
    }
    return lanes;
}

void setLane(LightTree::Node& node, int k, const NodeBounds& b) {
    node.centreX[k] = b.centre.x, node.centreY[k] = b.centre.y, node.centreZ[k] = b.centre.z;
    node.radius2[k] = b.radius2;
    node.wX[k] = b.w.x, node.wY[k] = b.w.y, node.wZ[k] = b.w.z;
    node.phi[k] = b.phi;
    node.cosTheta_o[k] = b.cosTheta_o, node.sinTheta_o[k] = b.sinTheta_o, node.cosTheta_e[k] = b.cosTheta_e;
    node.twoSided[k] = b.twoSided ? 1.f : 0.f;
}

// The lanes' weights at (p, n): I_k, or the stored P_k of a fixed node (then the sum is 1);
// false when no lane can light p. P(lane k | node, p, n) = weight_k / sum (double).
struct LaneWeights {
    double w[LightTree::kWidth];
    double sum;
};
bool laneWeights(const LightTree::Node& node, const Query4& q, LaneWeights* out) {
    if (node.fixed) {
        for (int k = 0; k < LightTree::kWidth; ++k) out->w[k] = node.fixedP[k];
        out->sum = 1.0;
        return true;
    }
    float importance[LightTree::kWidth];
    lighttree_detail::importance4(node, q, importance);
    for (int k = 0; k < LightTree::kWidth; ++k) out->w[k] = importance[k];
    out->sum = ((out->w[0] + out->w[1]) + out->w[2]) + out->w[3];  // unused lanes add 0
    return out->sum > 0 && std::isfinite(out->sum);
}

double laneProbability(const LaneWeights& lw, int k) { return lw.w[k] / lw.sum; }

// The lane whose share of [0, sum) holds x = u * sum (never one of weight 0: the last lane of
// weight > 0 takes what rounding leaves; no division, so the walk's next load waits on less), and
// u rescaled into that share.
int chooseLane(const LaneWeights& lw, int count, double* u) {
    const double x = *u * lw.sum;
    double start = 0;
    int k = 0;
    for (; k + 1 < count; ++k) {
        if (lw.w[k] > 0 && x < start + lw.w[k]) break;
        start += lw.w[k];
    }
    while (!(lw.w[k] > 0)) start -= lw.w[--k];  // rounding carried x past the last lane of weight > 0
    *u = std::min(std::max(x - start, 0.0) / lw.w[k], kOneMinusEpsilon);
    return k;
}

}  // namespace

LightTree::LightTree(const std::vector<Light>& lights) {
    trails_.assign(lights.size(), Trail{});
    infiniteSlot_.assign(lights.size(), -1);
    std::vector<Item> items;
    std::vector<double> infinitePowers;
    for (size_t i = 0; i < lights.size(); ++i) {
        const Light& l = lights[i];
        if (!(l.power > 0.0) || !std::isfinite(l.power)) continue;  // never chosen, as by the power sampler
        if (isInfinite(l)) {
            infiniteSlot_[i] = int(infinite_.size());
            infinite_.push_back(int(i));
            infinitePowers.push_back(l.power);
        } else {
            items.emplace_back(int(i), lightBounds(l));
        }
    }
    infiniteDistribution_ = Distribution1D(infinitePowers);
    if (items.empty()) return;
    std::vector<Binary> bin;
    bin.reserve(2 * items.size() - 1);
    buildBinary(bin, items, 0, items.size(), 0);
    nodes_.reserve(items.size() / 2 + 1);
    collapse(bin, 0, 0, 0);
}

int LightTree::buildBinary(std::vector<Binary>& bin, std::vector<Item>& items, size_t begin, size_t end, int depth) {
    const int index = int(bin.size());
    bin.emplace_back();
    if (end - begin == 1) {
        bin[size_t(index)].bounds = items[begin].second;
        bin[size_t(index)].light = items[begin].first;
        return index;
    }
    const size_t mid = splitPoint(items, begin, end, depth);
    buildBinary(bin, items, begin, mid, depth + 1);
    const int second = buildBinary(bin, items, mid, end, depth + 1);
    Binary& node = bin[size_t(index)];
    node.second = second;
    node.lights = end - begin;
    node.bounds = unionBounds(bin[size_t(index) + 1].bounds, bin[size_t(second)].bounds);
    return index;
}

// Makes the wide node for binary node b (a lone light: one lane) at `depth` (choices above it),
// reached by the lanes in `lanes`, and the wide nodes below it; records each light's trail.
void LightTree::collapse(const std::vector<Binary>& bin, int b, uint64_t lanes, int depth) {
    if (depth >= 32) throw std::logic_error("LightTree: a trail holds 32 choices");
    const size_t index = nodes_.size();
    nodes_.emplace_back();
    const std::vector<int> sources = bin[size_t(b)].light >= 0 ? std::vector<int>{b} : laneSources(bin, b);
    const double phiRoot = bin[0].bounds.phi;
    Node& node = nodes_[index];
    node.count = uint8_t(sources.size());
    double phiSum = 0;
    for (size_t k = 0; k < sources.size(); ++k) {
        setLane(node, int(k), nodeBounds(bin[size_t(sources[k])].bounds, phiRoot));
        phiSum += bin[size_t(sources[k])].bounds.phi;
    }
    bool samePhiFree = sources.size() >= 2;
    for (size_t k = 1; k < sources.size(); ++k)
        samePhiFree = samePhiFree && sameWalkBoundsButPhi(nodeBounds(bin[size_t(sources[k])].bounds, phiRoot),
                                                          nodeBounds(bin[size_t(sources[0])].bounds, phiRoot));
    node.fixed = samePhiFree;
    for (size_t k = 0; samePhiFree && k < sources.size(); ++k) node.fixedP[k] = bin[size_t(sources[k])].bounds.phi / phiSum;
    for (size_t k = 0; k < sources.size(); ++k) {
        const Binary& src = bin[size_t(sources[k])];
        const uint64_t path = lanes | (uint64_t(k) << (2 * depth));
        if (src.light >= 0) {
            nodes_[index].child[k] = src.light;
            nodes_[index].lightLanes = uint8_t(nodes_[index].lightLanes | (1u << k));
            trails_[size_t(src.light)] = Trail{path, depth + 1};
        } else {
            const int child = int(nodes_.size());
            collapse(bin, sources[k], path, depth + 1);
            nodes_[index].child[k] = child;
        }
    }
}

int LightTree::depth() const {
    int d = 0;
    for (const Trail& t : trails_) d = std::max(d, t.depth);
    return d;
}

// pInfinite: the infinite lights count as many choices as there are of them, the tree as one.
double LightTree::infiniteShare() const {
    if (infinite_.empty()) return 0.0;
    return double(infinite_.size()) / double(infinite_.size() + (nodes_.empty() ? 0 : 1));
}

int LightTree::sampleInfinite(float u, double share, float* pmf) const {
    float p = 0.f;
    const size_t k = infiniteDistribution_.sample(u, &p);
    *pmf = float(share * double(p));
    return *pmf > 0.f ? infinite_[k] : -1;
}

// The next node is known only once the importances are: start loading every candidate (the lanes'
// first two cache lines: centre, radius, cone, phi) while they are computed.
static void prefetchChildren(const LightTree::Node* nodes, const LightTree::Node& node) {
    for (int k = 0; k < node.count; ++k)
        if (!((node.lightLanes >> k) & 1u)) {
            const char* c = reinterpret_cast<const char*>(&nodes[node.child[k]]);
            __builtin_prefetch(c);
            __builtin_prefetch(c + 64);
        }
}

int LightTree::sample(const Vec3& p, const Vec3& n, float uf, float* pmf) const {
    *pmf = 0.f;
    if (std::isnan(uf)) return -1;
    double u = std::min(std::max(double(uf), 0.0), kOneMinusEpsilon);
    double acc = 1.0;
    const double share = infiniteShare();
    if (share > 0) {
        if (u < share) return sampleInfinite(float(std::min(u / share, kOneMinusEpsilon)), share, pmf);
        u = std::min((u - share) / (1.0 - share), kOneMinusEpsilon);
        acc = 1.0 - share;
    }
    if (nodes_.empty()) return -1;
    const Query4 q(p, n);
    const Node* node = &nodes_[0];
    for (;;) {
        prefetchChildren(nodes_.data(), *node);
        LaneWeights lw;
        if (!laneWeights(*node, q, &lw)) return -1;
        const int k = chooseLane(lw, node->count, &u);
        acc *= laneProbability(lw, k);
        if ((node->lightLanes >> k) & 1u) {
            *pmf = float(acc);
            return *pmf > 0.f ? node->child[k] : -1;
        }
        node = &nodes_[size_t(node->child[k])];
    }
}

float LightTree::pmf(const Vec3& p, const Vec3& n, int light) const {
    if (light < 0 || size_t(light) >= trails_.size()) return 0.f;
    const double share = infiniteShare();
    if (const int slot = infiniteSlot_[size_t(light)]; slot >= 0)
        return float(share * double(infiniteDistribution_.pmf(size_t(slot))));
    const Trail t = trails_[size_t(light)];
    if (t.depth < 0) return 0.f;
    double acc = share > 0 ? 1.0 - share : 1.0;
    const Query4 q(p, n);
    const Node* node = &nodes_[0];
    for (int d = 0; d < t.depth; ++d) {
        LaneWeights lw;
        if (!laneWeights(*node, q, &lw)) return 0.f;
        const int k = int((t.lanes >> (2 * d)) & 3u);
        acc *= laneProbability(lw, k);
        if (d + 1 < t.depth) node = &nodes_[size_t(node->child[k])];
    }
    return float(acc);
}

}  // namespace bdptref
