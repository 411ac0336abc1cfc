// MIS weights of a path for library users (bdptref.h): the job of `bdptref mis`, with its form
// selection and messages (src/cli/cmd_mis.cpp; formats in docs/trace-and-mis.md).
#include "bdptref/bdptref.h"
#include "bdptref/errors.h"
#include "api/path_absorption.h"
#include "verify/path_json.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace bdptref {

namespace {

MisReport report(std::string form, std::vector<StrategyVerdict> verdicts, const MisSettings& mis) {
    MisReport r;
    r.form = std::move(form);
    r.strategies = std::move(verdicts);
    r.mis = mis;
    for (const StrategyVerdict& v : r.strategies) r.sum += v.weight;
    return r;
}

std::string describe(const DVec3& p) {
    char text[128];
    std::snprintf(text, sizeof text, "(%g, %g, %g)", p.x, p.y, p.z);
    return text;
}

MisReport misOfPath(const PathDescription& d, const MisPathOptions& o, const nlohmann::ordered_json* json,
                    std::vector<SegmentAbsorption>* absorption);

}  // namespace

std::vector<double> MisReport::weights() const {
    std::vector<double> w;
    w.reserve(strategies.size());
    for (const StrategyVerdict& v : strategies) w.push_back(v.weight);
    return w;
}

MisReport misWeights(const PathDensities& path, const MisSettings& mis) {
    return report("densities", analyseMisDensities(path, mis), mis);
}

MisReport misWeights(const Scene& scene, const std::vector<PathVertex>& cameraFirstPath, const MisSettings& mis) {
    validateScenePath(scene, cameraFirstPath);
    MisReport r = report("scene", analyseMisScene(scene, cameraFirstPath, mis), mis);
    r.recursive = recursiveMisOfScenePath(scene, cameraFirstPath, mis);
    return r;
}

void checkMisPathOptions(const MisPathOptions& o) {
    if (o.form != "auto" && o.form != "scene" && o.form != "densities")
        throw InputError("--form: expected auto, scene or densities, got '" + o.form + "'");
    if (o.width < 0 || o.height < 0) throw InputError("--width/--height must be positive");
    if (o.overrideBeta && !(o.beta > 0.0 && o.beta <= 16.0)) throw InputError("--mis-beta must be in (0, 16]");
}

MisReport misWeightsOfPath(const PathDescription& d, const MisPathOptions& o) { return misOfPath(d, o, nullptr, nullptr); }

namespace {

// The job of misWeightsOfPath; with the path's JSON, what it recorded is checked against the
// scene too (transmittance), and `absorption` receives the absorbed segments.
MisReport misOfPath(const PathDescription& d, const MisPathOptions& o, const nlohmann::ordered_json* json,
                    std::vector<SegmentAbsorption>* absorption) {
    if (absorption) absorption->clear();
    checkMisPathOptions(o);
    MisSettings mis = d.hasMis ? d.mis : MisSettings{};
    if (o.overrideHeuristic) mis.heuristic = o.heuristic;
    if (o.overrideBeta) mis.beta = o.beta;
    if (o.overrideLightSampler) mis.lightSampler = o.lightSampler;
    const bool sceneAvailable = !o.sceneFile.empty() || d.hasScene;
    std::string form = o.form;
    if (form == "auto") {
        if (d.hasSceneVertices && sceneAvailable) form = "scene";
        else if (d.hasDensities) form = "densities";
        else if (d.hasSceneVertices)
            throw InputError("the path has scene references but no scene: give --scene FILE (or record \"scene\" in the JSON), "
                             "or give every vertex \"pdfCamera\"/\"pdfLight\" (docs/trace-and-mis.md)");
        else
            throw InputError("the path has neither scene references (\"type\" and \"p\" on every vertex) nor densities "
                             "(\"pdfCamera\", \"pdfLight\" on every vertex, \"pdfNextEvent\" on the last): see docs/trace-and-mis.md");
    }
    if (form == "scene" && !d.hasSceneVertices) throw InputError("--form scene: every vertex needs \"type\" and \"p\"");
    if (form == "scene" && !sceneAvailable) throw InputError("--form scene: give --scene FILE (the path records no scene)");
    if (form == "densities" && !d.hasDensities)
        throw InputError("--form densities: every vertex needs \"pdfCamera\" and \"pdfLight\" (x0 may omit them) and the "
                         "last one \"pdfNextEvent\"");
    MisReport r;
    if (form == "scene") {
        SceneReference ref = d.hasScene ? d.scene : SceneReference{};
        if (!o.sceneFile.empty()) ref.file = o.sceneFile;
        if (o.width > 0) ref.width = o.width;
        if (o.height > 0) ref.height = o.height;
        if (!o.camera.empty()) ref.camera = o.camera;
        const Scene scene = loadSceneFile(ref);
        std::vector<std::string> warnings;
        if (d.hasScene && !d.scene.contentHash.empty() && d.scene.contentHash != scene.info.contentHash)
            warnings.push_back("'" + ref.file + "' is not the scene the path was traced in (content hash " +
                               scene.info.contentHash + ", recorded " + d.scene.contentHash + ")");
        const std::vector<PathVertex> vertices = verticesInRenderSpace(d, scene);
        validateScenePath(scene, vertices);
        const DVec3 eye = scene.toWorld(scene.camera.position()), x0 = d.worldPositions[0];
        // (An orthographic camera's vertex 0 is a film point: anywhere on the film plane.)
        if (!scene.camera.isOrthographic() && glm::length(x0 - eye) > 1e-4 * std::max(1.0, glm::length(eye)))
            warnings.push_back("vertex 0 " + describe(x0) + " is not at the scene camera's position " + describe(eye) +
                               ": the camera's direction density is evaluated from vertex 0 with the scene's camera");
        r = report("scene", analyseMisScene(scene, vertices, mis), mis);
        r.recursive = recursiveMisOfScenePath(scene, vertices, mis);
        // Absorption: shown beside the weights, which do not depend on it (bdptref.h).
        std::vector<SegmentAbsorption> absorbed = pathAbsorption(scene, vertices);
        if (json) compareRecordedTransmittance(*json, absorbed, &warnings);
        if (absorption) *absorption = std::move(absorbed);
        r.warnings = std::move(warnings);
        r.sceneFile = ref.file;
    } else {
        r = report("densities", analyseMisDensities(d.densities, mis), mis);
    }
    r.producedBy = d.s;
    return r;
}

}  // namespace

MisReport misWeightsOfPathJson(const std::string& jsonText, const MisPathOptions& options) {
    checkMisPathOptions(options);
    nlohmann::ordered_json j;
    try {
        j = nlohmann::ordered_json::parse(jsonText);
    } catch (const nlohmann::json::exception& e) {
        throw InputError(std::string("the path is not valid JSON: ") + e.what());
    }
    return misOfPath(pathFromJson(j), options, &j, nullptr);
}

MisReport misWeightsOfPathFile(const std::string& file, const MisPathOptions& options, int s, int t) {
    return misWeightsOfPathFile(file, options, s, t, nullptr);
}

MisReport misWeightsOfPathFile(const std::string& file, const MisPathOptions& options, int s, int t,
                               std::vector<SegmentAbsorption>* absorption) {
    checkMisPathOptions(options);  // option errors first, as `bdptref mis` reports them
    const nlohmann::ordered_json json = readPathJson(file, s, t);
    return misOfPath(pathFromFileJson(json, file), options, &json, absorption);
}

}  // namespace bdptref
