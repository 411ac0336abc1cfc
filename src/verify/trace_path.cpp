#include "verify/trace_path.h"

#include "bdptref/errors.h"
#include "bdptref/light.h"
#include "bdptref/renderer.h"
#include "bdptref/rng.h"
#include "scene/accel.h"

#include <cmath>
#include <string>

namespace bdptref {

using json = nlohmann::ordered_json;

namespace {

json num(double v) {
    if (std::isfinite(v)) return v;
    return std::isnan(v) ? "nan" : v > 0 ? "inf" : "-inf";  // as path_io writes them
}
json vec(const Vec3& v) { return json::array({num(v.x), num(v.y), num(v.z)}); }
json vec(const DVec3& v) { return json::array({num(v.x), num(v.y), num(v.z)}); }
json vec(const Vec2& v) { return json::array({num(v.x), num(v.y)}); }

// The hit as a vertex (world coordinates, names for people).
json hitToJson(const SurfaceHit& h, const Scene& scene) {
    json o{{"p", vec(scene.toWorld(h.p))}, {"ng", vec(h.ng)}, {"ns", vec(h.ns)}, {"bary", vec(h.bary)},
           {"uv", vec(scene.attributes(h.triangle, h.bary).uv[0])}, {"triangle", h.triangle}, {"material", h.material}};
    if (h.material < scene.materials.size()) o["materialName"] = scene.materials[h.material].name;
    if (h.light >= 0) o["light"] = h.light;
    return o;
}

json bounceToJson(const PtBounceRecord& r, const Scene& scene) {
    const uint32_t base = dim::vertex(uint32_t(r.bounce), dim::Slot(0));
    json o{{"bounce", r.bounce},
           {"ray", json{{"origin", vec(scene.toWorld(r.ray.origin))}, {"direction", vec(r.ray.dir)}}},
           {"betaIn", vec(r.betaIn)}};
    if (r.transmittance != Rgb(1.f)) o["transmittance"] = vec(r.transmittance);  // volume absorption along the ray (in betaIn)
    if (r.escaped) {
        o["escaped"] = true;
    } else {
        o["vertex"] = hitToJson(r.hit, scene);
    }
    if (r.emission) {
        // Emission found by the ray: BSDF sampling's strategy, MIS-weighted against NEE at the previous vertex.
        o["emission"] = json{{"Le", vec(r.Le)},
                             {"bsdfPdf", num(r.emissionBsdfPdf)},
                             {"lightPdf", num(r.emissionLightPdf)},
                             {"weight", num(r.emissionWeight)},
                             {"added", vec(r.emissionAdded)},
                             {"note", r.emissionLightPdf > 0.f ? "power heuristic of bsdfPdf against lightPdf"
                                                               : "weight 1: the ray left a delta bounce (or the camera)"}};
    }
    if (r.escaped) return o;
    if (r.depthLimit) {
        o["end"] = "depth limit: a further vertex would exceed the maximum depth";
        return o;
    }
    json random{{"dimensionBase", base}};
    if (r.neeTried) {
        random["neeLight"] = num(r.uNeeLight);
        random["neePosition"] = vec(r.uNeePosition);
        json n{{"light", r.neeLight}, {"pmf", num(r.neePmf)}, {"sampled", r.neeSampled}};
        if (r.neeLight >= 0 && size_t(r.neeLight) < scene.lights.size())
            n["lightType"] = lightTypeName(scene.lights[size_t(r.neeLight)].type);
        if (r.neeSampled) {
            n["wi"] = vec(r.nee.wi);
            n["pLight"] = vec(isInfinite(scene.lights[size_t(r.neeLight)]) ? DVec3(r.nee.pLight) : scene.toWorld(r.nee.pLight));
            n["nLight"] = vec(r.nee.nLight);
            n["Li"] = vec(r.nee.Li);
            n["pdf"] = num(r.nee.pdf);
            n["delta"] = r.nee.delta;
        }
        if (r.neeShadowRay) {
            n["fCos"] = vec(r.neeFCos);
            if (r.neeTransmittance != Rgb(1.f)) n["transmittance"] = vec(r.neeTransmittance);
            n["lightPdf"] = num(double(r.neePmf) * double(r.nee.pdf));
            n["bsdfPdf"] = num(r.neeBsdfPdf);
            n["weight"] = num(r.neeWeight);
            n["contribution"] = vec(r.neeContribution);
            n["shadowRay"] = r.neeUnoccluded ? "unoccluded" : "occluded";
        } else if (r.neeSampled) {
            n["contribution"] = "none: f, Li or the transmittance is zero in that direction";
        }
        o["nee"] = n;
    } else {
        o["nee"] = json{{"skipped", "the BSDF has only delta lobes"}};
    }
    if (r.bsdfDrawn) {
        random["bsdfLobe"] = num(r.uBsdfLobe);
        random["bsdfDirection"] = vec(r.uBsdfDirection);
        json b{{"sampled", r.bsdfSampled}};
        if (r.bsdfSampled) {
            b["wi"] = vec(r.bsdf.wi);
            b["f"] = vec(r.bsdf.f);
            b["pdf"] = num(r.bsdf.pdf);
            b["delta"] = r.bsdf.delta;
            b["transmission"] = r.bsdf.transmission;
            b["betaOut"] = vec(r.betaOut);
        }
        o["bsdf"] = b;
    }
    if (r.rouletteTested) {
        random["roulette"] = num(r.uRoulette);
        o["roulette"] = json{{"survivalProbability", num(r.survive)}, {"survived", r.survived}};
    }
    o["random"] = random;
    o["continues"] = r.continues;
    return o;
}

}  // namespace

void checkTracedPixel(const Camera& camera, int x, int y) {
    if (x < camera.cropX0() || x >= camera.cropX1() || y < camera.cropY0() || y >= camera.cropY1())
        throw InputError("pixel (" + std::to_string(x) + ", " + std::to_string(y) + ") is outside the rendered window [" +
                         std::to_string(camera.cropX0()) + ", " + std::to_string(camera.cropX1()) + ") x [" +
                         std::to_string(camera.cropY0()) + ", " + std::to_string(camera.cropY1()) + ")");
}

TracedPathSample tracePathSample(const Scene& scene, uint32_t seed, const IntegratorSettings& settings, int x, int y,
                                 uint64_t sample) {
    const Camera& camera = scene.camera;
    checkTracedPixel(camera, x, y);
    if (settings.maxDepth < 0) throw InputError("the maximum depth must be >= 0");
    setFlushDenormals();  // as every rendering thread (renderer.cpp): same float results

    TracedPathSample out;
    out.x = x;
    out.y = y;
    out.sample = sample;
    out.seed = seed;
    out.settings = settings;
    out.pixelIndex = pixelIndex(x, y, camera.width());
    const PixelSampler sampler(seed, out.pixelIndex, sample);
    out.raster = Vec2(float(x), float(y)) + sampler.get2D(RngStream::Camera, dim::kFilm);

    // PathTracer::samplePixel's loop, with a trace attached.
    PtTrace trace;
    PtPathState st = ptBegin(scene, x, y, sampler);
    while (st.active) {
        SurfaceHit hit;
        const bool found = scene.intersect(st.ray, &hit);
        PtShadowRecord nee;
        if (ptShade(scene, sampler, settings, st, found ? &hit : nullptr, &nee, &trace)) {
            const bool unoccluded = traceShadowRay(scene, nee.ray);
            trace.bounces.back().neeUnoccluded = unoccluded;
            ptAddShadowResult(st, nee, unoccluded);
        }
    }
    out.bounces = std::move(trace.bounces);
    out.L = st.L;
    return out;
}

json pathTraceToJson(const TracedPathSample& t, const Scene& scene, const SceneReference* ref) {
    json o;
    o["format"] = "bdptref-trace";
    o["version"] = 1;
    const Camera& cam = scene.camera;
    json settings{{"integrator", "path"},
                  {"mode", "megakernel"},
                  {"seed", t.seed},
                  {"pixel", json::array({t.x, t.y})},
                  {"pixelIndex", t.pixelIndex},
                  {"sample", t.sample},
                  {"imageWidth", cam.width()},
                  {"imageHeight", cam.height()},
                  {"window", json::array({cam.cropX0(), cam.cropY0(), cam.cropX1(), cam.cropY1()})},
                  {"maxDepth", t.settings.maxDepth},
                  {"rouletteStartDepth", t.settings.rouletteStartDepth},
                  {"mis", "power heuristic (beta 2) between next-event estimation and BSDF sampling"},
                  {"sceneHash", scene.info.contentHash},
                  {"worldOrigin", vec(scene.worldOrigin)}};
    if (t.settings.lightSampler != LightSamplerKind::Power) settings["lightSampler"] = lightSamplerName(t.settings.lightSampler);
    if (ref) settings["scene"] = sceneReferenceToJson(*ref);
    o["settings"] = settings;
    o["rng"] = json{{"generator", "philox4x32-10"},
                    {"key", json::array({t.pixelIndex, t.seed})},
                    {"counter", "(dimension, sample & 0xffffffff, sample >> 32, stream); stream 0 camera"},
                    {"sampleWords", json::array({uint32_t(t.sample), uint32_t(t.sample >> 32)})},
                    {"camera", json{{"film", vec(t.raster - Vec2(float(t.x), float(t.y)))}}}};
    o["raster"] = vec(t.raster);
    json bounces = json::array();
    for (const PtBounceRecord& r : t.bounces) bounces.push_back(bounceToJson(r, scene));
    o["bounces"] = bounces;
    o["total"] = json{{"L", vec(t.L)}};
    return o;
}

}  // namespace bdptref
