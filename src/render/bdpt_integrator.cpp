// The BDPT and light-tracing integrators: both generate subpaths with the same functions and
// evaluate strategies with connectStrategy; light tracing keeps only t = 1, unweighted.
#include "bdptref/integrator.h"
#include "bdptref/scene.h"
#include "render/bdpt_vertex.h"

#include <vector>

namespace bdptref {

namespace {

BdptSettings toBdptSettings(const IntegratorSettings& s) {
    BdptSettings b;
    b.maxDepth = s.maxDepth;
    b.rouletteStartDepth = s.rouletteStartDepth;
    b.mis = s.mis;
    b.mis.lightSampler = s.lightSampler;  // next-event estimation's light choice (s = 1), in every MIS density
    return b;
}

// Per-thread subpath storage (sized once per thread for the deepest path): the vertices and their
// BSDF side arrays (SubpathBsdfs, bdpt.h).
struct SubpathBuffers {
    std::vector<PathVertex> camera, light;
    std::vector<Bsdf> cameraBsdfs, lightBsdfs;
};
SubpathBuffers& buffersFor(const BdptSettings& s) {
    thread_local SubpathBuffers buffers;
    const size_t nCamera = size_t(s.maxCameraVertices()), nLight = size_t(s.maxLightVertices());
    if (buffers.camera.size() < nCamera) buffers.camera.resize(nCamera);
    if (buffers.light.size() < nLight) buffers.light.resize(nLight);
    if (buffers.cameraBsdfs.size() < nCamera) buffers.cameraBsdfs.resize(nCamera);
    if (buffers.lightBsdfs.size() < nLight) buffers.lightBsdfs.resize(nLight);
    return buffers;
}

class BdptIntegrator final : public Integrator {
public:
    BdptIntegrator(const IntegratorSettings& s, bool lightTracingOnly)
        : settings_(toBdptSettings(s)), record_(s.recordStrategies), recordDepths_(s.recordDepths), lightOnly_(lightTracingOnly) {}
    const char* name() const override { return lightOnly_ ? "lt" : "bdpt"; }
    bool producesSplats() const override { return true; }

    void samplePixel(const Scene& scene, int x, int y, const PixelSampler& sampler, SampleOutput& out) const override {
        SubpathBuffers& buf = buffersFor(settings_);
        const Vec2 raster = Vec2(float(x), float(y)) + sampler.get2D(RngStream::Camera, dim::kFilm);
        const int nCamera = lightOnly_ ? 0 : generateCameraSubpath(scene, sampler, raster, settings_, buf.camera.data(),
                                                                   buf.cameraBsdfs.data());
        // Light tracing weighs every strategy 1: no MIS densities (the wavefront mode skips them too).
        const int nLight = lightOnly_ ? traceLightSubpath(scene, sampler, settings_, buf.light.data(), buf.lightBsdfs.data())
                                      : generateLightSubpath(scene, sampler, settings_, buf.light.data(), buf.lightBsdfs.data());
        const SubpathBsdfs bsdfs{buf.lightBsdfs.data(), buf.cameraBsdfs.data()};
        const int maxT = lightOnly_ ? 1 : nCamera;
        for (int t = 1; t <= maxT; ++t)
            for (int s = lightOnly_ ? 1 : 0; s <= lastLightStrategy(nLight, t); ++s) {
                if (strategyStatus(s, t, settings_.maxDepth, lightOnly_) != StrategyStatus::Evaluated) continue;
                Connection c;
                if (lightOnly_) {
                    if (!connectUnweighted(scene, buf.light.data(), s, buf.camera.data(), t, sampler, &c, bsdfs)) continue;
                } else if (!connectStrategy(scene, buf.light.data(), s, buf.camera.data(), t, sampler, settings_, &c, nullptr,
                                            bsdfs)) {
                    continue;
                }
                const double w = lightOnly_ ? 1.0 : c.weight;
                const Rgb weighted = c.unweighted * float(w);
                if (c.splat) out.splats.push_back(Splat{c.raster, weighted});
                else out.L += weighted;
                if (record_) out.strategies.push_back(StrategyContribution{s, t, weighted, c.unweighted, c.splat, c.raster});
                if (recordDepths_) out.depths.push_back(DepthContribution{s + t - 2, weighted, c.splat, c.raster});
            }
    }

private:
    BdptSettings settings_;
    bool record_;
    bool recordDepths_;
    bool lightOnly_;
};

}  // namespace

std::unique_ptr<Integrator> makeBdpt(const IntegratorSettings& s) { return std::make_unique<BdptIntegrator>(s, false); }
std::unique_ptr<Integrator> makeLightTracer(const IntegratorSettings& s) { return std::make_unique<BdptIntegrator>(s, true); }

}  // namespace bdptref
