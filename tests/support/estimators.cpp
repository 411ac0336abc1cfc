#include "support/estimators.h"

#include "bdptref/renderer.h"

#include <catch2/catch.hpp>

#include <memory>

namespace bdptref::test {

IntegratorSettings integratorSettingsOf(const EstimatorSetup& s) {
    IntegratorSettings is;
    is.maxDepth = s.maxDepth;
    is.mis.heuristic = s.heuristic;
    is.recordStrategies = s.layers;
    is.recordDepths = s.depthLayers;
    is.lightSampler = s.lightSampler;
    return is;
}

std::string estimatorName(const EstimatorSetup& s) {
    const std::string tree = s.lightSampler == LightSamplerKind::Tree ? "-tree" : "";
    if (s.integrator != "bdpt") return s.integrator + tree;
    return (s.heuristic == MisHeuristic::Balance ? "bdpt-balance"
                                                 : s.heuristic == MisHeuristic::Power ? "bdpt-power" : "bdpt-uniform") + tree;
}

std::vector<EstimatorSetup> everyEstimator() {
    std::vector<EstimatorSetup> setups(4);
    setups[0].integrator = "path";
    setups[1].integrator = "lt";
    setups[3].heuristic = MisHeuristic::Power;
    return setups;
}

Film renderEstimator(const Scene& scene, const EstimatorSetup& s, const std::function<void(const Film&, int)>& afterPass,
                     GpuReport* wavefrontReport) {
    const IntegratorSettings is = integratorSettingsOf(s);
    const auto integrator = makeIntegrator(s.integrator, is);
    RenderOptions ro;
    ro.spp = s.spp;
    ro.seed = s.seed;
    ro.threads = s.threads;
    if (s.tileSize > 0) ro.tileSize = s.tileSize;
    std::unique_ptr<WavefrontScheduler> wavefront;
    if (s.wavefront) {
        wavefront = std::make_unique<WavefrontScheduler>(s.integrator, is, s.wavefrontOptions);
        ro.scheduler = wavefront.get();
    }
    Film film(scene.camera.width(), scene.camera.height());
    if (s.layers) film.enableStrategies(s.maxDepth);
    if (s.depthLayers) film.enableDepthLayers(s.maxDepth);
    std::function<void(const RenderProgress&)> progress;
    if (afterPass) progress = [&](const RenderProgress& p) { afterPass(film, p.passesDone); };
    renderImage(scene, *integrator, ro, film, nullptr, progress);
    if (wavefront && wavefrontReport) *wavefrontReport = wavefront->report();
    return film;
}

std::vector<std::pair<std::string, Film>> renderEveryEstimator(const Scene& scene, const std::array<int, 4>& spp,
                                                               uint32_t seedBase, uint32_t seedStep) {
    std::vector<std::pair<std::string, Film>> out;
    std::vector<EstimatorSetup> setups = everyEstimator();
    for (size_t i = 0; i < setups.size(); ++i) {
        setups[i].spp = spp[i];
        setups[i].seed = seedBase + seedStep * uint32_t(i);  // independent renders
        Film f = renderEstimator(scene, setups[i]);
        CHECK(f.nonFiniteSamples() == 0);
        out.emplace_back(estimatorName(setups[i]), std::move(f));
    }
    return out;
}

std::vector<std::pair<std::string, MomentImage>> momentsOfEach(const std::vector<std::pair<std::string, Film>>& films) {
    std::vector<std::pair<std::string, MomentImage>> out;
    for (const auto& [name, film] : films) out.emplace_back(name, momentsOf(film));
    return out;
}

MomentImage scaledMoments(MomentImage img, double factor) {
    for (PixelMoments& p : img.pixels) {
        p.mean *= factor;
        p.varianceOfMean *= factor * factor;
    }
    return img;
}

void checkPairwiseAgreement(const std::vector<std::pair<std::string, MomentImage>>& images, double detectableBias,
                            bool blackRegions) {
    for (size_t i = 0; i < images.size(); ++i)
        for (size_t j = i + 1; j < images.size(); ++j) {
            const auto& [na, a] = images[i];
            const auto& [nb, b] = images[j];
            const ImageComparison c = compareImages(a, b, kPixelAlpha, na, nb);
            INFO(c.report);
            CHECK(c.passed());
            if (blackRegions && detectableBias <= 0.0) continue;
            // Not vacuous: (almost) every pixel (that is not black in both) is t-tested...
            const uint64_t considered = blackRegions ? c.pixels - c.exactOnly : c.pixels;
            if (blackRegions) CHECK(considered >= c.pixels / 2);
            CHECK(c.tested >= considered * 9 / 10);
            // ... and the comparison detects a uniform error of detectableBias in either image.
            const ImageComparison up = compareImages(scaledMoments(a, 1.0 + detectableBias), b, kPixelAlpha, na + " (scaled)", nb);
            const ImageComparison down = compareImages(a, scaledMoments(b, 1.0 + detectableBias), kPixelAlpha, na, nb + " (scaled)");
            INFO(up.report);
            INFO(down.report);
            CHECK_FALSE(up.passed());
            CHECK_FALSE(down.passed());
        }
}

FilmDifference filmDifference(const Film& a, const Film& b, int maxDepth) {
    FilmDifference d;
    const bool layers = a.strategies().enabled() && b.strategies().enabled();
    for (int y = 0; y < a.height(); ++y)
        for (int x = 0; x < a.width(); ++x) {
            d.beauty += !(a.sum(x, y) == b.sum(x, y) && a.sumSquares(x, y) == b.sumSquares(x, y) && a.count(x, y) == b.count(x, y));
            d.light += !(a.lightMean(x, y) == b.lightMean(x, y));
            if (!layers) continue;
            bool same = true;
            for (int depth = 0; depth <= maxDepth; ++depth)
                for (int s = 0; s <= depth + 1; ++s)
                    for (bool weighted : {false, true}) {
                        const int t = depth + 2 - s;
                        same = same && a.strategies().mean(s, t, weighted, x, y) == b.strategies().mean(s, t, weighted, x, y) &&
                               a.strategies().varianceOfMean(s, t, weighted, x, y) == b.strategies().varianceOfMean(s, t, weighted, x, y);
                    }
            d.layers += !same;
        }
    // Depth layers: sums and sums of squares, per pixel.
    const DepthLayers &da = a.depths(), &db = b.depths();
    if (da.enabled() && da.layerCount() == db.layerCount()) {
        const size_t n = a.pixelCount();
        for (size_t p = 0; p < n; ++p) {
            bool same = da.passes() == db.passes();
            for (int depth = 0; depth < da.layerCount(); ++depth) {
                const size_t i = size_t(depth) * n + p;
                same = same && da.sums()[i] == db.sums()[i] && da.sumSquares()[i] == db.sumSquares()[i];
            }
            d.layers += !same;
        }
    }
    // Films with layers on one side only are not comparable layer by layer.
    if (a.strategies().enabled() != b.strategies().enabled() || da.layerCount() != db.layerCount()) d.layers = int(a.pixelCount());
    return d;
}

double meanLuminance(const Film& f) {
    double m = 0;
    for (int y = 0; y < f.height(); ++y)
        for (int x = 0; x < f.width(); ++x) m += f.mean(x, y).y / double(f.pixelCount());
    return m;
}

double lightImageTotal(const Film& f) {
    double total = 0;
    for (int y = 0; y < f.height(); ++y)
        for (int x = 0; x < f.width(); ++x) total += f.lightMean(x, y).y;
    return total;
}

void checkWavefrontIdentical(const Scene& scene, EstimatorSetup s, GpuReport* reportOut) {
    INFO(estimatorName(s) << ", " << s.spp << " spp, pool " << s.wavefrontOptions.poolSize);
    s.wavefront = false;
    const Film mega = renderEstimator(scene, s);
    s.wavefront = true;
    GpuReport report;
    const Film wave = renderEstimator(scene, s, {}, &report);
    const FilmDifference d = filmDifference(mega, wave, s.maxDepth);
    CHECK(d.beauty == 0);
    CHECK(d.light == 0);
    CHECK(d.layers == 0);
    CHECK(meanLuminance(mega) > 1e-3);  // not vacuous: the image is not black
    if (s.integrator != "path") CHECK(lightImageTotal(mega) > 0.0);  // and it has splats
    if (s.layers) {  // and the strategy layers compared hold light
        double unweighted = 0;
        for (const DVec3& v : mega.strategies().sums(false)) unweighted += v.y;
        CHECK(unweighted > 0.0);
    }
    if (s.depthLayers) {  // and the depth layers compared hold something beyond depth 0
        double beyondDirect = 0;
        for (size_t i = mega.pixelCount(); i < mega.depths().sums().size(); ++i) beyondDirect += mega.depths().sums()[i].y;
        CHECK(beyondDirect > 0.0);
    }
    CHECK(report.pathSamples == uint64_t(scene.camera.width()) * uint64_t(scene.camera.height()) * uint64_t(s.spp));
    if (reportOut) *reportOut = report;
}

void checkWavefrontIdenticalEveryEstimator(const Scene& scene, const EstimatorSetup& base) {
    for (EstimatorSetup s : everyEstimator()) {
        const EstimatorSetup which = s;
        s = base;
        s.integrator = which.integrator;
        s.heuristic = which.heuristic;
        s.layers = true;
        s.depthLayers = true;
        checkWavefrontIdentical(scene, s);
    }
}

}  // namespace bdptref::test
