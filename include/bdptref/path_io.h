// JSON (de)serialisation of paths and of a traced pixel sample (nlohmann/json). The formats are
// specified in docs/trace-and-mis.md:
//   * "bdptref-trace" (version 1): what `bdptref trace` prints - settings, both subpaths, every
//     (s, t) connection, the sample's totals;
//   * "bdptref-path" (version 1): one full path, camera first, in the input format of
//     `bdptref mis` - vertices with scene references (the scene form) and/or explicit densities
//     (the densities form). `trace` writes the path of every contributing connection in it.
// Numbers are written with full precision (floats as the doubles they convert to exactly), so a
// path read back is bit-identical; non-finite numbers are written as the strings "inf", "-inf",
// "nan".
#pragma once

#include "bdptref/bdpt.h"
#include "bdptref/path_vertex.h"
#include "bdptref/trace.h"

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace bdptref {

class Scene;

// How to load the scene a path refers to: the options of `bdptref trace` / `render` that change
// the scene or its camera (see src/cli/scene_options.h). `file` is stored as an absolute path.
struct SceneReference {
    std::string file;
    int width = 256, height = 256;            // 0 = from the camera's aspect (docs/camera.md)
    std::string env;                          // "R,G,B" or empty
    std::string envMap;                       // --env-map FILE or empty (docs/lights.md, "Environment")
    double envScale = 1.0, envRotate = 0.0;   // --env-scale, --env-rotate (degrees)
    std::string camera;                       // --camera N|NAME ("" = the file's first)
    std::string cameraPos, cameraTarget, cameraUp = "0,1,0";
    double fov = 0.0;                         // degrees; 0 = the scene's
    std::string crop;                         // "x0,y0,x1,y1" or empty
    std::string contentHash;                  // of the scene as traced (a mismatch is reported)
};

// A full path as `bdptref mis` reads it. Positions in the JSON are world coordinates
// (docs/trace-and-mis.md, "Coordinates"): verticesInRenderSpace() gives the vertices the scene's
// functions take.
struct PathDescription {
    std::vector<PathVertex> vertices;  // scene form: type, p, ng, ns, uv, material, light, delta, infinite;
                                       // p: the world position rounded to float
    std::vector<DVec3> worldPositions;  // "p" of each vertex as written (world coordinates, double)
    std::vector<uint8_t> hasBary;       // 1 where the vertex gave "bary" (else computed from p)
    bool hasSceneVertices = false;     // every vertex has at least "type" and "p"
    PathDensities densities;           // densities form
    bool hasDensities = false;         // every vertex has "pdfCamera" (x_0 may omit it) and "pdfLight"
                                       // (x_0 may omit it), and x_{n-1} has "pdfNextEvent"
    bool hasScene = false;
    SceneReference scene;
    bool hasMis = false;
    MisSettings mis;
    int s = -1;  // the strategy that produced the path, when recorded (informational)
};

std::string misHeuristicName(MisHeuristic h);  // "balance" | "power" | "uniform"
nlohmann::ordered_json misToJson(const MisSettings& mis);
nlohmann::ordered_json sceneReferenceToJson(const SceneReference& ref);

// A subpath vertex with every field (index = its position in the subpath). With a scene, "p" is
// written in world coordinates (scene.toWorld) and the material's name and the light's type are
// added; without one, p is written as it is.
nlohmann::ordered_json vertexToJson(const PathVertex& v, int index, const Scene* scene);

// A full path (camera first) in the "bdptref-path" format. densities, scene, ref, mis: optional
// (null: not written). s >= 0 records the producing strategy.
nlohmann::ordered_json pathToJson(const std::vector<PathVertex>& path, const PathDensities* densities, const Scene* scene,
                          const SceneReference* ref, const MisSettings* mis, int s = -1);

// Parses a "bdptref-path" object. Throws InputError naming the offending field.
PathDescription pathFromJson(const nlohmann::ordered_json& j);
// The scene-form vertices moved into the scene's render space (p = scene.toRender(world p)).
std::vector<PathVertex> verticesInRenderSpace(const PathDescription& d, const Scene& scene);
// Reads and parses a file; a trace ("bdptref-trace") is accepted with a strategy (s, t) to pick
// the path of that contributing connection (s < 0: the file must be a path). Throws InputError
// (missing file, malformed JSON, bad fields).
PathDescription readPathFile(const std::string& file, int s = -1, int t = -1);

// The whole trace in the "bdptref-trace" format.
nlohmann::ordered_json traceToJson(const TracedSample& sample, const Scene& scene, const SceneReference* ref);

// Indented JSON with arrays of numbers (vectors, weights) kept on one line; keys in the order
// written above. Ends with a newline.
std::string formatJson(const nlohmann::ordered_json& j);

}  // namespace bdptref
