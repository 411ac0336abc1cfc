// An integrator turns one pixel sample (a pure function of scene, settings, seed, pixel and
// sample index) into an estimate: radiance for its own pixel, plus light-tracing splats that land
// on any pixel, plus (optionally) the contribution of every (s, t) strategy.
#pragma once

#include "bdptref/bdpt.h"
#include "bdptref/light_tree.h"
#include "bdptref/math.h"
#include "bdptref/rng.h"

#include <memory>
#include <string>
#include <vector>

namespace bdptref {

class Scene;

struct IntegratorSettings {
    // pbrt's meaning (docs/contracts.md, contract 5): depth = number of path edges - 1. An emitter seen
    // directly is depth 0, direct lighting depth 1; paths of at most maxDepth + 1 edges are kept.
    int maxDepth = 64;
    // Russian roulette after the BSDF sample of every bounce b >= rouletteStartDepth - 1 (b = 0:
    // the first scattering event); one policy in every estimator (docs/path-tracer.md, unbiased).
    int rouletteStartDepth = 3;
    MisSettings mis;                // BDPT only
    // How next-event estimation picks a light (--light-sampler): in proportion to power (default)
    // or by the light tree's importance at the shading point (docs/lights.md, "Light tree"). The
    // path tracer and BDPT's s = 1 strategy (its MIS densities included: BdptSettings::mis.lightSampler
    // is set from this field); makeIntegrator refuses Tree for lt.
    LightSamplerKind lightSampler = LightSamplerKind::Power;
    bool recordStrategies = false;  // fill SampleOutput::strategies (per-(s,t) layers)
    bool recordDepths = false;      // fill SampleOutput::depths (per-depth layers, every integrator)
};

struct Splat {
    Vec2 raster;  // full-image raster position
    Rgb value;
};

struct StrategyContribution {
    int s = 0, t = 0;
    Rgb weighted{0.f}, unweighted{0.f};
    bool splat = false;
    Vec2 raster{0.f};
};

// A contribution to the per-depth layers: `depth` scattering bounces (s + t - 2 for BDPT strategy
// (s, t); the path tracer adds one record per depth, the sum of its emission and next-event terms).
struct DepthContribution {
    int depth = 0;
    Rgb value{0.f};  // as added to the image (MIS-weighted)
    bool splat = false;
    Vec2 raster{0.f};  // full-image raster position of a splat
};

struct SampleOutput {
    Rgb L{0.f};
    std::vector<Splat> splats;
    std::vector<StrategyContribution> strategies;
    std::vector<DepthContribution> depths;
    void clear() {
        L = Rgb(0.f);
        splats.clear();
        strategies.clear();
        depths.clear();
    }
};

class Integrator {
public:
    virtual ~Integrator() = default;
    virtual const char* name() const = 0;
    virtual void samplePixel(const Scene& scene, int x, int y, const PixelSampler& sampler, SampleOutput& out) const = 0;
    virtual bool producesSplats() const { return false; }
};

// Unidirectional path tracer: BSDF sampling + next-event estimation combined with the power
// heuristic (docs/path-tracer.md).
std::unique_ptr<Integrator> makePathTracer(const IntegratorSettings& settings);
// Light tracing: every light-subpath vertex connected to the camera (t = 1), unweighted.
std::unique_ptr<Integrator> makeLightTracer(const IntegratorSettings& settings);
// Bidirectional path tracing: every (s, t) with full vertex connection, MIS-weighted.
std::unique_ptr<Integrator> makeBdpt(const IntegratorSettings& settings);

// Throws InputError when settings.lightSampler is one `integrator` does not implement (the tree:
// path and bdpt, not lt).
void checkLightSamplerSupported(const std::string& integrator, const IntegratorSettings& settings);

// "path" | "lt" | "bdpt"; throws InputError for unknown names (and checkLightSamplerSupported).
std::unique_ptr<Integrator> makeIntegrator(const std::string& name, const IntegratorSettings& settings);

}  // namespace bdptref
