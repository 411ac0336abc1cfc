// Normal maps (docs/materials.md, "Normal maps"): generated tangents on meshes whose tangents are
// known, the perturbation formula, the loader (TANGENT, generated tangents, node transforms), a
// flat map rendering bit-identically to none, and a constant tilted map on a Lambert plane under
// a constant environment against the closed form of the shading-normal convention.
#include "scene/normal_map.h"
#include "scene/tangents.h"
#include "support/gltf_builder.h"
#include "support/render_util.h"

#include "bdptref/errors.h"
#include "bdptref/gltf_loader.h"
#include "bdptref/scene.h"

#include <catch2/catch.hpp>

#include <cmath>

using namespace bdptref;
using namespace bdptref::test;

namespace {

constexpr double kPiD = 3.14159265358979323846;

// Unit quad [0,1]^2 at z = 0 facing +z (triangles (0,1,2), (0,2,3)), with uv = f(x, y).
std::vector<Vec4> quadTangents(Vec2 (*uvOf)(float x, float y)) {
    const std::vector<Vec3> p = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)};
    const std::vector<Vec3> n(4, Vec3(0, 0, 1));
    std::vector<Vec2> uv;
    for (const Vec3& q : p) uv.push_back(uvOf(q.x, q.y));
    return generateTangents(p, n, uv, {glm::uvec3(0, 1, 2), glm::uvec3(0, 2, 3)});
}

void checkAll(const std::vector<Vec4>& t, const Vec3& tangent, float sign) {
    for (const Vec4& v : t) {
        CHECK(v.x == Approx(tangent.x).margin(1e-6));
        CHECK(v.y == Approx(tangent.y).margin(1e-6));
        CHECK(v.z == Approx(tangent.z).margin(1e-6));
        CHECK(v.w == sign);
    }
}

}  // namespace

TEST_CASE("Normal maps: generated tangents of a planar quad follow its uv layout", "[normalmap]") {
    // glTF's v runs down the image and the map's +Y is up, so B = w cross(N, T) must point along
    // -dp/dv: uv = xy (v grows with y) gives w = -1, the usual exported layout v = 1 - y gives +1.
    checkAll(quadTangents([](float x, float y) { return Vec2(x, y); }), Vec3(1, 0, 0), -1.f);
    checkAll(quadTangents([](float x, float y) { return Vec2(x, 1.f - y); }), Vec3(1, 0, 0), 1.f);
    // Mirrored in u: the tangent turns round and the handedness flips.
    checkAll(quadTangents([](float x, float y) { return Vec2(1.f - x, 1.f - y); }), Vec3(-1, 0, 0), -1.f);
    checkAll(quadTangents([](float x, float y) { return Vec2(-x, y); }), Vec3(-1, 0, 0), 1.f);
    // A layout rotated by phi: uv = R(phi) (x, y), so dp/du = R(-phi) e_u = (cos phi, -sin phi).
    checkAll(quadTangents([](float x, float y) {
                 const float c = std::cos(0.5f), s = std::sin(0.5f);
                 return Vec2(c * x - s * y, s * x + c * y);
             }),
             Vec3(std::cos(0.5f), -std::sin(0.5f), 0.f), -1.f);
    // Scaling uv does not change the tangent (only its direction counts).
    checkAll(quadTangents([](float x, float y) { return Vec2(7.f * x, 1.f - 0.25f * y); }), Vec3(1, 0, 0), 1.f);
}

TEST_CASE("Normal maps: a shared vertex averages its corners' tangents weighted by the corner angles", "[normalmap]") {
    // Vertex 0 at the origin is a corner of triangle A (angle 90 deg, uv = xy: tangent +x) and of
    // triangle B (angle 45 deg, uv = (y, -x): tangent +y). MikkTSpace weights by angle:
    // normalize(pi/2 (1,0,0) + pi/4 (0,1,0)) = (2, 1, 0)/sqrt 5 (an area weighting would give
    // (1, 1, 0)/sqrt 2: both triangles have area 1/2). Vertex 4 is a copy of vertex 0 (same
    // position, normal and uv) used by B: it welds with vertex 0 and gets the same tangent.
    const std::vector<Vec3> p = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 1, 0), Vec3(0, 0, 0), Vec3(-1, 1, 0)};
    const std::vector<Vec3> n(p.size(), Vec3(0, 0, 1));
    const std::vector<Vec2> uv = {Vec2(0, 0), Vec2(1, 0), Vec2(0, 1), Vec2(1, 0), Vec2(0, 0), Vec2(1, 1)};
    const std::vector<Vec4> t = generateTangents(p, n, uv, {glm::uvec3(0, 1, 2), glm::uvec3(4, 3, 5)});
    const Vec3 expected = Vec3(2, 1, 0) / std::sqrt(5.f);
    for (int v : {0, 4}) {
        INFO("vertex " << v);
        CHECK(t[size_t(v)].x == Approx(expected.x).margin(1e-6));
        CHECK(t[size_t(v)].y == Approx(expected.y).margin(1e-6));
        CHECK(t[size_t(v)].z == Approx(0.0).margin(1e-6));
        CHECK(t[size_t(v)].w == -1.f);
    }
    // Unshared vertices keep their own triangle's tangent.
    CHECK(t[1].x == Approx(1.0).margin(1e-6));
    CHECK(t[3].y == Approx(1.0).margin(1e-6));
    CHECK(t[5].y == Approx(1.0).margin(1e-6));
}

TEST_CASE("Normal maps: generated tangents are orthogonal to curved normals and survive degenerate uv", "[normalmap]") {
    // Normals tilted away from the face: the tangent is dp/du projected onto the normal's plane.
    const std::vector<Vec3> p = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
    const Vec3 tilted = glm::normalize(Vec3(0.3f, 0.1f, 1.f));
    const std::vector<Vec2> uv = {Vec2(0, 1), Vec2(1, 1), Vec2(0, 0)};
    const std::vector<Vec4> t = generateTangents(p, {tilted, tilted, tilted}, uv, {glm::uvec3(0, 1, 2)});
    const Vec3 expected = glm::normalize(Vec3(1, 0, 0) - tilted * tilted.x);
    for (const Vec4& v : t) {
        CHECK(glm::dot(Vec3(v), tilted) == Approx(0.0).margin(1e-6));
        CHECK(glm::length(Vec3(v) - expected) == Approx(0.0).margin(1e-6));
        CHECK(v.w == 1.f);
    }
    // All uv equal: no tangent can be derived; a unit vector orthogonal to the normal, w = +1.
    const std::vector<Vec4> d = generateTangents(p, {tilted, tilted, tilted}, {Vec2(0.5f), Vec2(0.5f), Vec2(0.5f)}, {glm::uvec3(0, 1, 2)});
    for (const Vec4& v : d) {
        CHECK(glm::length(Vec3(v)) == Approx(1.0).margin(1e-6));
        CHECK(glm::dot(Vec3(v), tilted) == Approx(0.0).margin(1e-6));
        CHECK(v.w == 1.f);
    }
}

TEST_CASE("Normal maps: the perturbation formula", "[normalmap]") {
    const Vec3 n(0, 0, 1), ng(0, 0, 1), t(1, 0, 0);
    // Texel (0.5, 0.5, 1) is the map's +z: ns unchanged, bit for bit; so is scale 0.
    const Vec3 bent = glm::normalize(Vec3(0.1f, -0.2f, 1.f));
    CHECK(applyNormalMap(bent, ng, t, 1.f, Vec3(0.5f, 0.5f, 1.f), 1.f) == bent);
    CHECK(applyNormalMap(bent, ng, t, 1.f, Vec3(0.9f, 0.1f, 0.7f), 0.f) == bent);
    // A tilt by theta about the bitangent: tangent-space (sin, 0, cos) -> T sin + N cos.
    const double th = 0.6;
    const Vec3 texel(float(0.5 * (std::sin(th) + 1.0)), 0.5f, float(0.5 * (std::cos(th) + 1.0)));
    const Vec3 r = applyNormalMap(n, ng, t, 1.f, texel, 1.f);
    CHECK(r.x == Approx(std::sin(th)).margin(1e-6));
    CHECK(r.y == Approx(0.0).margin(1e-7));
    CHECK(r.z == Approx(std::cos(th)).margin(1e-6));
    // Green goes along B = sign cross(N, T): +y for sign +1, -y for sign -1.
    CHECK(applyNormalMap(n, ng, t, 1.f, Vec3(0.5f, 0.8f, 0.9f), 1.f).y > 0.1f);
    CHECK(applyNormalMap(n, ng, t, -1.f, Vec3(0.5f, 0.8f, 0.9f), 1.f).y < -0.1f);
    // scale multiplies x and y before normalising: scale 2 on (0.25, 0, 1) ~ (0.5, 0, 1).
    const Vec3 s = applyNormalMap(n, ng, t, 1.f, Vec3(0.625f, 0.5f, 1.f), 2.f);
    CHECK(s.x / s.z == Approx(0.5).epsilon(1e-6));
    // The tangent need not be unit or orthogonal to n: it is orthogonalised first.
    const Vec3 r2 = applyNormalMap(n, ng, Vec3(3.f, 0.f, 2.f), 1.f, texel, 1.f);
    CHECK(glm::length(r2 - r) == Approx(0.0).margin(1e-6));
    // Below the geometric plane, a tangent along n, or a non-finite texel: n is kept.
    CHECK(applyNormalMap(n, ng, t, 1.f, Vec3(1.f, 0.5f, 0.5f), 1.f) == n);  // (1, 0, 0): in the plane
    CHECK(applyNormalMap(n, ng, t, 1.f, Vec3(1.f, 0.5f, 0.2f), 1.f) == n);  // below it
    CHECK(applyNormalMap(n, ng, Vec3(0, 0, 2), 1.f, texel, 1.f) == n);
    CHECK(applyNormalMap(n, ng, t, 1.f, Vec3(std::nanf(""), 0.5f, 1.f), 1.f) == n);
    // A shading normal already tilted from ng: the map tilts it further, in its own frame.
    const Vec3 n2 = glm::normalize(Vec3(0.f, 0.3f, 1.f));
    const Vec3 r3 = applyNormalMap(n2, ng, t, 1.f, texel, 1.f);
    CHECK(glm::dot(r3, n2) == Approx(std::cos(th)).margin(1e-6));
    CHECK(glm::length(r3) == Approx(1.0).margin(1e-6));
}

// ----- the loader

namespace {

// A 2x2 quad at z = 0 facing +z, uv = (x, 1 - y) on [-1,1]^2 -> [0,1]^2, with a normal-mapped
// Lambert material whose map is one RGB8 texel; optionally a TANGENT attribute and a node transform.
Doc normalMappedQuad(const std::array<int, 3>& texel, double scale, bool withTangents, const json& node = json::object(),
                     bool withMap = true) {
    Doc d;
    const int mat = d.lambert({0.5, 0.5, 0.5});
    if (withMap) {
        const auto png = makePng(1, 1, 3, 8, {uint16_t(texel[0]), uint16_t(texel[1]), uint16_t(texel[2])});
        d.j["images"] = json::array({json{{"uri", "data:image/png;base64," + base64(png)}}});
        d.j["textures"] = json::array({json{{"source", 0}}});
        d.j["materials"][size_t(mat)]["normalTexture"] = {{"index", 0}, {"scale", scale}};
    }
    const int pos = d.floats({-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0}, "VEC3");
    const int nrm = d.floats({0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}, "VEC3");
    const int uv = d.floats({0, 1, 1, 1, 1, 0, 0, 0}, "VEC2");
    const int idx = d.indices(std::vector<uint16_t>{0, 1, 2, 0, 2, 3});
    json prim = Doc::prim(pos, idx, nrm, uv, 4, mat);
    if (withTangents) prim["attributes"]["TANGENT"] = d.floats({0, 1, 0, -1, 0, 1, 0, -1, 0, 1, 0, -1, 0, 1, 0, -1}, "VEC4");
    json n = node;
    n["mesh"] = d.mesh(prim);
    d.node(n);
    return d;
}

Scene loadDoc(const Doc& d, const std::string& name, int w = 16, int h = 16) {
    LoadOptions o;
    o.width = w;
    o.height = h;
    return loadGltfScene(d.write(name), o);
}

}  // namespace

TEST_CASE("Normal maps: the loader reads normalTexture and scale, TANGENT, or generates tangents", "[normalmap][gltf]") {
    SECTION("generated, with a node rotation and a mirror") {
        const Scene s = loadDoc(normalMappedQuad({200, 128, 255}, 0.7, false), "nm-generated.gltf");
        REQUIRE(s.materials.size() == 1);
        CHECK(s.materials[0].normalTexture.valid());
        CHECK(s.materials[0].normalScale == 0.7f);
        for (const std::string& w : s.info.warnings) CHECK(w.find("normalTexture") == std::string::npos);
        REQUIRE(s.mesh.tangents.size() == s.mesh.positions.size());
        for (const Vec4& t : s.mesh.tangents) CHECK(t == Vec4(1, 0, 0, 1));
        // Rotated by 90 degrees about z: the tangent turns with the surface.
        const double k = std::sqrt(0.5);
        const Scene r = loadDoc(normalMappedQuad({200, 128, 255}, 1.0, false, {{"rotation", {0, 0, k, k}}}), "nm-rotated.gltf");
        for (const Vec4& t : r.mesh.tangents) {
            CHECK(t.x == Approx(0.0).margin(1e-6));
            CHECK(t.y == Approx(1.0).margin(1e-6));
            CHECK(t.w == 1.f);
        }
        // Mirrored in x: T = (-1, 0, 0) and the handedness flips (the bitangent must stay M B = -dp/dv).
        const Scene m = loadDoc(normalMappedQuad({200, 128, 255}, 1.0, false, {{"scale", {-1, 1, 1}}}), "nm-mirror.gltf");
        for (const Vec4& t : m.mesh.tangents) CHECK(t == Vec4(-1, 0, 0, -1));
    }
    SECTION("TANGENT attribute") {
        const Scene s = loadDoc(normalMappedQuad({200, 128, 255}, 1.0, true), "nm-tangent.gltf");
        REQUIRE(s.mesh.tangents.size() == 4);
        for (const Vec4& t : s.mesh.tangents) CHECK(t == Vec4(0, 1, 0, -1));
    }
    SECTION("no normal map: no tangents") {
        const Scene s = loadDoc(normalMappedQuad({0, 0, 0}, 1.0, true, json::object(), false), "nm-none.gltf");
        CHECK(s.mesh.tangents.empty());
        CHECK_FALSE(s.materials[0].normalTexture.valid());
    }
}

// ----- rendering

namespace {

// The quad seen from straight above (camera at z = 3, looking down -z, 30 degree field of view:
// every pixel sees the quad), under a constant environment of radiance 1.
Doc withCamera(Doc d) {
    d.j["cameras"] = json::array({json{{"type", "perspective"}, {"perspective", {{"yfov", 0.5}, {"znear", 0.01}}}}});
    d.node({{"camera", 0}, {"translation", {0, 0, 3}}});
    return d;
}

Scene litScene(const Doc& d, const std::string& name) {
    Scene s = loadDoc(withCamera(d), name);
    s.setEnvironment(Rgb(1.f));
    s.finalize();
    return s;
}

bool identicalFilms(const Film& a, const Film& b) {
    for (int y = 0; y < a.height(); ++y)
        for (int x = 0; x < a.width(); ++x)
            if (!(a.sum(x, y) == b.sum(x, y) && a.sumSquares(x, y) == b.sumSquares(x, y))) return false;
    return true;
}

}  // namespace

TEST_CASE("Normal maps: a flat map renders bit-identically to no map", "[normalmap][render]") {
    // The glTF formula n = normalize((2 c - 1) (s, s, 1)) is +z exactly only for c = (0.5, 0.5, 1),
    // which no UNORM texel holds (128/255 = 0.50196: an 8-bit "flat" texel tilts by 0.32 deg,
    // docs/materials.md). Flat maps are therefore (a) scale 0, any texels, straight from glTF, and
    // (b) texels exactly (0.5, 0.5, 1), set in the decoded texture.
    const Scene none = litScene(normalMappedQuad({0, 0, 0}, 1.0, false, json::object(), false), "flat-none.gltf");
    const Scene scaled0 = litScene(normalMappedQuad({220, 40, 200}, 0.0, false), "flat-scale0.gltf");
    Scene exact = loadDoc(withCamera(normalMappedQuad({128, 128, 255}, 1.0, false)), "flat-exact.gltf");
    REQUIRE(exact.textures.size() == 1);
    {
        const bdptref::Texture& t = exact.textures[0];
        bdptref::Texture flat = bdptref::Texture::fromLinear(
            t.width, t.height, std::vector<Vec4>(size_t(t.width) * size_t(t.height), Vec4(0.5f, 0.5f, 1.f, 1.f)));
        flat.wrapS = t.wrapS;
        flat.wrapT = t.wrapT;
        flat.nearest = t.nearest;
        exact.textures[0] = std::move(flat);
    }
    exact.setEnvironment(Rgb(1.f));
    exact.finalize();
    const Scene eightBit = litScene(normalMappedQuad({128, 128, 255}, 1.0, false), "flat-8bit.gltf");
    for (const char* integrator : {"path", "bdpt"}) {
        INFO(integrator);
        const Film a = renderFilm(none, integrator, 4, 4, 11);
        CHECK(identicalFilms(a, renderFilm(scaled0, integrator, 4, 4, 11)));
        CHECK(identicalFilms(a, renderFilm(exact, integrator, 4, 4, 11)));
        // Not vacuous: the 8-bit (128, 128, 255) texel does perturb the normal (slightly).
        CHECK_FALSE(identicalFilms(a, renderFilm(eightBit, integrator, 4, 4, 11)));
    }
}

TEST_CASE("Normal maps: a constant tilted map on a Lambert plane under a constant environment gives rho L (1 + cos theta) / 2",
          "[normalmap][render]") {
    // docs/materials.md, "Normal maps": with the shading normal tilted by theta from ng, a Lambert
    // surface reflects only directions above both the shading and the geometric plane, whose
    // projected solid angle about ns is pi (1 + cos theta) / 2; so L_o = rho L (1 + cos theta) / 2
    // for every view with wo . ns > 0 (all pixels here). The texel (230, 128, 180) decodes to
    // n_ts = normalize(2 c / 255 - 1): cos theta = n_ts.z (the plane's frame is orthonormal).
    const int r = 230, g = 128, b = 180;
    const double x = 2.0 * r / 255.0 - 1.0, y = 2.0 * g / 255.0 - 1.0, z = 2.0 * b / 255.0 - 1.0;
    const double cosTheta = z / std::sqrt(x * x + y * y + z * z);
    const double expected = 0.5 * (1.0 + cosTheta) * 0.5;  // rho = 0.5, L = 1
    const Scene s = litScene(normalMappedQuad({r, g, b}, 1.0, false), "tilted.gltf");
    const PooledMean m = pooledMean(renderFilm(s, "path", 256, 3, 5));
    constexpr double kSigmas = 5.0;  // fixed seed; k = 5 standard errors of the pooled mean
    INFO("cos theta " << cosTheta << ", expected " << expected << ", got " << m.mean.x << " +- " << m.standardError.x);
    for (int c = 0; c < 3; ++c) CHECK(std::abs(m.mean[c] - expected) <= kSigmas * m.standardError[c]);
    // Power: the unperturbed answer rho L = 0.5 and the "whole shading hemisphere" answer are
    // many standard errors away.
    CHECK(std::abs(m.mean.x - 0.5) > 20.0 * m.standardError.x);
}

TEST_CASE("Normal maps: a malformed TANGENT attribute is an input error naming it", "[normalmap][gltf]") {
    Doc d = normalMappedQuad({200, 128, 255}, 1.0, true);
    // TANGENT pointing at the VEC3 NORMAL accessor: wrong type.
    json& attrs = d.j["meshes"][0]["primitives"][0]["attributes"];
    attrs["TANGENT"] = attrs["NORMAL"];
    try {
        (void)loadDoc(d, "nm-bad-tangent.gltf");
        FAIL("no InputError");
    } catch (const InputError& e) {
        const std::string msg = e.what();
        INFO(msg);
        CHECK(msg.find("TANGENT") != std::string::npos);
        CHECK(msg.find("nm-bad-tangent.gltf") != std::string::npos);
    }
}
