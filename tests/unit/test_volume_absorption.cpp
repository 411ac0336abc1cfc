// KHR_materials_volume (docs/materials.md, "Volume absorption"): the loader (defaults, sigma_a =
// -ln(attenuationColor) / attenuationDistance, validation errors, thickness ignored with a
// warning) and the medium rule of segmentTransmittance on hand-built segment ends (back side of
// the start or of the end, symmetry, points, infinite ends, nested media, zero colours).
#include "support/gltf_builder.h"

#include "bdptref/errors.h"
#include "bdptref/gltf_loader.h"
#include "bdptref/scene.h"
#include "render/segment_transmittance.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <string>

using namespace bdptref;
using namespace bdptref::test;
using json = nlohmann::json;

namespace {

// One triangle with a material carrying `extensions` (KHR_materials_transmission added unless
// `transmissive` is false).
Doc volumeDoc(const json& volume, bool transmissive = true) {
    Doc d;
    json ext = {{"KHR_materials_volume", volume}};
    d.use("KHR_materials_volume");
    if (transmissive) {
        d.use("KHR_materials_transmission");
        ext["KHR_materials_transmission"] = {{"transmissionFactor", 1.0}};
    }
    const int mat = d.material({{"pbrMetallicRoughness", {{"metallicFactor", 0}, {"roughnessFactor", 0}}}, {"extensions", ext}});
    const int pos = d.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3");
    d.node({{"mesh", d.mesh(Doc::prim(pos, -1, -1, -1, 4, mat))}});
    return d;
}

Scene load(const Doc& d, const std::string& name) {
    LoadOptions o;
    o.width = o.height = 8;
    return loadGltfScene(d.write(name), o);
}

bool hasWarning(const Scene& s, const std::string& phrase) {
    for (const auto& w : s.info.warnings)
        if (w.find(phrase) != std::string::npos) return true;
    return false;
}

// `namesMaterial`: the message comes from the material conversion (the schema check names the
// JSON path instead).
void requireInputError(const Doc& d, const std::string& name, const std::string& phrase, bool namesMaterial = true) {
    INFO("expected phrase: " << phrase);
    try {
        (void)load(d, name);
        FAIL("no InputError was thrown");
    } catch (const InputError& e) {
        INFO("message: " << e.what());
        CHECK(std::string(e.what()).find(phrase) != std::string::npos);
        if (namesMaterial) CHECK(std::string(e.what()).find("material 0") != std::string::npos);
    }
}

}  // namespace

TEST_CASE("Volume loader: defaults, sigma_a from attenuationColor and attenuationDistance, thickness ignored",
          "[volume][gltf]") {
    SECTION("no attenuation given: no absorption, the extension is supported (not in ignoredFeatures)") {
        const Scene s = load(volumeDoc(json::object()), "volume-defaults.gltf");
        CHECK(s.materials.at(0).absorption == Rgb(0.f));
        CHECK(s.info.ignoredFeatures.empty());
        CHECK(s.info.extensionsIgnored.empty());
    }
    SECTION("a colour without a distance (+inf) and a distance with a white colour: no absorption") {
        CHECK(load(volumeDoc({{"attenuationColor", {0.5, 0.5, 0.5}}}), "volume-no-distance.gltf").materials.at(0).absorption == Rgb(0.f));
        CHECK(load(volumeDoc({{"attenuationDistance", 2.0}}), "volume-white.gltf").materials.at(0).absorption == Rgb(0.f));
    }
    SECTION("sigma_a = -ln(c) / d per channel, +inf for c = 0") {
        const Scene s = load(volumeDoc({{"attenuationColor", {0.8, 0.25, 0.0}}, {"attenuationDistance", 0.5}, {"thicknessFactor", 0.3}}),
                             "volume-sigma.gltf");
        const Rgb sigma = s.materials.at(0).absorption;
        CHECK(sigma.r == Approx(-std::log(0.8) / 0.5).epsilon(1e-6));
        CHECK(sigma.g == Approx(-std::log(0.25) / 0.5).epsilon(1e-6));
        CHECK(std::isinf(sigma.b));
        CHECK(hasWarning(s, "thicknessFactor/thicknessTexture ignored"));
        CHECK(s.info.ignoredFeatures.empty());
        CHECK(!hasWarning(s, "thin-walled"));
    }
    SECTION("thicknessFactor 0 (thin-walled in the specification) still absorbs, with a warning") {
        const Scene s = load(volumeDoc({{"attenuationColor", {0.5, 0.5, 0.5}}, {"attenuationDistance", 1.0}}), "volume-thin.gltf");
        CHECK(s.materials.at(0).absorption.g == Approx(std::log(2.0)).epsilon(1e-6));
        CHECK(hasWarning(s, "thicknessFactor 0"));
    }
    SECTION("without KHR_materials_transmission the volume is ignored with a warning") {
        const Scene s = load(volumeDoc({{"attenuationColor", {0.5, 0.5, 0.5}}, {"attenuationDistance", 1.0}}, false),
                             "volume-opaque.gltf");
        CHECK(s.materials.at(0).absorption == Rgb(0.f));
        CHECK(hasWarning(s, "no KHR_materials_transmission"));
    }
}

TEST_CASE("Volume loader: invalid attenuation and thickness are InputErrors naming the material", "[volume][gltf]") {
    requireInputError(volumeDoc({{"attenuationDistance", 0.0}}), "volume-d0.gltf", "attenuationDistance = 0 is invalid");
    requireInputError(volumeDoc({{"attenuationDistance", -1.0}}), "volume-dneg.gltf", "attenuationDistance = -1 is invalid");
    requireInputError(volumeDoc({{"attenuationDistance", 1e39}}), "volume-dhuge.gltf", "attenuationDistance");
    requireInputError(volumeDoc({{"attenuationDistance", 1e-50}}), "volume-dtiny.gltf", "attenuationDistance");
    requireInputError(volumeDoc({{"attenuationColor", {0.5, 1.5, 0.5}}}), "volume-c-high.gltf", "attenuationColor[1] = 1.5 is outside [0, 1]");
    requireInputError(volumeDoc({{"attenuationColor", {-0.1, 0.5, 0.5}}}), "volume-c-neg.gltf", "attenuationColor[0] is negative");
    requireInputError(volumeDoc({{"attenuationColor", {0.5, 0.5}}}), "volume-c-short.gltf", "attenuationColor must have 3 elements", false);
    requireInputError(volumeDoc({{"thicknessFactor", -0.5}}), "volume-t-neg.gltf", "thicknessFactor = -0.5 is invalid");
    requireInputError(volumeDoc({{"attenuationDistance", "far"}}), "volume-d-string.gltf", "attenuationDistance", false);
}

namespace {

// A scene with two absorbing materials and one clear one, for the medium rule (no geometry needed).
Scene mediumScene() {
    Scene s;
    s.materials.resize(3);
    s.materials[0].absorption = Rgb(1.f, 2.f, 0.f);   // blue channel clear
    s.materials[1].absorption = Rgb(0.5f, 0.5f, 0.5f);
    s.materials[2].absorption = Rgb(0.f);            // clear glass
    return s;
}

void checkRgb(const Rgb& a, const Rgb& b) {
    for (int c = 0; c < 3; ++c) CHECK(a[c] == Approx(b[c]).epsilon(1e-6).margin(1e-12));
}

}  // namespace

TEST_CASE("Volume: the medium of a segment is decided by the back sides of its ends", "[volume]") {
    const Scene s = mediumScene();
    const Vec3 up(0, 1, 0);
    // A horizontal slab between y = 0 (bottom face, outward normal -y) and y = 2 (top, +y) of material 0.
    const SegmentEnd bottom{Vec3(0, 0, 0), -up, 0, false}, top{Vec3(0, 2, 0), up, 0, false};
    const Rgb inside(std::exp(-2.0), std::exp(-4.0), 1.0);  // sigma (1, 2, 0) over length 2
    SECTION("between the two faces, seen from their back sides: absorbed, in both directions") {
        CHECK(segmentMedium(s, bottom, top) == 0);
        checkRgb(segmentTransmittance(s, bottom, top), inside);
        checkRgb(segmentTransmittance(s, top, bottom), inside);
    }
    SECTION("outside: front sides and points are not absorbed") {
        const SegmentEnd below = pointEnd(Vec3(0, -3, 0)), above{Vec3(1, 5, 0), -up, 1, false};  // above: a front face of material 1
        CHECK(segmentMedium(s, below, bottom) == -1);
        checkRgb(segmentTransmittance(s, top, above), Rgb(1.f));
        checkRgb(segmentTransmittance(s, above, top), Rgb(1.f));
    }
    SECTION("a point (camera, punctual light) inside: the surface end decides") {
        const SegmentEnd light = pointEnd(Vec3(0, 1, 0));
        checkRgb(segmentTransmittance(s, light, top), Rgb(std::exp(-1.0), std::exp(-2.0), 1.0));
        checkRgb(segmentTransmittance(s, bottom, light), Rgb(std::exp(-1.0), std::exp(-2.0), 1.0));
        CHECK(segmentMedium(s, light, pointEnd(Vec3(0, 1.5f, 0))) == -1);  // no surface at either end: the limitation
    }
    SECTION("unbounded segments: 0 in absorbing channels, 1 in clear ones") {
        checkRgb(segmentTransmittance(s, bottom, infiniteEnd(up)), Rgb(0.f, 0.f, 1.f));  // leaves the bottom inwards and never ends
        checkRgb(segmentTransmittance(s, infiniteEnd(-up), top), Rgb(0.f, 0.f, 1.f));    // comes from infinity below, meets the top's back
        checkRgb(segmentTransmittance(s, top, infiniteEnd(up)), Rgb(1.f));               // leaves the top outwards
    }
    SECTION("nested: B (material 1) inside A (material 0)") {
        const SegmentEnd bOutside{Vec3(0, 1, 0), -up, 1, false};  // B's bottom face, outward -y, seen from below
        checkRgb(segmentTransmittance(s, bottom, bOutside), Rgb(std::exp(-1.0), std::exp(-2.0), 1.0));  // A's medium
        const SegmentEnd bTop{Vec3(0, 1.5f, 0), up, 1, false};
        checkRgb(segmentTransmittance(s, bOutside, bTop), Rgb(std::exp(-0.25f)));  // inside B
        // Both ends back-facing with different materials (overlap): the smaller index, either direction.
        const SegmentEnd lowB{Vec3(0, 0.5f, 0), -up, 1, false}, highA{Vec3(0, 1, 0), up, 0, false};
        CHECK(segmentMedium(s, lowB, highA) == 0);
        CHECK(segmentMedium(s, highA, lowB) == 0);
    }
    SECTION("Beer-Lambert limits") {
        checkRgb(beerLambert(Rgb(kInfinity, 1.f, 0.f), 0.0), Rgb(1.f));                  // zero length: nothing absorbed
        checkRgb(beerLambert(Rgb(kInfinity, 1.f, 0.f), 1.0), Rgb(0.f, std::exp(-1.0), 1.f));
        checkRgb(beerLambert(Rgb(0.f), double(kInfinity)), Rgb(1.f));                    // clear: no NaN from 0 * inf
    }
}
