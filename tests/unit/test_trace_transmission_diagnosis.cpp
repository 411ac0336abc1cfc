// `bdptref trace`'s diagnosis of a zero-BSDF connection across a surface names what makes f zero
// for the material there (src/verify/transmission_diagnosis.h), instead of "no transmission lobe"
// for every material:
//  * on hand-built direction pairs, each wording goes with a pair the BSDF really gives f = 0
//    (and the rough glass's valid refraction pair, the control, gives f > 0): no transmission
//    (Lambert), a transmission that is zero (metallic 1), only a smooth (delta) refraction, and
//    for rough glass a generalized half-vector facing away from a direction, from outside and
//    (total internal reflection) from inside;
//  * the replay of a closed rough glass box with the camera and a light inside, under an
//    environment, diagnoses many zero-BSDF connections across the glass: none says "no
//    transmission lobe", each names the material (mostly the half-vector); those across the
//    Lambert block inside still say "no transmission lobe".
#include "bdptref/bsdf.h"
#include "bdptref/gltf_loader.h"
#include "bdptref/scene.h"
#include "bdptref/trace.h"
#include "support/gltf_builder.h"
#include "verify/transmission_diagnosis.h"

#include <catch2/catch.hpp>

#include <string>

using namespace bdptref;
using namespace bdptref::test;

namespace {

MaterialParams roughGlassParams(float roughness) {
    MaterialParams p;
    p.roughness = roughness;
    p.transmission = 1.f;
    p.ior = 1.5f;
    return p;
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

}  // namespace

TEST_CASE("trace diagnosis: the wording of a zero BSDF across the surface follows the material", "[trace][roughglass]") {
    const Vec3 n(0, 0, 1);
    const Vec3 wo(0, 0, 1);  // arriving along the normal, from the front (outside)
    const std::string name = "material 3 'probe'";
    auto cause = [&](const MaterialParams& p, const Vec3& from, const Vec3& to, TransportMode mode) {
        // Only pairs the BSDF really zeroes are diagnosed.
        CHECK(isBlack(Bsdf(p, n, n).f(from, to, mode)));
        return zeroTransmissionCause(p, name, n, n, from, to, mode);
    };
    const Vec3 down(0, 0, -1);

    MaterialParams lambert;
    const std::string l = cause(lambert, wo, down, TransportMode::Radiance);
    CHECK(l == name + " has no transmission lobe");

    MaterialParams metal = roughGlassParams(0.4f);
    metal.metallic = 1.f;
    CHECK(contains(cause(metal, wo, down, TransportMode::Radiance), "transmits nothing here (metallic 1)"));

    MaterialParams smooth = roughGlassParams(0.f);
    smooth.transmission = 0.5f;  // a diffuse base: connectible, but its refraction is a delta lobe
    CHECK(contains(cause(smooth, wo, down, TransportMode::Radiance), "smooth (delta) lobe (roughness 0)"));

    const MaterialParams rough = roughGlassParams(0.4f);
    // The control: straight through at normal incidence is a refraction (f > 0).
    CHECK(!isBlack(Bsdf(rough, n, n).f(wo, down, TransportMode::Radiance)));
    // From outside along the normal into a grazing direction: eta_o wo + eta_i wi points up, so h
    // faces wi.
    const Vec3 grazing = glm::normalize(Vec3(1.f, 0.f, -0.1f));
    for (const TransportMode mode : {TransportMode::Radiance, TransportMode::Importance}) {
        const std::string r = cause(rough, wo, grazing, mode);
        INFO(r);
        CHECK(!contains(r, "no transmission lobe"));
        CHECK(contains(r, name + " is rough glass (roughness 0.4)"));
        CHECK(contains(r, "generalized half-vector"));
        CHECK(!contains(r, "total internal reflection"));
    }
    // From inside (wo on the back side), grazing, out along the normal: past the critical angle.
    const Vec3 woInside = glm::normalize(Vec3(1.f, 0.f, -0.1f));
    const std::string tir = cause(rough, woInside, Vec3(0, 0, 1), TransportMode::Radiance);
    INFO(tir);
    CHECK(contains(tir, "generalized half-vector"));
    CHECK(contains(tir, "total internal reflection"));
}

TEST_CASE("trace diagnosis: zero-BSDF connections across rough glass do not say 'no transmission lobe'", "[trace][roughglass]") {
    // A closed rough glass box (roughness 0.4) holding the camera, a point light and a grey block,
    // under the environment 1: light subpaths from the environment end on the glass from outside
    // and connect to camera vertices inside.
    Doc d;
    d.use("KHR_materials_transmission");
    d.use("KHR_materials_ior");
    const int glass = d.material({{"name", "frosted"},
                                  {"pbrMetallicRoughness", {{"baseColorFactor", {1, 1, 1, 1}}, {"metallicFactor", 0}, {"roughnessFactor", 0.4}}},
                                  {"extensions", {{"KHR_materials_transmission", {{"transmissionFactor", 1.0}}}, {"KHR_materials_ior", {{"ior", 1.5}}}}}});
    d.box({-1, -1, -1}, {1, 1, 1}, glass);
    const int block = d.lambert({0.6, 0.6, 0.6});
    d.j["materials"][size_t(block)]["name"] = "block";
    d.box({-0.6, -0.9, -0.8}, {0.2, -0.3, -0.2}, block);
    d.punctual({{"type", "point"}, {"color", {1, 1, 1}}, {"intensity", 2.0}}, {{"translation", {0.3, 0.5, -0.3}}});
    LoadOptions lo;
    lo.width = lo.height = 12;
    Scene scene = loadGltfScene(d.write("diagnosis-rough-box.gltf"), lo);
    scene.camera = Camera::lookAt(Vec3(0.2f, 0.1f, 0.7f), Vec3(-0.3f, -0.3f, -1.f), Vec3(0, 1, 0), 1.3f, 12, 12);
    scene.setEnvironment(Rgb(1.f));
    scene.finalize();
    const std::string glassName = "material " + std::to_string(glass) + " 'frosted'";
    const std::string blockName = "material " + std::to_string(block) + " 'block'";

    TraceSettings ts;
    ts.seed = 9;
    ts.bdpt.maxDepth = 5;
    ts.fullPaths = false;
    // Zero-BSDF connections across a surface, at the glass and at the block (the control: the
    // block has no transmission lobe, so saying so there is right).
    long acrossGlass = 0, glassNoLobe = 0, halfVector = 0, acrossBlock = 0, blockNoLobe = 0, unnamed = 0;
    std::string example;
    for (int k = 0; k < 200; ++k) {
        const TracedSample tr = traceSample(scene, ts, (k * 5) % 12, (k * 7) % 12, uint64_t(k));
        for (const TracedConnection& c : tr.connections) {
            if (c.status != ConnectionStatus::ZeroContribution || !contains(c.reason, "on the other side of the surface")) continue;
            if (contains(c.reason, glassName + " is rough glass (roughness 0.4)")) {
                ++acrossGlass;
                glassNoLobe += contains(c.reason, "no transmission lobe");
                halfVector += contains(c.reason, "generalized half-vector");
                if (example.empty()) example = c.reason;
            } else if (contains(c.reason, blockName)) {
                ++acrossBlock;
                blockNoLobe += contains(c.reason, blockName + " has no transmission lobe)");
            } else {
                ++unnamed;
            }
        }
    }
    INFO("zero-BSDF connections across the glass " << acrossGlass << " (the half-vector " << halfVector << "), across the block "
                                                   << acrossBlock << "; e.g. " << example);
    CHECK(acrossGlass >= 50);  // not vacuous
    CHECK(glassNoLobe == 0);
    CHECK(unnamed == 0);  // every such diagnosis names the material
    CHECK(blockNoLobe == acrossBlock);
    CHECK(halfVector > 0);
}
