// `bdptref trace --integrator path`: one path-tracing pixel sample replayed exactly as the
// renderer computes it (ptBegin / ptShade / traceShadowRay, src/render/path_tracer.h), with every
// bounce's hit, the emission found and its MIS weight, the next-event sample (light, point,
// densities, weight, shadow ray), the BSDF sample, Russian roulette, and the random numbers drawn
// (docs/rng.md). JSON format: docs/trace-and-mis.md, "Path tracing".
#pragma once

#include "bdptref/path_io.h"
#include "bdptref/scene.h"
#include "render/path_tracer.h"

#include <cstdint>
#include <vector>

namespace bdptref {

struct TracedPathSample {
    int x = 0, y = 0;
    uint64_t sample = 0;
    uint32_t seed = 0, pixelIndex = 0;
    IntegratorSettings settings;
    Vec2 raster{0.f};                     // (x, y) + the film jitter (camera stream, dimension 0)
    std::vector<PtBounceRecord> bounces;  // one per ray traced (the last may be an escape)
    Rgb L{0.f};                           // exactly what the path tracer adds to the pixel
};

// InputError unless pixel (x, y) (full-image coordinates) lies inside the camera's crop window.
void checkTracedPixel(const Camera& camera, int x, int y);

// Pure function of (scene, seed, settings, x, y, sample); (x, y) in full-image coordinates inside
// the camera's crop window (InputError otherwise). Sets FTZ/DAZ as the renderer's threads do.
TracedPathSample tracePathSample(const Scene& scene, uint32_t seed, const IntegratorSettings& settings, int x, int y,
                                 uint64_t sample);

nlohmann::ordered_json pathTraceToJson(const TracedPathSample& traced, const Scene& scene, const SceneReference* ref);

}  // namespace bdptref
