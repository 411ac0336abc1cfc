#include "stability/hard_case_scenes.h"

#include "bdptref/gltf_loader.h"
#include "support/gltf_builder.h"

#include <cmath>

namespace bdptref::test {

namespace {

using P = std::array<double, 3>;

P add(const P& a, const P& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }

// Every coordinate of the room scenes is a multiple of 1/64, so a translation by 1e5 (an integer
// below 2^17, where the float spacing is 1/128) moves the geometry EXACTLY: the translated scene
// is the same scene, and any difference in the picture is the renderer's precision.
struct Room {
    Doc d;
    P o{0, 0, 0};  // offset of everything
    int white = -1, red = -1, green = -1;
    explicit Room(const P& offset = {0, 0, 0}, bool ceiling = true) : o(offset) {
        white = d.lambert({0.7, 0.7, 0.7});
        red = d.lambert({0.7, 0.1, 0.1});
        green = d.lambert({0.1, 0.7, 0.1});
        // The room [-1, 1]^3, open at +z (the camera looks in from there), sides facing inwards.
        d.box(add({-1, -1, -1}, o), add({1, 1, 1}, o), white, true, {0, 1, 5, ceiling ? 5 : 3});
        d.box(add({-1, -1, -1}, o), add({1, 1, 1}, o), red, true, {1, 2, 3, 4, 5});
        d.box(add({-1, -1, -1}, o), add({1, 1, 1}, o), green, true, {0, 2, 3, 4, 5});
    }
    // An axis-aligned quad light on the ceiling (facing down), centre (x, z), edge `size`.
    void ceilingLight(double size, double radiance, double x = 0, double z = 0) {
        const int m = d.lambert({0, 0, 0}, {1, 1, 1}, radiance);
        const double h = size / 2, y = 1 - 1.0 / 64;
        d.quad(add({x - h, y, z - h}, o), add({x + h, y, z - h}, o), add({x + h, y, z + h}, o), add({x - h, y, z + h}, o), m);
    }
    Scene load(int w, int h, const P& eye, const P& target, double yfovDegrees = 30) const {
        LoadOptions lo;
        lo.width = w;
        lo.height = h;
        static int serial = 0;
        Scene s = loadGltfScene(d.write("hard-case-" + std::to_string(serial++) + ".gltf"), lo);
        const P e = add(eye, o), t = add(target, o);
        s.camera = Camera::lookAt(Vec3(float(e[0]), float(e[1]), float(e[2])), Vec3(float(t[0]), float(t[1]), float(t[2])),
                                  Vec3(0, 1, 0), float(yfovDegrees * 3.14159265358979323846 / 180.0), w, h);
        return s;
    }
};

const P kEye{0, -0.25, 3.5}, kTarget{0, -0.375, 0};

// A rough glass (KHR_materials_transmission with roughness > 0, ior 1.5).
int roughGlassMaterial(Doc& d, double roughness) {
    d.use("KHR_materials_transmission");
    return d.material({{"pbrMetallicRoughness", {{"baseColorFactor", {1, 1, 1, 1}}, {"metallicFactor", 0}, {"roughnessFactor", roughness}}},
                       {"extensions", {{"KHR_materials_transmission", {{"transmissionFactor", 1.0}}}}}});
}

// A layered material: a sheen (KHR_materials_sheen) over a Lambert-like base under a rough
// clearcoat (KHR_materials_clearcoat): the albedo table lookups of the sheen and the coat's
// Fresnel run on every f, pdf and sample.
int sheenUnderCoatMaterial(Doc& d) {
    d.use("KHR_materials_sheen");
    d.use("KHR_materials_clearcoat");
    return d.material({{"pbrMetallicRoughness", {{"baseColorFactor", {0.6, 0.5, 0.4, 1}}, {"metallicFactor", 0}, {"roughnessFactor", 0.7}}},
                       {"extensions",
                        {{"KHR_materials_sheen", {{"sheenColorFactor", {0.9, 0.8, 0.7}}, {"sheenRoughnessFactor", 0.3}}},
                         {"KHR_materials_clearcoat", {{"clearcoatFactor", 0.5}, {"clearcoatRoughnessFactor", 0.4}}}}}});
}

Scene finalized(Scene s) {
    s.finalize();
    return s;
}

// A cube resting on the floor and touching the red wall, plus a quad exactly coincident with the
// back wall: contact edges where connection vertices nearly coincide (G = cos cos / d^2 blows up).
Scene touching(int w, int h, const P& offset) {
    Room r(offset);
    r.ceilingLight(0.5, 10);
    r.d.box(add({-1, -1, -0.5}, offset), add({-0.5, -0.5, 0}, offset), r.white);  // outward faces
    r.d.quad(add({-0.5, -0.5, -1}, offset), add({0.5, -0.5, -1}, offset), add({0.5, 0.5, -1}, offset),
             add({-0.5, 0.5, -1}, offset), r.white);
    return finalized(r.load(w, h, kEye, kTarget));
}

}  // namespace

std::vector<HardCase> hardCases() {
    std::vector<HardCase> cases;
    const std::vector<std::string> all = {"lt", "bdpt-balance", "bdpt-power"};
    const std::vector<std::string> bdpt = {"bdpt-balance", "bdpt-power"};

    {   // Grazing view (the camera 1/64 above the floor) and a grazing light (a strip emitter on
        // the red wall, 1/32 high, shining along the floor).
        HardCase c;
        c.name = "grazing view and light";
        c.build = [](int w, int h) {
            Room r;
            const int m = r.d.lambert({0, 0, 0}, {1, 1, 1}, 40);
            const double x = -1 + 1.0 / 64, y0 = -1 + 1.0 / 64, y1 = -1 + 3.0 / 64;
            r.d.quad({x, y0, -0.75}, {x, y1, -0.75}, {x, y1, 0.75}, {x, y0, 0.75}, m);  // faces +x
            return finalized(r.load(w, h, {0, -1 + 1.0 / 64, 3.5}, {0, -1 + 1.0 / 64, -1}));
        };
        // PT is unbiased here but heavy-tailed from depth 2 on (the floor right in front of the
        // strip is lit ~1/distance^2 and PT finds it by chance; docs/hard-cases.md): LT is the
        // reference, PT is compared on direct lighting, where it is not heavy-tailed.
        c.reference = "lt";
        c.converging = bdpt;
        c.convergingDirectLighting = {"path"};
        c.referenceSpp = 4096;
        // The strip seen edge-on covers a fraction of a few pixels (samples 0 or 40): that coverage
        // noise sets the image mean's standard error, and 5 sigma < 10% of the mean needs 2048 spp.
        c.spp = 2048;
        cases.push_back(c);
    }
    {   // A light of edge 2e-4 (1e-4 of the room) and radiance 6.25e7: as much power as a 0.5 x 0.5
        // light of radiance 10. Not in view (PT could not find it by camera rays).
        HardCase c;
        c.name = "tiny bright area light";
        c.build = [](int w, int h) {
            Room r;
            r.ceilingLight(2e-4, 10 * 0.25 / 4e-8);
            return finalized(r.load(w, h, kEye, kTarget));
        };
        c.converging = all;
        c.spp = 128;
        cases.push_back(c);
    }
    {   // The floor: GGX metal at roughness 1e-4 (left) next to an exact mirror (right); a light on
        // the back wall whose reflection is in view. LT cannot reach the camera through a
        // (near-)specular bounce.
        HardCase c;
        c.name = "GGX roughness 1e-4 next to a delta mirror";
        c.build = [](int w, int h) {
            Room r;
            const int glossy = r.d.metal({0.9, 0.9, 0.9}, 1e-4), mirror = r.d.metal({0.9, 0.9, 0.9}, 0.0);
            const double y = -1 + 1.0 / 64;
            r.d.quad({-1, y, -1}, {-1, y, 1}, {0, y, 1}, {0, y, -1}, glossy);
            r.d.quad({0, y, -1}, {0, y, 1}, {1, y, 1}, {1, y, -1}, mirror);
            const int m = r.d.lambert({0, 0, 0}, {1, 1, 1}, 10);
            const double z = -1 + 1.0 / 64;
            r.d.quad({-0.5, 0.25, z}, {0.5, 0.25, z}, {0.5, 0.75, z}, {-0.5, 0.75, z}, m);
            return finalized(r.load(w, h, kEye, {0, -1, -1}, 50));
        };
        c.converging = bdpt;
        c.spp = 256;
        // PT at 256 spp is heavy-tailed in the glossy pixels (docs/hard-cases.md: the top 1% of
        // its samples carry 28% of the mean); at 4096 spp its per-pixel t-test is calibrated.
        c.referenceSpp = 4096;
        cases.push_back(c);
    }
    {
        HardCase c;
        c.name = "coincident and touching geometry";
        c.build = [](int w, int h) { return touching(w, h, {0, 0, 0}); };
        c.converging = all;
        c.spp = 128;
        cases.push_back(c);
    }
    {   // The touching scene moved by 1e5 along every axis (exactly: see Room), against PT at the
        // origin. Camera-centred render space makes it the same scene as at the origin
        // (test_translated_scene.cpp asserts bit-identical films); world-space offsets failed here.
        HardCase c;
        c.name = "scene translated by 1e5";
        c.build = [](int w, int h) { return touching(w, h, {1e5, 1e5, 1e5}); };
        c.referenceBuild = [](int w, int h) { return touching(w, h, {0, 0, 0}); };
        c.converging = {"path", "lt", "bdpt-balance", "bdpt-power"};
        c.spp = 128;
        cases.push_back(c);
    }
    {   // Closed box, albedo 0.99, every wall emitting Le = 1, camera inside, max depth 256:
        // L = Le (1 - rho^257) / (1 - rho) in every pixel (docs/contracts.md, contract 5).
        HardCase c;
        c.name = "closed box of albedo 0.99 at max depth 256";
        c.build = [](int w, int h) {
            Doc d;
            d.box({-1, -1, -1}, {1, 1, 1}, d.lambert({0.99, 0.99, 0.99}, {1, 1, 1}), true);
            LoadOptions lo;
            lo.width = w;
            lo.height = h;
            Scene s = loadGltfScene(d.write("closed-box.gltf"), lo);
            s.camera = Camera::lookAt(Vec3(0.1f, 0.2f, 0.3f), Vec3(-1, 0, -0.5f), Vec3(0, 1, 0), 1.2f, w, h);
            return finalized(std::move(s));
        };
        c.maxDepth = 256;
        c.analyticPixel = (1.0 - std::pow(0.99, 257)) / (1.0 - 0.99);
        // BDPT connects every pair of vertices of ~100-vertex subpaths: 2 x 2 pixels keep it fast.
        // 128 spp: since light subpaths play Russian roulette (docs/path-tracer.md) a BDPT sample
        // is cheaper and noisier here; at 64 spp its standard error was 1.01x the precision
        // runHardCase requires (5 se <= 25% of the value); 128 spp take 5.8 CPU-s, 64 before 6.3.
        c.size = 2;
        c.spp = 128;
        cases.push_back(c);
    }
    {   // A point light inside a glass sphere over the floor: every light path leaves through two
        // specular refractions. PT can never connect to it (the shadow ray hits the glass, and a
        // BSDF-sampled ray cannot hit a point): exactly black. LT and BDPT sample L S S D E (the
        // caustic seen directly); at max depth 3 no longer path exists, so both estimate the same
        // image. (Deeper, E S S D S S L is sampled by nobody and E S S D D S S L only by BDPT.)
        HardCase c;
        c.name = "point light seen only through a glass sphere";
        c.build = [](int w, int h) {
            Room r;
            r.d.sphere({0, -0.5, -0.25}, 0.375, r.d.glass(1.5));
            r.d.punctual({{"type", "point"}, {"color", {1, 1, 1}}, {"intensity", 4.0}}, {{"translation", {0, -0.5, -0.25}}});
            return finalized(r.load(w, h, kEye, kTarget));
        };
        c.maxDepth = 3;
        c.reference = "lt";
        c.converging = bdpt;
        c.exactlyBlack = {"path"};
        c.spp = 256;
        cases.push_back(c);
    }
    {   // A spot light whose cone is 0.02 rad wide, pointing down from the ceiling. The lit disk
        // (radius 0.04) is a rare target for camera paths: PT is in the rare-event regime in
        // every pixel, so LT is the reference.
        HardCase c;
        c.reference = "lt";
        c.name = "narrow spot light";
        c.build = [](int w, int h) {
            Room r;
            const float hq = 0.5f * -3.14159265f / 2;  // -z -> -y
            r.d.punctual({{"type", "spot"}, {"color", {1, 1, 1}}, {"intensity", 1000.0}, {"spot", {{"innerConeAngle", 0.01}, {"outerConeAngle", 0.02}}}},
                         {{"translation", {0.25, 0.9, -0.5}}, {"rotation", {std::sin(hq), 0, 0, std::cos(hq)}}});
            return finalized(r.load(w, h, kEye, kTarget));
        };
        c.converging = bdpt;
        c.spp = 256;
        cases.push_back(c);
    }
    {   // Sunlight through the open ceiling.
        HardCase c;
        c.name = "directional light";
        c.build = [](int w, int h) {
            Room r({0, 0, 0}, false);
            const float a = 0.5f * -1.2f;  // about x: -z turned towards -y (and a little towards +z)
            r.d.punctual({{"type", "directional"}, {"color", {1, 1, 1}}, {"intensity", 3.0}}, {{"rotation", {std::sin(a), 0, 0, std::cos(a)}}});
            return finalized(r.load(w, h, kEye, kTarget));
        };
        c.converging = all;
        c.spp = 128;
        cases.push_back(c);
    }
    {   // One-sided emitters facing away from the camera (their backs in view must be black and
        // must not emit), one facing the floor from just above it, and a small two-sided one.
        HardCase c;
        c.name = "back-facing emitters";
        c.build = [](int w, int h) {
            Room r;
            const int one = r.d.lambert({0.5, 0.5, 0.5}, {1, 1, 1}, 8), two = r.d.lambert({0.5, 0.5, 0.5}, {1, 0.5, 0.25}, 8, true);
            // Facing -z (the back wall); the camera sees its back.
            r.d.quad({-0.25, 0, 0}, {-0.25, 0.5, 0}, {0.25, 0.5, 0}, {0.25, 0, 0}, one);
            // Facing -y, 1/64 above the floor.
            const double y = -1 + 1.0 / 64;
            r.d.quad({0.25, y, 0.25}, {0.75, y, 0.25}, {0.75, y, 0.75}, {0.25, y, 0.75}, one);
            r.d.quad({-0.75, 0.5, 0.5}, {-0.5, 0.5, 0.5}, {-0.5, 0.75, 0.5}, {-0.75, 0.75, 0.5}, two);
            return finalized(r.load(w, h, kEye, kTarget));
        };
        c.converging = all;
        c.spp = 512;
        cases.push_back(c);
    }
    {   // The ceiling light's triangles include a sliver (area ~1e-7 of the light's) and, added
        // behind the loader's back (it drops them with a warning), zero-area triangles: collinear
        // and with repeated vertices. Zero-area ones must not become lights; the sliver must not
        // make any density infinite.
        HardCase c;
        c.name = "degenerate and zero-area triangles among the lights";
        c.build = [](int w, int h) {
            Room r;
            r.ceilingLight(0.5, 10);
            const int m = r.d.lambert({0, 0, 0}, {1, 1, 1}, 10);
            const double y = 1 - 1.0 / 64;
            r.d.triangles({{0.25, y, 0.5}, {-0.25, y, 0.5}, {0.0, y, 0.5 - 1.0 / 4096 / 1024}}, m);  // faces down
            Scene s = r.load(w, h, kEye, kTarget);
            const uint32_t base = uint32_t(s.mesh.positions.size());
            const uint32_t mat = s.mesh.triangleMaterial.back();
            for (const Vec3& p : {Vec3(-0.5f, 0.98f, 0.f), Vec3(0.f, 0.98f, 0.f), Vec3(0.5f, 0.98f, 0.f), Vec3(0.3f, 0.98f, 0.2f)}) {
                s.mesh.positions.push_back(p);
                s.mesh.normals.push_back(Vec3(0, -1, 0));
                s.mesh.vertexHasNormal.push_back(0);
            }
            for (const glm::uvec3 t : {glm::uvec3(base, base + 1, base + 2), glm::uvec3(base + 3, base + 3, base + 3),
                                       glm::uvec3(base, base + 3, base + 3)}) {
                s.mesh.indices.push_back(t);
                s.mesh.triangleMaterial.push_back(mat);
                s.mesh.triangleLight.push_back(-1);
            }
            return finalized(std::move(s));
        };
        c.converging = all;
        c.spp = 128;
        cases.push_back(c);
    }
    {   // A sun 5 degrees above the horizon on a rough glass slab (roughness 0.3) 0.05 above a grey
        // floor filling the view: grazing incidence on the top face, the side faces lit head-on, and
        // grazing refractions inside towards the floor under and behind the slab.
        HardCase c;
        c.name = "grazing sun on rough glass";
        c.build = [](int w, int h) {
            Doc d;
            d.quad({-4, 0, 4}, {4, 0, 4}, {4, 0, -4}, {-4, 0, -4}, d.lambert({0.6, 0.6, 0.6}));
            d.box({-0.5, 0.05, -0.5}, {0.5, 0.25, 0.5}, roughGlassMaterial(d, 0.3));
            const double a = 0.5 * -5.0 * 3.14159265358979323846 / 180.0;  // -z turned 5 degrees towards -y
            d.punctual({{"type", "directional"}, {"color", {1, 1, 1}}, {"intensity", 3.0}}, {{"rotation", {std::sin(a), 0, 0, std::cos(a)}}});
            LoadOptions lo;
            lo.width = w;
            lo.height = h;
            Scene s = loadGltfScene(d.write("grazing-sun-rough-glass.gltf"), lo);
            s.camera = Camera::lookAt(Vec3(0.2f, 2.2f, 1.6f), Vec3(0.f, 0.1f, -0.3f), Vec3(0, 1, 0), 0.6f, w, h);
            return finalized(std::move(s));
        };
        // LT: finite only (its image mean's 5 sigma is ~10x the mean at 256 spp). BDPT agrees per
        // pixel but its image mean is heavy-tailed too: an open finding (docs/hard-cases.md).
        c.converging = bdpt;
        c.spp = 256;
        cases.push_back(c);
    }
    {   // A rough glass sphere at roughness 1e-3 (GGX alpha at its floor 1e-4: a refracted lobe
        // ~3e-5 rad wide, still the microfacet BTDF, docs/materials.md) in the room with a ceiling
        // light: near-delta f and pdf values (~1e8) in connections, MIS and the caustic below it.
        HardCase c;
        c.name = "near-delta rough glass roughness 1e-3";
        c.build = [](int w, int h) {
            Room r;
            r.ceilingLight(0.5, 10);
            r.d.sphere({0, -0.5, -0.25}, 0.375, roughGlassMaterial(r.d, 1e-3), 12, 24);
            return finalized(r.load(w, h, kEye, kTarget));
        };
        c.converging = bdpt;
        c.spp = 128;
        // PT is the reference; through the near-delta sphere it is as noisy as through smooth glass.
        c.referenceSpp = 1024;
        cases.push_back(c);
    }
    {   // Sheen under a clearcoat (layered) on coincident and touching geometry: a rug 1/64 above
        // the floor made of two coincident quads (the same material, triangulated along either
        // diagonal) and a cube of the same material resting on it against the back wall. Where
        // surfaces coincide, two path vertices can land on the same point, and the direction
        // between them was NaN, which the sheen's albedo table then indexed with (a crash;
        // docs/hard-cases.md, "NaN-safe lookups"). test_hard_cases.cpp also builds such vertices
        // exactly, on this scene.
        HardCase c;
        c.name = kLayeredCoincidentCase;
        c.build = [](int w, int h) {
            Room r;
            r.ceilingLight(0.5, 10);
            const int m = sheenUnderCoatMaterial(r.d);
            const double y = -1 + 1.0 / 64;
            const P a{-0.75, y, 0.75}, b{0.75, y, 0.75}, e{0.75, y, -1}, f{-0.75, y, -1};
            r.d.quad(a, b, e, f, m);  // faces +y
            r.d.quad(b, e, f, a, m);  // the same square, the other diagonal
            r.d.box({-0.5, y, -1}, {0, -0.5, -0.5}, m);
            return finalized(r.load(w, h, kEye, kTarget));
        };
        c.converging = all;
        c.spp = 128;
        cases.push_back(c);
    }
    return cases;
}

}  // namespace bdptref::test
