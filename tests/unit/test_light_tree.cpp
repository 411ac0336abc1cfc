// The light tree (include/bdptref/light_tree.h, docs/lights.md "Light tree"). What is proven, on
// a fixed set of 300 lights (area one- and two-sided of powers spread over 4 decades, points, spots,
// and in one case an environment and a directional light) and fixed random shading points:
//  * sample() and pmf() agree bit for bit: the pmf sample returns == pmf(p, n, light) (2000 pairs);
//  * the pmfs of all lights sum to 1 within 1e-5 (float rounding of 300 products of double
//    probabilities; a walk of depth d rounds once, relative 6e-8) where every light can reach p,
//    and to at most 1 + 1e-5 everywhere (lights that cannot reach p get 0);
//  * a light that can send light to p is never given pmf 0 (the importance is conservative);
//  * sample frequencies match the pmfs: chi-square over lights (and the "none" cell), 3 points,
//    Sidak-corrected to a 1% family false-failure rate;
//  * the build is deterministic (two builds give the same pmfs);
//  * children with the same bounds but power (a quad light) are chosen in proportion to power;
//  * the 4-wide importance (importance4, SSE) equals lightImportance lane by lane, bit for bit
//    (2000 random nodes: cones of any spread, two-sided, phi 0 lanes, points inside the spheres);
//  * a node of up to 4 lights (a leaf of several lights) gives each light I_k / sum I, and 0
//    exactly where its importance is 0;
//  * 8192 lights on a ceiling grid give a tree of depth <= 10 whose pmfs sum to 1 and agree
//    with sample bit for bit.
#include "bdptref/light_tree.h"

#include "../support/chi2.h"
#include "scene/light_importance4.h"

#include <catch2/catch.hpp>

#include <cmath>

using namespace bdptref;
using test::TestRng;

namespace {

constexpr int kChi2Tests = 3;
const double kChi2Alpha = test::sidakAlpha(0.01, kChi2Tests);

Vec3 randomIn(TestRng& r, float lo, float hi) {
    return Vec3(lo + (hi - lo) * r.uniform(), lo + (hi - lo) * r.uniform(), lo + (hi - lo) * r.uniform());
}

Light randomAreaLight(TestRng& r, bool twoSided) {
    Light l;
    l.type = LightType::Area;
    const Vec3 c = randomIn(r, -4.f, 4.f);
    const float size = 0.05f + 0.3f * r.uniform();
    l.v0 = c + size * randomIn(r, -1.f, 1.f);
    l.v1 = c + size * randomIn(r, -1.f, 1.f);
    l.v2 = c + size * randomIn(r, -1.f, 1.f);
    const Vec3 x = glm::cross(l.v1 - l.v0, l.v2 - l.v0);
    l.normal = glm::normalize(x);
    l.area = 0.5f * glm::length(x);
    l.emission = Rgb(std::pow(10.f, 4.f * r.uniform() - 2.f));  // 4 decades
    l.twoSided = twoSided;
    l.power = lightPower(l);
    return l;
}

Light randomPunctual(TestRng& r, LightType type) {
    Light l;
    l.type = type;
    l.position = randomIn(r, -4.f, 4.f);
    l.direction = glm::normalize(randomIn(r, -1.f, 1.f));
    l.cosInner = std::cos(0.2f + 0.3f * r.uniform());
    l.cosOuter = std::cos(0.6f + 0.5f * r.uniform());
    l.emission = Rgb(std::pow(10.f, 2.f * r.uniform() - 1.f));
    l.power = lightPower(l);
    return l;
}

// 300 lights; `allReachEverywhere`: only two-sided area and point lights (none can be culled).
std::vector<Light> testLights(bool allReachEverywhere, bool withInfinite) {
    TestRng r(7, allReachEverywhere ? 1 : 2);
    std::vector<Light> lights;
    for (int i = 0; i < 300; ++i) {
        const int kind = i % 10;
        if (kind == 0) lights.push_back(randomPunctual(r, LightType::Point));
        else if (kind == 1 && !allReachEverywhere) lights.push_back(randomPunctual(r, LightType::Spot));
        else lights.push_back(randomAreaLight(r, allReachEverywhere || kind < 5));
    }
    if (withInfinite) {
        Light env;
        env.type = LightType::Environment;
        env.emission = Rgb(0.5f);
        env.sceneRadius = 6.f;
        env.power = lightPower(env);
        lights.push_back(env);
        Light sun;
        sun.type = LightType::Directional;
        sun.direction = glm::normalize(Vec3(0.3f, -1.f, 0.2f));
        sun.emission = Rgb(3.f);
        sun.sceneRadius = 6.f;
        sun.power = lightPower(sun);
        lights.push_back(sun);
    }
    return lights;
}

struct ShadingPoint {
    Vec3 p, n;
};

ShadingPoint randomShadingPoint(uint64_t i) {
    TestRng r(11, i);
    const Vec3 n = i % 7 == 0 ? Vec3(0.f) : glm::normalize(randomIn(r, -1.f, 1.f));
    return ShadingPoint{randomIn(r, -5.f, 5.f), n};
}

double pmfSum(const LightTree& tree, const ShadingPoint& s, size_t lightCount) {
    double sum = 0;
    for (size_t k = 0; k < lightCount; ++k) sum += tree.pmf(s.p, s.n, int(k));
    return sum;
}

// Some vertex of the triangle sees p from its emitting side (or the light is not an area light).
bool canReach(const Light& l, const Vec3& p) {
    if (l.type != LightType::Area || l.twoSided) return l.type != LightType::Spot;
    for (const Vec3& v : {l.v0, l.v1, l.v2})
        if (glm::dot(l.normal, p - v) > 1e-4f * glm::length(p - v)) return true;
    return false;
}

}  // namespace

TEST_CASE("light tree: sample returns exactly pmf(p, n, light)", "[lighttree]") {
    for (const bool infinite : {false, true}) {
        const std::vector<Light> lights = testLights(false, infinite);
        const LightTree tree(lights);
        REQUIRE(tree.depth() < 64);
        int checked = 0;
        for (uint64_t i = 0; i < 100; ++i) {
            const ShadingPoint s = randomShadingPoint(i);
            for (uint64_t j = 0; j < 10; ++j) {
                float pmf = 0.f;
                const int light = tree.sample(s.p, s.n, TestRng(12, i * 10 + j).uniform(), &pmf);
                if (light < 0) continue;
                INFO("point " << i << " light " << light);
                REQUIRE(pmf > 0.f);
                REQUIRE(pmf == tree.pmf(s.p, s.n, light));  // bit for bit
                ++checked;
            }
        }
        CHECK(checked > 900);
    }
}

TEST_CASE("light tree: pmfs sum to 1, lights that can reach p are never at 0", "[lighttree]") {
    const std::vector<Light> everywhere = testLights(true, true);
    const LightTree full(everywhere);
    const std::vector<Light> mixed = testLights(false, false);
    const LightTree culled(mixed);
    for (uint64_t i = 0; i < 100; ++i) {
        const ShadingPoint s = randomShadingPoint(i);
        INFO("point " << i);
        CHECK(std::abs(pmfSum(full, s, everywhere.size()) - 1.0) < 1e-5);
        CHECK(pmfSum(culled, s, mixed.size()) < 1.0 + 1e-5);
        for (size_t k = 0; k < mixed.size(); ++k)
            if (canReach(mixed[k], s.p)) CHECK(culled.pmf(s.p, s.n, int(k)) > 0.f);
    }
}

TEST_CASE("light tree: sample frequencies match the pmfs (chi-square)", "[lighttree][chi2]") {
    const std::vector<Light> lights = testLights(false, true);
    const LightTree tree(lights);
    for (uint64_t point : {3u, 5u, 14u}) {  // 14: no normal
        const ShadingPoint s = randomShadingPoint(point);
        std::vector<double> pmf(lights.size());
        for (size_t k = 0; k < lights.size(); ++k) pmf[k] = tree.pmf(s.p, s.n, int(k));
        auto sampler = [&](uint64_t i, size_t* k) {
            float p = 0.f;
            const int light = tree.sample(s.p, s.n, TestRng(13 + point, i).uniform(), &p);
            if (light < 0) return false;
            *k = size_t(light);
            return true;
        };
        const test::Chi2Result r = test::chi2DiscreteTest(sampler, pmf, 200000);
        INFO("point " << point << ": " << r.report);
        CHECK(r.pValue > kChi2Alpha);
    }
}

TEST_CASE("light tree: the build is deterministic, also with no lights or only infinite lights", "[lighttree]") {
    const std::vector<Light> lights = testLights(false, true);
    const LightTree a(lights), b(lights);
    REQUIRE(a.nodeCount() == b.nodeCount());
    for (uint64_t i = 0; i < 20; ++i) {
        const ShadingPoint s = randomShadingPoint(i);
        for (size_t k = 0; k < lights.size(); ++k) CHECK(a.pmf(s.p, s.n, int(k)) == b.pmf(s.p, s.n, int(k)));
    }
    float pmf = 1.f;
    CHECK(LightTree(std::vector<Light>{}).sample(Vec3(0.f), Vec3(0.f, 0.f, 1.f), 0.5f, &pmf) == -1);
    CHECK(pmf == 0.f);
    const std::vector<Light> infiniteOnly(lights.end() - 2, lights.end());
    const LightTree inf(infiniteOnly);
    CHECK(inf.pmf(Vec3(0.f), Vec3(0.f), 0) + inf.pmf(Vec3(0.f), Vec3(0.f), 1) == Approx(1.0).epsilon(1e-6));
    const int k = inf.sample(Vec3(0.f), Vec3(0.f), 0.3f, &pmf);
    REQUIRE(k >= 0);
    CHECK(pmf == inf.pmf(Vec3(0.f), Vec3(0.f), k));
}

TEST_CASE("light tree: children that differ only in power are chosen by power (a quad's two triangles)", "[lighttree]") {
    Light a;
    a.type = LightType::Area;
    a.v0 = Vec3(0, 2, 0), a.v1 = Vec3(1, 2, 0), a.v2 = Vec3(1, 2, 1);
    a.normal = Vec3(0, -1, 0);
    a.area = 0.5f;
    a.emission = Rgb(1.f);
    a.power = lightPower(a);
    Light b = a;
    b.v1 = Vec3(1, 2, 1), b.v2 = Vec3(0, 2, 1);  // the quad's other half: the same box
    b.emission = Rgb(3.f);
    b.power = lightPower(b);
    const LightTree tree(std::vector<Light>{a, b});
    for (uint64_t i = 0; i < 20; ++i) {
        const ShadingPoint s = randomShadingPoint(i);
        CHECK(tree.pmf(s.p, s.n, 0) == float(a.power / (a.power + b.power)));
        CHECK(tree.pmf(s.p, s.n, 1) == float(1.0 - a.power / (a.power + b.power)));
        float pmf = 0.f;
        const int k = tree.sample(s.p, s.n, TestRng(17, i).uniform(), &pmf);
        REQUIRE(k >= 0);
        CHECK(pmf == tree.pmf(s.p, s.n, k));
    }
}

namespace {

// Random node bounds: boxes of 0 to 2 m around points in [-4, 4]^3, cones of any spread, some
// two-sided, some of phi 0 (an unused lane).
NodeBounds randomNodeBounds(TestRng& r) {
    LightBounds b;
    const Vec3 c = randomIn(r, -4.f, 4.f), half = randomIn(r, 0.f, 1.f) * (r.uniform() < 0.2f ? 0.f : 1.f);
    b.pMin = c - half, b.pMax = c + half;
    b.phi = r.uniform() < 0.1f ? 0.0 : std::pow(10.0, 3.0 * r.uniform() - 2.0);
    b.w = glm::normalize(randomIn(r, -1.f, 1.f));
    b.cosTheta_o = 2.f * r.uniform() - 1.f;
    b.cosTheta_e = r.uniform() < 0.5f ? 0.f : r.uniform();
    b.twoSided = r.uniform() < 0.3f;
    return nodeBounds(b, 10.0);
}

}  // namespace

TEST_CASE("light tree: the 4-wide importance equals lightImportance lane by lane, bit for bit", "[lighttree]") {
    TestRng r(19, 0);
    for (int trial = 0; trial < 2000; ++trial) {
        NodeBounds lanes[LightTree::kWidth];
        LightTree::Node node;
        for (int k = 0; k < LightTree::kWidth; ++k) {
            lanes[k] = randomNodeBounds(r);
            node.centreX[k] = lanes[k].centre.x, node.centreY[k] = lanes[k].centre.y, node.centreZ[k] = lanes[k].centre.z;
            node.radius2[k] = lanes[k].radius2;
            node.wX[k] = lanes[k].w.x, node.wY[k] = lanes[k].w.y, node.wZ[k] = lanes[k].w.z;
            node.phi[k] = lanes[k].phi;
            node.cosTheta_o[k] = lanes[k].cosTheta_o, node.sinTheta_o[k] = lanes[k].sinTheta_o;
            node.cosTheta_e[k] = lanes[k].cosTheta_e, node.twoSided[k] = lanes[k].twoSided ? 1.f : 0.f;
        }
        // Points near the boxes too (inside the bounding sphere: theta_b = pi), with and without a normal.
        const Vec3 p = trial % 5 == 0 ? lanes[0].centre + 0.1f * randomIn(r, -1.f, 1.f) : randomIn(r, -5.f, 5.f);
        const Vec3 n = trial % 7 == 0 ? Vec3(0.f) : randomIn(r, -1.f, 1.f);  // not unit: lightImportance normalises
        float wide[LightTree::kWidth];
        lighttree_detail::importance4(node, lighttree_detail::Query4(p, n), wide);
        for (int k = 0; k < LightTree::kWidth; ++k) {
            INFO("trial " << trial << " lane " << k);
            CHECK(wide[k] == lightImportance(lanes[k], p, n));
        }
    }
}

TEST_CASE("light tree: up to 4 lights share one node, each chosen in proportion to its importance", "[lighttree]") {
    const std::vector<Light> all = testLights(false, false);
    for (size_t count : {1u, 2u, 3u, 4u}) {
        const std::vector<Light> lights(all.begin() + 2, all.begin() + 2 + std::ptrdiff_t(count));  // area lights
        const LightTree tree(lights);
        REQUIRE(tree.nodeCount() == 1);
        REQUIRE(tree.depth() == 1);
        LightBounds rootBounds;
        for (const Light& l : lights) rootBounds = unionBounds(rootBounds, lightBounds(l));
        for (uint64_t i = 0; i < 50; ++i) {
            const ShadingPoint s = randomShadingPoint(i);
            std::vector<double> importance;
            double sum = 0;
            for (const Light& l : lights) {
                importance.push_back(lightImportance(nodeBounds(lightBounds(l), rootBounds.phi), s.p, s.n));
                sum += importance.back();
            }
            for (size_t k = 0; k < count; ++k) {
                INFO("lights " << count << " point " << i << " light " << k);
                // The tree's phiRoot sums in build order: equal up to rounding, and 0 exactly where I is.
                const float pmf = tree.pmf(s.p, s.n, int(k));
                CHECK(pmf == Approx(sum > 0 ? importance[k] / sum : 0.0).epsilon(1e-5).margin(1e-30));
                CHECK((pmf > 0.f) == (importance[k] > 0.0));
            }
        }
    }
}

TEST_CASE("light tree: the 4-wide tree over a grid of 8192 lights is shallow, its pmfs sum to 1", "[lighttree]") {
    std::vector<Light> lights;
    TestRng r(23, 0);
    for (int i = 0; i < 8192; ++i) {  // a 64 x 128 ceiling of small downward quads' triangles
        Light l = randomAreaLight(r, false);
        const Vec3 c(float(i % 64) * 0.5f, 4.f, float(i / 64) * 0.5f);
        l.v0 = c, l.v1 = c + Vec3(0.1f, 0.f, 0.f), l.v2 = c + Vec3(0.f, 0.f, 0.1f);
        l.normal = Vec3(0.f, -1.f, 0.f);
        l.area = 0.005f;
        l.power = lightPower(l);
        lights.push_back(l);
    }
    const LightTree tree(lights);
    INFO("depth " << tree.depth() << ", nodes " << tree.nodeCount());
    CHECK(tree.depth() <= 10);  // log4(8192) = 6.5; the binary SAOH tree of these is 13 to 20 deep
    for (uint64_t i = 0; i < 5; ++i) {
        const Vec3 p(32.f * float(i) / 5.f, 0.f, 64.f * float(i) / 5.f), n(0.f, 1.f, 0.f);
        double sum = 0;
        for (size_t k = 0; k < lights.size(); ++k) sum += tree.pmf(p, n, int(k));
        CHECK(std::abs(sum - 1.0) < 1e-5);
        for (uint64_t j = 0; j < 50; ++j) {
            float pmf = 0.f;
            const int k = tree.sample(p, n, TestRng(29, i * 50 + j).uniform(), &pmf);
            REQUIRE(k >= 0);
            CHECK(pmf == tree.pmf(p, n, k));
        }
    }
}
