// The term catalogue of the diagnosis (docs/diagnosis.md, "The terms"): one list, in code, of the
// terms a BDPT / PT / LT port implements, each with a stable id, the estimators that use it and
// the signature a wrong implementation leaves on the conformance suite. The suite file says which
// scene exercises which term (`terms`); the doc's table is this list (termCatalogueMarkdown, held
// equal to the doc by tests/unit/test_validate_diagnosis.cpp).
#include "verify/validate_diagnosis.h"

#include <algorithm>
#include <iterator>
#include <sstream>

namespace bdptref {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr unsigned P = kUsedByPath, L = kUsedByLight, B = kUsedByBidirectional, All = kUsedByAll;
constexpr unsigned kPunctual = lightKindBit(LightKind::Punctual), kDirectional = lightKindBit(LightKind::Directional);

TermFactor uniform(double value, const char* name, bool partial = false) {
    return {TermFactor::Mode::Uniform, TermFactor::Of::Constant, value, value, name, partial};
}
// A uniform factor on the whole contribution of some kinds of light (lightKindBit): partial on a
// scene lit by other kinds too, 1 - s (1 - f) where the scene's light shares say s.
TermFactor onLights(double value, const char* name, unsigned lights) {
    TermFactor f = uniform(value, name, true);
    f.lights = lights;
    return f;
}
// A factor on one of BDPT's strategy shares (SuiteScene::strategyShares).
TermFactor onStrategyShare(double value, const char* name, const char* share) {
    TermFactor f = uniform(value, name);
    f.strategyShare = share;
    return f;
}
// A factor on some emitters' light from depth 1 on (SuiteScene::emitterShares).
TermFactor onEmitterShare(double value, const char* name, const char* share) {
    TermFactor f = uniform(value, name);
    f.emitterShare = share;
    return f;
}
TermFactor withoutDepthLayers(TermFactor f) {
    f.withoutDepthLayers = true;
    return f;
}
TermFactor uniformRange(double low, double high, const char* name) {
    return {TermFactor::Mode::Uniform, TermFactor::Of::Constant, low, high, name, false};
}
TermFactor perBounce(double value, const char* name) {
    return {TermFactor::Mode::PerBounce, TermFactor::Of::Constant, value, value, name, false};
}
TermFactor perBounceRange(double low, double high, const char* name) {
    return {TermFactor::Mode::PerBounce, TermFactor::Of::Constant, low, high, name, false};
}
// The radiance scaling of refraction: a wrong term shows (eta_o / eta_i)^(+-2) where radiance
// crosses the glass once (a camera inside it), on the rays that refract (partial); the ratio
// inverted ((eta_i / eta_o)^2 for (eta_o / eta_i)^2) shows its square, (eta_o / eta_i)^(+-4).
TermFactor sceneEta2(TermFactor::Of of, const char* name) {
    return {TermFactor::Mode::Uniform, of, 1, 1, name, true};
}

// The BSDFs' terms: lobes, their sampling, layers, textures.
std::vector<Term> bsdfTerms() {
    using Of = TermFactor::Of;
    return {
        {"lambert.eval", "Lambert BRDF value albedo / pi and the cosine of the rendering equation", All,
         "a constant per Lambert bounce (pi, 1/pi, pi/2 for albedo/2): the ratio grows or shrinks geometrically with depth",
         kGrowing, {perBounce(kPi, "pi"), perBounce(1 / kPi, "1/pi"), perBounce(kPi / 2, "pi/2"), perBounce(2 / kPi, "2/pi")},
         false, false, kFromDepth1 | kUniform},
        {"lambert.sample", "cosine-weighted hemisphere sampling and its density cos / pi (estimator and MIS)", All,
         "a per-bounce factor where BSDF sampling carries the light, a depth >= 1 change where MIS weighs it against next-event estimation",
         kGrowing | kFromDepth1, {perBounce(kPi, "pi"), perBounce(1 / kPi, "1/pi")}, false, false},
        {"diffuse.burley_vs_lambert", "Burley (Disney) diffuse instead of glTF's Lambert (a convention of Cycles' Principled BSDF)", All,
         "a per-bounce gain of a few percent on rough diffuse walls: +19% cornell-box, +175% white-box",
         kGrowing, {perBounceRange(1.01, 1.30, "a Burley gain of 1-30% per bounce"), withoutDepthLayers(uniformRange(1.02, 4.0, "a Burley brightening"))},
         true, true},
        {"diffuse.fresnel_weighted", "the diffuse base weighted by (1 - F) of the specular layer (a WebGL path tracer's convention)", All,
         "a per-bounce loss of a few percent on diffuse surfaces (1 - F0 = 0.96 where glTF's default specular layer is assumed)",
         kGrowing,
         {perBounceRange(0.80, 0.99, "a (1 - F) loss of 1-20% per bounce"),
          perBounceRange(1.01, 1.25, "a gain of 1-25% per bounce (the 1 - F weight missing under a specular layer)")},
         true, true},
        {"ggx.eval", "GGX (Trowbridge-Reitz) microfacet BRDF: D, Smith G1(wo) G1(wi), Fresnel, 1 / (4 cos_o cos_i)", All,
         "glossy metals brighter or darker, by an angle-dependent amount, from depth 1", kFromDepth1 | kGrowing, {}, false, false},
        {"ggx.vndf_pdf", "visible-normal sampling of GGX and its density G1(wo) D / (4 cos_o), weighed against light sampling by MIS", All,
         "glossy reflections of small lights wrong where MIS weighs BSDF sampling (veach-mis)", kFromDepth1 | kDeep, {}, false, false},
        {"ggx.rough_transmission", "rough dielectric BTDF: the half-vector Jacobian, refraction's half vector, VNDF sampling of refraction", All,
         "the floor seen or lit through rough glass wrong (ortho-rough-glass, the absorbing-glass box)", kFromDepth1 | kDeep, {}, false, false},
        {"dielectric.fresnel", "smooth dielectric: Fresnel choice between reflection and refraction, eta inverted inside, total internal reflection", All,
         "scenes with smooth glass wrong where rays cross it", kFromDepth1 | kDeep, {}, false, false},
        {"specular.delta", "delta lobes (mirror, smooth glass): weight F or 1 - F, no connections to them, MIS weight 0 for strategies that cannot sample them", All,
         "mirrors and smooth glass too bright or too dark; bidirectional caustics counted twice", kFromDepth1 | kDeep, {}, false, false},
        {"refraction.eta2", "radiance scaled by (eta_o / eta_i)^2 at refraction, importance not (Cycles applies none)", All,
         "x 1/eta^2 only where radiance crosses glass once: camera-in-glass -49% (1/eta^2 = -56% on the rays that refract); "
         "x eta^2 on light subpaths leaving a glass (light-in-glass)",
         kFromDepth1 | kUniform,
         {sceneEta2(Of::SceneInvEta2, "1/eta^2"), sceneEta2(Of::SceneEta2, "eta^2"), sceneEta2(Of::SceneInvEta4, "1/eta^4 (the ratio inverted)"),
          sceneEta2(Of::SceneEta4, "eta^4 (the ratio inverted)")},
         true, false},
        {"layer.clearcoat", "KHR_materials_clearcoat: the coat's GGX lobe about its own normal, F_c(V.n_c) with f0 0.04, the base times 1 - clearcoat F_c", All,
         "coated surfaces of layered-materials wrong", kFromDepth1, {}, false, false},
        {"layer.sheen", "KHR_materials_sheen: the Charlie lobe and visibility, the base's albedo scaling, roughness squared", All,
         "the velvet sphere of layered-materials wrong", kFromDepth1, {}, false, false},
        {"bsdf.lobe_selection", "choosing one lobe of several (diffuse, specular, coat, sheen, reflect / refract) and dividing by its probability", All,
         "multi-lobe materials off by a constant-ish factor per bounce on them", kFromDepth1 | kGrowing | kDeep, {}, false, false},
        {"shading.normal_adjoint", "shading normals: the adjoint correction (wo.ns)(wi.ng) / ((wo.ng)(wi.ns)), in absolute values, on light subpaths", L | B,
         "light-traced images of smooth-shaded or normal-mapped meshes wrong, path-traced ones right", kFromDepth1 | kGrowing, {}, false, false},
        {"texture.lookup", "texture coordinates (glTF's v axis), sRGB decoding of colour textures, metallicRoughness channels (G, B)", All,
         "textured surfaces wrong where the texture varies; a mirrored or darker pattern", kUniform | kFromDepth1, {}, false, false},
        {"texture.normal_map", "normal maps: tangent frames, glTF's +Y green channel", All,
         "normal-mapped surfaces lit from the wrong side of their bumps", kFromDepth1, {}, false, false},
        {"alpha.cutout", "alpha MASK and BLEND: camera, shadow and light rays pass where alpha says", All,
         "cut-out and blended quads opaque for some kind of ray", kUniform | kFromDepth1, {}, false, false},
    };
}

// Each light type's emission, sampling and units.
std::vector<Term> lightTerms() {
    return {
        {"light.area.emission", "emitted radiance of emissive triangles: emissiveFactor x strength x emissive texture", All,
         "a uniform factor on everything an area light lights, from depth 0 (the light seen directly)",
         kUniform | kDepth0Only, {}, false, false},
        {"light.area.nee_jacobian", "next-event estimation of an area light: area density to solid angle, cos_light / distance^2", P | B,
         "every depth >= 1 off by a similar factor under area lights; depth 0 right", kFromDepth1 | kDepth1Only, {}, false, false},
        {"light.area.sidedness", "one-sided emitters dark from behind; a double-sided one emits from both faces with the direction density halved", All,
         "the back of a one-sided light glowing (depth 0) and what it lights (from depth 1, or from depth 2 where the "
         "camera sees those surfaces only after a bounce), or a double-sided light's power wrong (lights-room; a light "
         "tracer's direction density not halved: x 1/2 on the double-sided lamp's light from depth 1)",
         kDepth0Only | kFromDepth1 | kUniform | kFromDepth2,
         // A light tracer whose double-sided emitter's direction density is not halved (or halved
         // twice) scales that emitter's light from depth 1 on.
         {onEmitterShare(0.5, "1/2 (the direction density of both faces not halved)", kDoubleSidedFromDepth1Share),
          onEmitterShare(2.0, "2 (the direction density halved twice)", kDoubleSidedFromDepth1Share)},
         false, false},
        {"light.area.emission_sampling", "light subpaths from area lights: a point with density 1 / area, a cosine direction", L | B,
         "light-traced images under area lights off by a factor; path-traced ones right (from depth 1 when the direction's "
         "density is wrong: depth 0 connects the light's point to the camera)",
         kUniform | kFromDepth1, {uniformRange(1.1, 2.1, "up to x2 (the emission cosine missing: the mean of 1 / cos is 2)")}, false, false},
        {"light.selection", "choosing one light of several by power and dividing by its probability", All,
         "scenes with several lights off by per-light factors; single-light scenes right", kFromDepth1 | kUniform, {}, false, false},
        {"light.point.intensity_units", "point and spot intensity in W/sr divided by distance^2 (not a power divided by 4 pi)", All,
         "x 1/(4 pi) or x 4 pi on the light of punctual lights, from depth 1",
         kFromDepth1 | kUniform, {onLights(1 / (4 * kPi), "1/(4 pi)", kPunctual), onLights(4 * kPi, "4 pi", kPunctual)}, true, false},
        {"light.point.emission_pdf", "light subpaths from point lights: uniform directions, density 1 / (4 pi)", L | B,
         "x 4 pi or x 1/(4 pi) on light-traced images of point lights, x 1/2 or x 2 for a hemisphere's density",
         kFromDepth1 | kUniform,
         {uniform(1 / (4 * kPi), "1/(4 pi)", true), uniform(4 * kPi, "4 pi", true), uniform(0.5, "1/2", true), uniform(2.0, "2", true)},
         true, false},
        {"light.spot.falloff", "spot cone falloff between the inner and outer angle (glTF: the square of a linear ramp in cos), also for emission sampling", All,
         "the floor under the spots of lights-room brighter or darker at the cone's edge (Cycles' spot blend differs)",
         kFromDepth1, {}, false, false},
        {"light.directional.irradiance", "a directional light's intensity as irradiance in W/m^2 on a surface facing it (lux read as W/m^2), a delta light reached only by next-event estimation and light paths", All,
         "x pi, x 1/pi or a missing receiver cosine on the sunlit surfaces of sun-courtyard, from depth 1",
         kFromDepth1 | kUniform, {onLights(kPi, "pi", kDirectional), onLights(1 / kPi, "1/pi", kDirectional)}, true, false},
        {"light.directional.emission_pdf", "light subpaths from directional and environment lights: a disk over the scene's bounding sphere, density 1 / (pi R^2)", L | B,
         "light carried by light subpaths from directional or environment lights off by R (sun-courtyard, mis-zoo, env-map-outdoor)",
         kFromDepth1 | kUniform, {}, false, false},
        {"light.env.mapping", "the environment map's orientation: u = 0.5 + atan2(z, x) / 2 pi, v = acos(y) / pi, top row +Y", All,
         "the sky and the sun in the wrong place: env-map-outdoor wrong at every depth", kUniform, {}, false, false},
        {"light.env.sampling_pdf", "importance sampling of an environment map and its solid-angle density (1 / (2 pi^2 sin theta))", All,
         "env-map-outdoor off where next-event estimation or MIS weighs map samples", kFromDepth1, {}, false, false},
        {"units.photometric_683", "punctual light intensity in photometric units (candela) divided by 683 lm/W (a convention of Cycles)", All,
         "x 1/683 on the light of punctual lights: uniform on scenes lit by them alone (sphere-point-light), partial where emissive meshes light too",
         kFromDepth1 | kUniform, {onLights(1.0 / 683.0, "1/683", kPunctual | kDirectional), onLights(683.0, "683", kPunctual | kDirectional)},
         true, true},
    };
}

// The camera's rays and importance, light tracing's splats, the pixel filter.
std::vector<Term> cameraTerms() {
    return {
        {"camera.generate", "camera rays: field of view and aspect, pixel positions", All,
         "the image scaled, shifted or cropped: large differences at edges, every depth", kAnyDepthShape, {}, false, false},
        {"camera.orthographic", "orthographic camera rays: glTF's xmag / ymag as half extents, parallel rays from film points", All,
         "the orthographic scenes (ortho-camera, ortho-rough-glass) scaled or cropped, the perspective ones right",
         kAnyDepthShape, {}, false, false},
        {"camera.importance", "camera importance We = 1 / (A cos^4) and its density for light tracing's camera connections (t = 1)", L | B,
         "light-traced images wrong away from the image centre (wide lights-room camera) or by a film-area factor (ortho-rough-glass)",
         kAnyDepthShape, {uniform(4, "4 (the film area from half extents)"), uniform(0.25, "1/4 (the film area from full extents)")},
         false, false},
        {"lt.splat_normalisation", "light tracing's splats divided by the number of light paths, independent of crop and tiling", L | B,
         "a uniform factor (the pixel count, the spp) on the light-traced part of every scene",
         kUniform, {uniform(4096.0, "64 x 64 pixels", true), uniform(1.0 / 4096.0, "1/(64 x 64 pixels)", true),
                    onStrategyShare(4096.0, "64 x 64 pixels", kLightTracingShare),
                    onStrategyShare(1.0 / 4096.0, "1/(64 x 64 pixels)", kLightTracingShare)},
         false, false},
        {"pixel.filter", "the pixel filter: a box over the pixel (a tent or Gaussian filter blurs across pixels)", All,
         "differences at high-contrast edges only; no net factor", kAnyDepthShape, {}, false, true},
    };
}

// The estimator's own machinery: MIS, roulette, path lengths, offsets, volumes, random numbers.
std::vector<Term> transportTerms() {
    return {
        {"mis.weights", "MIS weights of the strategies (balance / power): the densities they use, delta vertices, reverse densities", P | B,
         "an estimator whose strategies do not sum to one: off where strategies overlap, from depth 1; in BDPT, whose depth k has "
         "k + 2 strategies (two at depth 0), a wrong weight's error grows or shrinks with depth",
         kFromDepth1 | kDepth1Only, {}, false, false, kGrowing | kDeep | kUniform},
        {"roulette.camera_subpath", "Russian roulette on camera subpaths: survivors divided by the survival probability", P | B,
         "the ratio decays with depth from where roulette starts (white-box)", kGrowing | kDeep,
         {perBounceRange(0.05, 0.995, "a roulette loss per bounce")}, true, false},
        {"roulette.light_subpath", "Russian roulette on light subpaths, including throughput far above 1 (a probability clamped to 1)", L | B,
         "light-traced deep paths lost (white-box) or mis-weighted where light throughput is large (cornell-box)", kGrowing | kDeep,
         {perBounceRange(0.05, 0.995, "a roulette loss per bounce")}, true, false},
        {"subpath.length_limit", "the maximum depth: paths of at most maxDepth + 1 edges, light subpaths as long as the estimator allows", All,
         "the deepest layer missing or one too many (white-box depth 16); light-in-glass darker; depth-limit-caustic black",
         kLastDepth | kDeep,
         {uniform(0.0, "0 (the deepest layer, all of depth-limit-caustic, missing)"),
          onStrategyShare(0.0, "0 (a camera subpath one vertex short)", kDeepestEmitterHitShare),
          onStrategyShare(0.0, "0 (a light subpath one vertex short)", kDeepestLightTracingShare)},
         false, false},
        {"ray.offset", "ray origins offset off the surface (self-intersection), shadow rays leaving from the right side", All,
         "depth >= 1 darker under point lights (-25% at depth 1 when shadow rays leave from below), little under emissive meshes",
         kDepth1Only | kFromDepth1, {}, false, false},
        {"volume.attenuation_mapping", "KHR_materials_volume: sigma_a = -ln(attenuationColor) / attenuationDistance (Cycles maps the colour to a density)", All,
         "absorbing-glass alone: +49% with the colour as density, a few percent for distance or 1 - colour mistakes",
         kFromDepth1 | kUniform, {}, false, true},
        {"volume.segments", "absorption on every segment inside a medium (camera, extension, next-event and connection segments) and the inside / outside rule", All,
         "absorbing-glass alone, brighter when a kind of segment is not absorbed", kFromDepth1, {}, false, false},
        {"rng.dimensions", "each decision reads its own random dimension (docs/rng.md): two decisions on one number correlate them", All,
         "a small bias where the correlated decisions meet: every deep vertex of lobe-box (lobe choice and direction: -4.7%), the glass of caustic-glass (lobe choice and roulette: +0.3%)",
         kDeep | kFromDepth1 | kGrowing, {}, false, false},
    };
}

// Every term, in the order of docs/diagnosis.md's table.
std::vector<Term> buildCatalogue() {
    std::vector<Term> all;
    for (std::vector<Term> (*group)() : {bsdfTerms, lightTerms, cameraTerms, transportTerms}) {
        std::vector<Term> terms = group();
        all.insert(all.end(), std::make_move_iterator(terms.begin()), std::make_move_iterator(terms.end()));
    }
    return all;
}

}  // namespace

unsigned estimatorBit(PortEstimator e) {
    switch (e) {
        case PortEstimator::Path: return kUsedByPath;
        case PortEstimator::Light: return kUsedByLight;
        case PortEstimator::Bidirectional: return kUsedByBidirectional;
    }
    return 0;
}

bool wholeImageInLightTracer(const Term& t, PortEstimator e) {
    return e == PortEstimator::Light && strategyClassesOf(t) == strategyClassBit(StrategyClass::LightTracing);
}

bool oneFactorForEveryScene(const Term& t, PortEstimator e) {
    return wholeImageInLightTracer(t, e) && std::string(t.id) == "lt.splat_normalisation";
}

bool movesPixelsNotTheMean(const Term& t) { return std::string(t.id) == "pixel.filter"; }

bool movesDepth0(const Term& t) {
    static const std::vector<std::string> ids = {
        "light.area.emission", "light.area.sidedness", "light.env.mapping",
        "camera.generate",     "camera.orthographic",  "pixel.filter",      "texture.lookup",
        "alpha.cutout",        "volume.segments",      "volume.attenuation_mapping",
        "mis.weights",         "rng.dimensions",
    };
    return std::find(ids.begin(), ids.end(), t.id) != ids.end();
}

// BSDF sampling alone: a light tracer's depth-1 path (light, surface, lens) evaluates the surface's
// BSDF towards the lens but samples none, so these terms first act at depth 2 there.
bool bsdfSamplingOnly(const Term& t) {
    static const std::vector<std::string> ids = {"lambert.sample", "ggx.vndf_pdf", "bsdf.lobe_selection"};
    return std::find(ids.begin(), ids.end(), t.id) != ids.end();
}

unsigned depthShapesFor(const Term& t, PortEstimator e) {
    if (e == PortEstimator::Light && bsdfSamplingOnly(t)) return kDeep | kFromDepth2;
    return t.depthShapes | (e == PortEstimator::Bidirectional ? t.bidirectionalDepthShapes : 0u);
}

unsigned strategyClassesOf(const Term& t) {
    constexpr unsigned H = strategyClassBit(StrategyClass::EmitterHit), N = strategyClassBit(StrategyClass::NextEvent),
                       T = strategyClassBit(StrategyClass::LightTracing), C = strategyClassBit(StrategyClass::Connections);
    static const std::vector<std::pair<std::string, unsigned>> classes = {
        {"mis.weights", 0u},                        // the unweighted layers hold no weight
        {"light.area.nee_jacobian", N},             // the light sample's density (s = 1)
        {"light.selection", N | T | C},             // the light chosen for a next event or a light subpath
        {"light.env.sampling_pdf", N | T | C},
        {"light.area.emission_sampling", T | C},    // the light subpath's first vertex and direction
        {"light.point.emission_pdf", T | C},
        {"light.directional.emission_pdf", T | C},
        {"camera.importance", T},                   // We and its density at t = 1
        {"lt.splat_normalisation", T},
        {"roulette.light_subpath", T | C},
        {"roulette.camera_subpath", H | N | C},
        {"shading.normal_adjoint", T | C},          // the adjoint BSDF on light subpaths
    };
    for (const auto& [id, bits] : classes)
        if (id == t.id) return bits;
    return kAllStrategyClasses;
}

unsigned strategyClassesOfEstimator(PortEstimator e) {
    unsigned bits = 0;
    for (int c = 0; c < kStrategyClassCount; ++c)
        if (estimatorHasClass(e, StrategyClass(c))) bits |= strategyClassBit(StrategyClass(c));
    return bits;
}

const std::vector<Term>& termCatalogue() {
    static const std::vector<Term> terms = buildCatalogue();
    return terms;
}

const Term* findTerm(const std::string& id) {
    for (const Term& t : termCatalogue())
        if (id == t.id) return &t;
    return nullptr;
}

std::string termCatalogueMarkdown(const Suite* suite) {
    std::ostringstream md;
    md << "| term | estimators | " << (suite ? "scenes | " : "") << "what it is | signature of a wrong one |\n";
    md << "|---|---|" << (suite ? "---|" : "") << "---|---|\n";
    for (const Term& t : termCatalogue()) {
        std::string est;
        if (t.estimators & kUsedByPath) est += "path";
        if (t.estimators & kUsedByLight) est += std::string(est.empty() ? "" : ", ") + "light";
        if (t.estimators & kUsedByBidirectional) est += std::string(est.empty() ? "" : ", ") + "bidirectional";
        md << "| `" << t.id << "`" << (t.convention ? " (convention)" : "") << " | " << est << " | ";
        if (suite) {
            std::string scenes;
            for (const SuiteScene& s : suite->scenes)
                if (std::find(s.terms.begin(), s.terms.end(), t.id) != s.terms.end())
                    scenes += (scenes.empty() ? "" : ", ") + s.name;
            md << (scenes.empty() ? "none" : scenes) << " | ";
        }
        md << t.description << " | " << t.signature << " |\n";
    }
    return md.str();
}

}  // namespace bdptref
