#include "bdptref/scene.h"

#include "bdptref/errors.h"
#include "core/ray_offset.h"
#include "scene/accel.h"
#include "scene/alpha.h"
#include "scene/normal_map.h"
#include "scene/ray_counters.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <mutex>

namespace bdptref {

struct Scene::LazyLightTree {
    std::once_flag built;
    LightTree tree;
};

Scene::Scene() = default;
Scene::~Scene() = default;
Scene::Scene(Scene&&) noexcept = default;
Scene& Scene::operator=(Scene&&) noexcept = default;

void Scene::setEnvironment(const Rgb& L) {
    if (!(isFinite(L) && L.r >= 0.f && L.g >= 0.f && L.b >= 0.f))
        throw InputError("environment radiance must be finite and non-negative");
    hasEnvironment_ = !isBlack(L);
    envRadiance_ = L;
    envMapIndex_ = -1;
    envName_ = "the environment (--env)";
}

void Scene::setEnvironmentMap(EnvironmentMap map, float scale, const std::string& name) {
    if (!(std::isfinite(scale) && scale > 0.f)) throw InputError(name + ": the scale must be a finite number > 0");
    if (!map.valid()) throw InputError(name + ": the map is empty");
    // The brightest radiance scale x texel must stay within the limit every light has
    // (docs/lights.md, "Limits"); finalize() checks only the scale.
    double brightest = 0.0;
    for (int y = 0; y < map.height(); ++y)
        for (int x = 0; x < map.width(); ++x)
            for (int c = 0; c < 3; ++c) brightest = std::max(brightest, double(map.texel(x, y)[c]) * double(scale));
    if (!(brightest <= 1e25))
        throw InputError(name + ": radiance " + std::to_string(brightest) + " (scale x brightest texel) exceeds the renderer's limit of 1e25");
    environmentMaps.push_back(std::move(map));
    envMapIndex_ = int(environmentMaps.size()) - 1;
    hasEnvironment_ = true;
    envRadiance_ = Rgb(scale);
    envName_ = name;
}

namespace {
// p - origin rounded to float; InputError when it does not fit (a float minus a float can reach
// 2 FLT_MAX, and converting that to float is undefined behaviour).
Vec3 relativeTo(const DVec3& p, const DVec3& origin, const std::string& who) {
    const DVec3 d = p - origin;
    constexpr double kMax = double(std::numeric_limits<float>::max());
    if (!(std::abs(d.x) <= kMax && std::abs(d.y) <= kMax && std::abs(d.z) <= kMax))
        throw InputError(who + ": a position is out of float range relative to the camera");
    return Vec3(d);
}
}  // namespace

// The limits of docs/lights.md, "Limits". A path multiplies what a light emits by 1/pdf, 1/d^2,
// the camera's importance and 1/(selection probability) in single precision (FLT_MAX 3.4e38);
// keeping emission and total power at or below 1e25 leaves 13 decades for those factors, where a
// larger value would overflow to Inf, be dropped as a non-finite sample and leave a black image.
constexpr double kMaxLightValue = 1e25;

namespace {
std::string num(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return buf;
}
}  // namespace

void Scene::checkLightPowers(const std::vector<Light>& all, const std::vector<std::string>& names) {
    auto fail = [&](size_t i, const std::string& what) { throw InputError(info.path + ": " + names[i] + ": " + what); };
    double total = 0.0;
    size_t brightest = 0;
    for (size_t i = 0; i < all.size(); ++i) {
        const Light& l = all[i];
        for (int c = 0; c < 3; ++c)
            if (!(double(l.emission[c]) <= kMaxLightValue))
                fail(i, std::string(l.type == LightType::Area || l.type == LightType::Environment ? "radiance "
                                    : l.type == LightType::Directional                              ? "irradiance "
                                                                                                    : "intensity ") +
                            num(double(l.emission[c])) + " exceeds the renderer's limit of 1e25 (single-precision range; docs/lights.md)");
        for (int c = 0; c < 3; ++c)
            if (l.emission[c] > 0.f && l.emission[c] < std::numeric_limits<float>::min())
                fail(i, "emission " + num(double(l.emission[c])) + " is below the smallest normal float (1.2e-38); the render "
                        "threads flush such values to zero (FTZ/DAZ), so the light would be missing; scale the lights up");
        if (!std::isfinite(l.power)) fail(i, "its power is not finite");
        total += l.power;
        if (l.power > all[brightest].power) brightest = i;
    }
    if (!(total <= kMaxLightValue))
        fail(brightest, "the lights' total power " + num(total) +
                            " exceeds the renderer's limit of 1e25 (single-precision range; docs/lights.md); scale the lights down");
    size_t dark = 0, unreachableArea = 0;
    for (size_t i = 0; i < all.size(); ++i) {
        const Light& l = all[i];
        // The selection probability is a float (FTZ/DAZ in render threads): below FLT_MIN it is 0.
        if (l.power > 0.0 && float(l.power / total) >= std::numeric_limits<float>::min()) continue;
        if (isBlack(l.emission)) {
            ++dark;
            info.warnings.push_back(names[i] + ": emits nothing (black colour or intensity 0); ignored");
        } else if (isDeltaPosition(l) || isDeltaDirection(l)) {
            // Nothing can hit a point or directional light: never selected means missing from the image.
            fail(i, l.power > 0.0 ? "its power " + num(l.power) + " is too small next to the lights' total " + num(total) +
                                        " to be selected in single precision, so it would be missing from the image; scale the "
                                        "lights to a common range"
                                  : "it emits no power in single precision (a spot cone narrower than float can represent?), so "
                                    "it could never be selected and would be missing from the image");
        } else {
            ++unreachableArea;
        }
    }
    if (unreachableArea)
        info.warnings.push_back(std::to_string(unreachableArea) +
                                " area or environment light(s) have too little power next to the others to be chosen by light "
                                "sampling; only paths that hit them see them (noisier, still unbiased)");
    if (all.size() == dark)
        info.warnings.push_back("the scene has no lights; the image will be black (light it with a constant environment, "
                                "--env R,G,B, e.g. --env 1,1,1, or add emissive materials or KHR_lights_punctual lights)");
}

Vec3 Scene::toRender(const DVec3& world) const { return relativeTo(world, worldOrigin, info.path); }

void Scene::moveOriginToCamera() {
    // Render space is centred on the camera (pbrt-v4's "camera-world" space): float spacing is
    // then finest where the picture is made, and a scene far from the world origin (a translation
    // by 1e5: spacing 1/128) renders like the same scene near it. The shift is the camera's float
    // position, so the camera lands exactly at 0 and worldOrigin is exact; each coordinate is
    // subtracted in double (exact for floats) and rounded to float once.
    const Vec3 eye = camera.position();
    if (!isFinite(eye)) throw InputError(info.path + ": the camera position is not finite");
    if (eye == Vec3(0.f)) return;
    const DVec3 shift(eye);
    auto move = [&](Vec3& p) { p = relativeTo(DVec3(p), shift, info.path); };
    // Into copies first: a position out of range throws and leaves the scene as it was.
    std::vector<Vec3> positions = mesh.positions;
    std::vector<Light> movedLights = lights;
    for (Vec3& p : positions) move(p);
    for (Light& l : movedLights) {
        move(l.position);  // point / spot (unused, and harmless, for the others)
        for (Vec3* v : {&l.v0, &l.v1, &l.v2}) move(*v);
    }
    mesh.positions = std::move(positions);
    lights = std::move(movedLights);
    camera = camera.withPosition(Vec3(0.f));
    worldOrigin += shift;
}

void Scene::finalize() {
    const size_t nTri = mesh.triangleCount();
    if (mesh.triangleMaterial.size() != nTri) throw InputError(info.path + ": internal: triangle material table has the wrong size");
    moveOriginToCamera();
    absorptionFree_ = std::none_of(materials.begin(), materials.end(), [](const Material& m) { return !isBlack(m.absorption); });

    // Bounds of the geometry (punctual lights and the camera count when there is no geometry).
    boundsMin_ = Vec3(kInfinity);
    boundsMax_ = Vec3(-kInfinity);
    for (const glm::uvec3& tri : mesh.indices)
        for (int k = 0; k < 3; ++k) {
            boundsMin_ = glm::min(boundsMin_, mesh.positions[tri[k]]);
            boundsMax_ = glm::max(boundsMax_, mesh.positions[tri[k]]);
        }
    if (nTri == 0) {
        for (const Light& l : lights)
            if (isDeltaPosition(l)) {
                boundsMin_ = glm::min(boundsMin_, l.position);
                boundsMax_ = glm::max(boundsMax_, l.position);
            }
        boundsMin_ = glm::min(boundsMin_, camera.position());
        boundsMax_ = glm::max(boundsMax_, camera.position());
    }
    center_ = 0.5f * (boundsMin_ + boundsMax_);
    radius_ = std::max(glm::length(boundsMax_ - center_), 1e-3f);

    // Area lights first (one per emissive triangle), then the punctual lights, then the environment.
    std::vector<Light> all;
    std::vector<std::string> names;
    mesh.triangleLight.assign(nTri, -1);
    for (size_t i = 0; i < nTri; ++i) {
        const Material& m = materials.at(mesh.triangleMaterial[i]);
        if (isBlack(m.emission)) continue;
        if (needsAlphaTest(m, !mesh.colors.empty()))  // the glTF loader refuses these with the file's names; this guards hand-built scenes
            throw InputError(info.path + ": material " + std::to_string(mesh.triangleMaterial[i]) +
                             " is emissive and alpha-tested (MASK/BLEND); emission through partial coverage is not supported");
        const glm::uvec3 tri = mesh.indices[i];
        Light l;
        l.type = LightType::Area;
        l.v0 = mesh.positions[tri.x];
        l.v1 = mesh.positions[tri.y];
        l.v2 = mesh.positions[tri.z];
        const Vec3 c = glm::cross(l.v1 - l.v0, l.v2 - l.v0);
        const float len = glm::length(c);
        if (!(len > 0.f) || !std::isfinite(len)) continue;  // zero-area triangles emit nothing
        l.normal = c / len;
        l.area = 0.5f * len;
        l.emission = m.emission;
        if (m.emissiveTexture.valid()) {  // the triangle's uvs of the texture's set (zero where the mesh lacks it)
            l.emissiveTexture = m.emissiveTexture;
            const size_t set = size_t(m.emissiveTexture.texCoord);
            if (set < mesh.uvSets.size() && mesh.uvSets[set].size() == mesh.positions.size()) {
                l.uv0 = mesh.uvSets[set][tri.x];
                l.uv1 = mesh.uvSets[set][tri.y];
                l.uv2 = mesh.uvSets[set][tri.z];
            }
        }
        l.twoSided = m.doubleSided;
        l.triangle = uint32_t(i);
        mesh.triangleLight[i] = int32_t(all.size());
        all.push_back(l);
        names.push_back("emissive triangle " + std::to_string(i) + " (material " + std::to_string(mesh.triangleMaterial[i]) +
                        (m.name.empty() ? "" : " '" + m.name + "'") + ")");
    }
    for (size_t j = 0; j < lights.size(); ++j) {
        const Light& l = lights[j];
        if (l.type == LightType::Area || l.type == LightType::Environment) continue;
        all.push_back(l);
        names.push_back(j < lightNames.size() ? lightNames[j] : std::string(lightTypeName(l.type)) + " light " + std::to_string(j));
    }
    envLight_ = -1;
    if (hasEnvironment_) {
        Light env;
        env.type = LightType::Environment;
        env.emission = envRadiance_;
        env.envMap = envMapIndex_;
        envLight_ = int(all.size());
        all.push_back(env);
        names.push_back(envName_);
    }
    for (Light& l : all) {
        l.sceneCenter = center_;
        l.sceneRadius = radius_;
        l.power = lightPower(l, *this);
    }
    checkLightPowers(all, names);
    lights = std::move(all);
    lightNames = std::move(names);
    lightSampler_ = LightSampler(lights);
    lightTree_ = std::make_unique<LazyLightTree>();  // built from `lights` on first use (lightTree())

    // Alpha-tested triangles (MASK / BLEND) get Embree's filter functions; the others none.
    std::vector<uint8_t> alphaTested;
    for (size_t i = 0; i < nTri; ++i)
        if (needsAlphaTest(materials.at(mesh.triangleMaterial[i]), !mesh.colors.empty())) {
            if (alphaTested.empty()) alphaTested.assign(nTri, 0);
            alphaTested[i] = 1;
        }
    accel_ = std::make_unique<Accel>(mesh.positions, mesh.indices, alphaTested);
    buildUniformBsdfs();
}

const LightTree& Scene::lightTree() const {
    static const LightTree none;
    if (!lightTree_) return none;
    std::call_once(lightTree_->built, [this] { lightTree_->tree = LightTree(lights); });
    return lightTree_->tree;
}

void Scene::buildUniformBsdfs() {
    // Vertex colours multiply the base colour: every material varies with them.
    const bool colours = !mesh.colors.empty();
    uniformBsdfs_.assign(materials.size(), Bsdf());
    uniformBsdf_.assign(materials.size(), 0);
    for (size_t i = 0; i < materials.size(); ++i) {
        const Material& m = materials[i];
        const TextureRef* used[] = {&m.baseColorTexture,  &m.metallicRoughnessTexture, &m.normalTexture,
                                    &m.transmissionTexture, &m.specularTexture,        &m.specularColorTexture,
                                    &m.clearcoatTexture,  &m.clearcoatRoughnessTexture, &m.clearcoatNormalTexture,
                                    &m.sheenColorTexture, &m.sheenRoughnessTexture};
        const bool textured = std::any_of(std::begin(used), std::end(used), [](const TextureRef* t) { return t->valid(); });
        // resolveMaterial at no point: COLOR_0 = 1 multiplies exactly, as at every point of a mesh without colours.
        const MaterialParams p = resolveMaterial(m, textures, SurfaceAttributes{});
        if (colours || textured || p.clearcoat > 0.f) continue;  // the coat's normal defaults to the shading normal
        uniformBsdfs_[i] = Bsdf(p, Vec3(0.f), Vec3(0.f));
        uniformBsdf_[i] = 1;
    }
}

Bsdf Scene::bsdfAt(uint32_t material, uint32_t triangle, Vec2 bary, const Vec3& ns, const Vec3& ng) const {
    if (material < uniformBsdf_.size() && uniformBsdf_[material]) return uniformBsdfs_[material].atNormals(ns, ng);
    return Bsdf(materialParams(material, triangle, bary), ns, ng);
}

namespace {
// The coverage test the intersection layer asks at candidate hits on alpha-tested triangles.
bool sceneCovers(const void* user, uint32_t triangle, Vec2 barycentrics, const Vec3& origin, const Vec3& dir) {
    return surfaceCovers(*static_cast<const Scene*>(user), triangle, barycentrics, origin, dir);
}
}  // namespace

CoverageTest Scene::coverageTest() const { return CoverageTest{this, sceneCovers}; }

namespace {
// The interpolated vertex normal on ng's side (the winding defines the front), or ng where a
// vertex has no normal or the interpolation has no length.
Vec3 interpolatedNormal(const TriangleMesh& mesh, const glm::uvec3& tri, float b0, float b1, float b2, const Vec3& ng) {
    if (!(mesh.vertexHasNormal[tri.x] && mesh.vertexHasNormal[tri.y] && mesh.vertexHasNormal[tri.z])) return ng;
    const Vec3 n = b0 * mesh.normals[tri.x] + b1 * mesh.normals[tri.y] + b2 * mesh.normals[tri.z];
    const float len = glm::length(n);
    if (!(len > 0.f && std::isfinite(len))) return ng;
    const Vec3 ns = n / len;
    return glm::dot(ns, ng) < 0.f ? -ns : ns;
}
}  // namespace

bool Scene::intersect(const Ray& ray, SurfaceHit* hit) const {
    countRay(threadRayCounters().extension);
    EmbreeHit h;
    if (!accel_->intersect(ray, &h, coverageTest())) return false;
    surfaceHitOf(h, hit);
    return true;
}

void Scene::intersectStream(const Ray* const* rays, uint32_t n, SurfaceHit* const* hits, bool* found) const {
    EmbreeHit h[Accel::kStreamMax];
    for (uint32_t begin = 0; begin < n; begin += Accel::kStreamMax) {
        const uint32_t m = std::min(n - begin, Accel::kStreamMax);
        for (uint32_t i = 0; i < m; ++i) countRay(threadRayCounters().extension);
        accel_->intersectStream(rays + begin, m, h, found + begin, coverageTest());
        for (uint32_t i = 0; i < m; ++i)
            if (found[begin + i]) surfaceHitOf(h[i], hits[begin + i]);
    }
}

// What intersect() returns for Embree's hit h: the surface's position, normals, material and light.
void Scene::surfaceHitOf(const EmbreeHit& h, SurfaceHit* hit) const {
    const glm::uvec3 tri = mesh.indices[h.triangle];
    const float b1 = h.u, b2 = h.v, b0 = 1.f - h.u - h.v;
    const Vec3& p0 = mesh.positions[tri.x];
    const Vec3& p1 = mesh.positions[tri.y];
    const Vec3& p2 = mesh.positions[tri.z];
    // Interpolating the vertices is more accurate than origin + t*dir far from the origin.
    hit->p = b0 * p0 + b1 * p1 + b2 * p2;
    hit->ng = glm::normalize(glm::cross(p1 - p0, p2 - p0));
    hit->ns = interpolatedNormal(mesh, tri, b0, b1, b2, hit->ng);
    // Normal map (docs/materials.md, "Normal maps"): perturbs ns in the interpolated tangent frame.
    const Material& hitMaterial = materials[mesh.triangleMaterial[h.triangle]];
    if (hitMaterial.normalTexture.valid() && mesh.tangents.size() == mesh.positions.size()) {
        const Vec4 tangent = b0 * mesh.tangents[tri.x] + b1 * mesh.tangents[tri.y] + b2 * mesh.tangents[tri.z];
        const Vec4 texel = sampleTexture(hitMaterial.normalTexture, textures, attributes(h.triangle, Vec2(b1, b2)));
        hit->ns = applyNormalMap(hit->ns, hit->ng, Vec3(tangent), tangent.w, Vec3(texel), hitMaterial.normalScale);
    }
    hit->bary = Vec2(b1, b2);
    hit->t = h.t;
    hit->triangle = h.triangle;
    hit->material = mesh.triangleMaterial[h.triangle];
    hit->light = mesh.triangleLight.empty() ? -1 : mesh.triangleLight[h.triangle];
}

SurfaceAttributes Scene::attributes(uint32_t triangle, Vec2 bary) const {
    SurfaceAttributes a;
    if (triangle >= mesh.indices.size()) return a;
    const glm::uvec3 tri = mesh.indices[triangle];
    const float b1 = bary.x, b2 = bary.y, b0 = 1.f - b1 - b2;
    const size_t sets = std::min(mesh.uvSets.size(), size_t(kMaxTexCoordSets));
    for (size_t s = 0; s < sets; ++s) {
        const std::vector<Vec2>& uv = mesh.uvSets[s];
        if (uv.size() == mesh.positions.size()) a.uv[s] = b0 * uv[tri.x] + b1 * uv[tri.y] + b2 * uv[tri.z];
    }
    if (mesh.colors.size() == mesh.positions.size())
        a.color = b0 * mesh.colors[tri.x] + b1 * mesh.colors[tri.y] + b2 * mesh.colors[tri.z];
    return a;
}

MaterialParams Scene::materialParams(uint32_t material, uint32_t triangle, Vec2 bary) const {
    const Material& m = materials.at(material);
    const SurfaceAttributes at = attributes(triangle, bary);
    MaterialParams p = resolveMaterial(m, textures, at);
    // The coat's normal differs from the shading normal only under a normal map of either layer
    // (KHR_materials_clearcoat: the base's normalTexture does not perturb the coat).
    if (p.clearcoat > 0.f && (m.normalTexture.valid() || m.clearcoatNormalTexture.valid()) && triangle < mesh.indices.size()) {
        const glm::uvec3 tri = mesh.indices[triangle];
        const float b1 = bary.x, b2 = bary.y, b0 = 1.f - b1 - b2;
        const Vec3& p0 = mesh.positions[tri.x];
        const Vec3 ng = glm::normalize(glm::cross(mesh.positions[tri.y] - p0, mesh.positions[tri.z] - p0));
        Vec3 nc = interpolatedNormal(mesh, tri, b0, b1, b2, ng);
        if (m.clearcoatNormalTexture.valid() && mesh.tangents.size() == mesh.positions.size()) {
            const Vec4 tangent = b0 * mesh.tangents[tri.x] + b1 * mesh.tangents[tri.y] + b2 * mesh.tangents[tri.z];
            const Vec4 texel = sampleTexture(m.clearcoatNormalTexture, textures, at);
            nc = applyNormalMap(nc, ng, Vec3(tangent), tangent.w, Vec3(texel), m.clearcoatNormalScale);
        }
        p.clearcoatNormal = nc;
    }
    return p;
}

Vec2 Scene::barycentricsOf(uint32_t triangle, const Vec3& p) const {
    if (triangle >= mesh.indices.size()) return Vec2(0.f);
    const glm::uvec3 tri = mesh.indices[triangle];
    // Least-squares solution of p - p0 = b1 e1 + b2 e2 (in double: the Gram matrix is ill-conditioned
    // for slivers).
    const glm::dvec3 p0(mesh.positions[tri.x]);
    const glm::dvec3 e1 = glm::dvec3(mesh.positions[tri.y]) - p0, e2 = glm::dvec3(mesh.positions[tri.z]) - p0;
    const glm::dvec3 d = glm::dvec3(p) - p0;
    const double a11 = glm::dot(e1, e1), a12 = glm::dot(e1, e2), a22 = glm::dot(e2, e2);
    const double r1 = glm::dot(d, e1), r2 = glm::dot(d, e2);
    const double det = a11 * a22 - a12 * a12;
    if (!(std::abs(det) > 0.0)) return Vec2(0.f);
    return Vec2(float((a22 * r1 - a12 * r2) / det), float((a11 * r2 - a12 * r1) / det));
}

namespace {
// Offsets p off its surface to the side of n that `towards` points to (no offset for points in
// space: n == 0).
inline Vec3 offsetTowards(const Vec3& p, const Vec3& n, const Vec3& towards) {
    if (n == Vec3(0.f)) return p;
    return offsetRayOriginInline(p, glm::dot(n, towards) >= 0.f ? n : -n);
}
}  // namespace

Ray Scene::segmentRay(const Vec3& p0, const Vec3& n0, const Vec3& p1, const Vec3& n1) {
    const Vec3 d = p1 - p0;  // -d is p0 - p1 exactly (subtraction rounds symmetrically)
    const Vec3 o = offsetTowards(p0, n0, d);
    const Vec3 e = offsetTowards(p1, n1, -d);
    // Unnormalised direction: t in (0, 1) spans exactly the segment between the offset points.
    return {o, e - o, 1.f};
}

Ray Scene::infinityRay(const Vec3& p0, const Vec3& n0, const Vec3& dir) {
    return {offsetTowards(p0, n0, dir), dir, kInfinity};
}

bool Scene::visible(const Vec3& p0, const Vec3& n0, const Vec3& p1, const Vec3& n1) const {
    countRay(threadRayCounters().shadow);
    const Ray r = segmentRay(p0, n0, p1, n1);
    return !accel_->occluded(r.origin, r.dir, r.tMax, coverageTest());
}

bool Scene::visibleToInfinity(const Vec3& p0, const Vec3& n0, const Vec3& dir) const {
    countRay(threadRayCounters().shadow);
    const Ray r = infinityRay(p0, n0, dir);
    return !accel_->occluded(r.origin, r.dir, r.tMax, coverageTest());
}

void Scene::occludedStream(const Ray* rays, uint32_t n, bool* occluded) const {
    for (uint32_t begin = 0; begin < n; begin += Accel::kStreamMax) {
        const uint32_t m = std::min(n - begin, Accel::kStreamMax);
        for (uint32_t i = 0; i < m; ++i) countRay(threadRayCounters().shadow);
        accel_->occludedStream(rays + begin, m, occluded + begin, coverageTest());
    }
}

}  // namespace bdptref
