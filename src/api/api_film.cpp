// Films for library users (bdptref.h): write with the version recorded, render a scene in-process
// exactly as `bdptref render` computes the pixels (megakernel; renderImage and makeIntegrator).
#include "bdptref/bdptref.h"
#include "bdptref/errors.h"

#include <algorithm>
#include <climits>

namespace bdptref {

namespace {

template <typename T>
void addIfAbsent(std::vector<std::pair<std::string, T>>& list, const std::string& key, const T& value) {
    for (const auto& kv : list)
        if (kv.first == key) return;
    list.emplace_back(key, value);
}

}  // namespace

void writeFilm(const std::string& path, const Film& film, const ExrMetadata& metadata, bool lightLayer) {
    ExrMetadata md = metadata;
    addIfAbsent<std::string>(md.strings, "bdptref:version", BDPTREF_VERSION);
    addIfAbsent<std::string>(md.strings, "bdptref:gitRevision", BDPTREF_GIT_REVISION);
    writeFilmExr(path, film, md, lightLayer);
}

Film renderScene(const Scene& scene, const RenderJob& job, RenderStats* stats) {
    if (job.spp < 1) throw InputError("--spp must be at least 1, got " + std::to_string(job.spp));
    if (!(job.settings.mis.beta > 0.0 && job.settings.mis.beta <= 16.0)) throw InputError("--mis-beta must be in (0, 16]");
    if (job.settings.recordStrategies && job.settings.maxDepth > 32)
        throw InputError("--strategies writes 12 layers per (s,t) strategy: use --max-depth 32 or less with it");
    if (job.settings.recordDepths && job.settings.maxDepth > 256)
        throw InputError("--depth-layers writes 6 channels per path depth: use --max-depth 256 or less with it");
    const auto integrator = makeIntegrator(job.integrator, job.settings);
    Film film(scene.camera.width(), scene.camera.height());
    if (job.settings.recordStrategies) film.enableStrategies(job.settings.maxDepth);
    if (job.settings.recordDepths) film.enableDepthLayers(job.settings.maxDepth);
    RenderOptions ro;
    ro.spp = job.spp;
    ro.firstSample = job.firstSample;
    ro.seed = job.seed;
    ro.threads = job.threads;
    const RenderStats s = renderImage(scene, *integrator, ro, film);
    if (stats) *stats = s;
    return film;
}

ExrMetadata renderMetadata(const Scene& scene, const RenderJob& job, const Film& film) {
    ExrMetadata md;
    md.strings = {{"bdptref:integrator", job.integrator},
                  {"bdptref:scene", scene.info.path},
                  {"bdptref:sceneHash", scene.info.contentHash},
                  {"bdptref:camera", scene.info.cameraSource},
                  {"bdptref:mis", job.integrator == "bdpt" ? misHeuristicName(job.settings.mis.heuristic) : "none"},
                  {"bdptref:version", BDPTREF_VERSION},
                  {"bdptref:gitRevision", BDPTREF_GIT_REVISION},
                  {"bdptref:status", "complete"},
                  {"bdptref:varianceLayers", "variance.{R,G,B} = variance of the pixel mean (s^2/n); count = samples"}};
    md.ints = {{"bdptref:spp", int(std::min<uint64_t>(film.samples().total(), INT_MAX))},
               {"bdptref:seed", int(job.seed)},
               {"bdptref:maxDepth", job.settings.maxDepth}};
    return md;
}

}  // namespace bdptref
