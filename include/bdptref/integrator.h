// An integrator turns one pixel sample (a pure function of scene, settings, seed, pixel and
// sample index) into a radiance estimate.
#pragma once

#include "bdptref/math.h"
#include "bdptref/rng.h"

#include <memory>
#include <string>

namespace bdptref {

class Scene;

struct IntegratorSettings {
    // pbrt's meaning (DESIGN contract 5): depth = number of path edges - 1. An emitter seen
    // directly is depth 0, direct lighting depth 1; paths of at most maxDepth + 1 edges are kept.
    int maxDepth = 64;
    // Russian roulette starts after this many bounces (it is unbiased: survivors are reweighted).
    int rouletteStartDepth = 3;
};

class Integrator {
public:
    virtual ~Integrator() = default;
    virtual const char* name() const = 0;
    // Estimate of the radiance through pixel (x, y) for sample `sampleIndex`.
    virtual Rgb samplePixel(const Scene& scene, int x, int y, const PixelSampler& sampler) const = 0;
};

// Unidirectional path tracer: BSDF sampling + next-event estimation combined with the power
// heuristic (docs/path-tracer.md).
std::unique_ptr<Integrator> makePathTracer(const IntegratorSettings& settings);

// "path" -> path tracer; throws InputError for unknown names.
std::unique_ptr<Integrator> makeIntegrator(const std::string& name, const IntegratorSettings& settings);

}  // namespace bdptref
