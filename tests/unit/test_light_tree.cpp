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
//  * children with the same bounds but power (a quad light) are chosen in proportion to power.
#include "bdptref/light_tree.h"

#include "../support/chi2.h"

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
