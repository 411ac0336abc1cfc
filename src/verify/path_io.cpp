// JSON formats of `bdptref trace` and `bdptref mis` (docs/trace-and-mis.md).
#include "bdptref/path_io.h"

#include "bdptref/errors.h"
#include "bdptref/light.h"
#include "bdptref/scene.h"
#include "render/segment_transmittance.h"
#include "verify/path_json.h"

#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

namespace bdptref {

using json = nlohmann::ordered_json;

namespace {

// Non-finite numbers are not JSON: write them as strings.
json num(double v) {
    if (std::isfinite(v)) return v;
    if (std::isnan(v)) return "nan";
    return v > 0 ? "inf" : "-inf";
}
json vec(const Vec3& v) { return json::array({num(v.x), num(v.y), num(v.z)}); }
json vec(const Vec2& v) { return json::array({num(v.x), num(v.y)}); }
json vec(const DVec3& v) { return json::array({num(v.x), num(v.y), num(v.z)}); }

// Volume absorption along the segment a-b, written only where it is not 1 (docs/materials.md).
void addTransmittance(json& o, const Scene* scene, const PathVertex& a, const PathVertex& b) {
    if (!scene) return;
    const Rgb T = segmentTransmittance(*scene, vertexEnd(*scene, a), vertexEnd(*scene, b));
    if (T != Rgb(1.f)) o["transmittance"] = vec(T);
}

const char* typeName(VertexType t) {
    switch (t) {
    case VertexType::Camera: return "camera";
    case VertexType::Light: return "light";
    case VertexType::Surface: return "surface";
    }
    return "?";
}


// Scene references of a vertex (what the definition needs), plus names for people.
void sceneFields(json& o, const PathVertex& v, const Scene* scene) {
    o["type"] = typeName(v.type);
    // Users and ports see world coordinates: render space + the scene's worldOrigin, in double
    // (docs/trace-and-mis.md, "Coordinates").
    o["p"] = scene ? vec(scene->toWorld(v.p)) : vec(v.p);
    o["ng"] = vec(v.ng);
    o["ns"] = vec(v.ns);
    o["bary"] = vec(v.bary);
    if (scene && v.type == VertexType::Surface) o["uv"] = vec(scene->attributes(v.triangle, v.bary).uv[0]);
    if (v.type == VertexType::Surface) {
        o["material"] = v.material;
        if (scene && v.material < scene->materials.size()) o["materialName"] = scene->materials[v.material].name;
    }
    if (v.light >= 0) {
        o["light"] = v.light;
        if (scene && size_t(v.light) < scene->lights.size()) o["lightType"] = lightTypeName(scene->lights[size_t(v.light)].type);
    }
    if (v.type != VertexType::Camera) o["triangle"] = v.triangle;
    o["delta"] = v.delta;
    o["infinite"] = v.infinite;
}

// ---- reading ----------------------------------------------------------------------------------

[[noreturn]] void bad(const std::string& where, const std::string& what) { throw InputError(where + ": " + what); }

double readNumber(const json& j, const std::string& where) {
    if (j.is_number()) return j.get<double>();
    if (j.is_string()) {
        const std::string s = j.get<std::string>();
        if (s == "inf") return std::numeric_limits<double>::infinity();
        if (s == "-inf") return -std::numeric_limits<double>::infinity();
        if (s == "nan") return std::numeric_limits<double>::quiet_NaN();
    }
    bad(where, "expected a number, got " + j.dump());
}

int readInt(const json& j, const std::string& where) {
    if (!j.is_number_integer()) bad(where, "expected an integer, got " + j.dump());
    const long long v = j.get<long long>();
    if (v < -2147483647LL || v > 2147483647LL) bad(where, "integer out of range");
    return int(v);
}

bool readBool(const json& j, const std::string& where) {
    if (!j.is_boolean()) bad(where, "expected true or false, got " + j.dump());
    return j.get<bool>();
}

std::string readString(const json& j, const std::string& where) {
    if (!j.is_string()) bad(where, "expected a string, got " + j.dump());
    return j.get<std::string>();
}

DVec3 readPosition(const json& j, const std::string& where) {
    if (!j.is_array() || j.size() != 3) bad(where, "expected an array of 3 numbers, got " + j.dump());
    DVec3 v;
    for (int i = 0; i < 3; ++i) {
        v[i] = readNumber(j[size_t(i)], where);
        if (!std::isfinite(v[i])) bad(where, "components must be finite");
    }
    return v;
}

template <int N>
glm::vec<N, float> readVec(const json& j, const std::string& where) {
    if (!j.is_array() || j.size() != size_t(N)) bad(where, "expected an array of " + std::to_string(N) + " numbers, got " + j.dump());
    glm::vec<N, float> v;
    for (int i = 0; i < N; ++i) {
        const double d = readNumber(j[size_t(i)], where);
        if (!std::isfinite(d)) bad(where, "components must be finite");
        v[i] = float(d);
    }
    return v;
}

double readDensity(const json& j, const std::string& where) {
    const double d = readNumber(j, where);
    if (std::isnan(d) || d < 0.0)
        bad(where, "a density must be >= 0 (0: that side cannot sample the vertex), got " + j.dump());
    return d;
}

VertexType readType(const json& j, const std::string& where) {
    const std::string s = readString(j, where);
    if (s == "camera") return VertexType::Camera;
    if (s == "light") return VertexType::Light;
    if (s == "surface") return VertexType::Surface;
    bad(where, "expected \"camera\", \"light\" or \"surface\", got \"" + s + "\"");
}

}  // namespace

std::string misHeuristicName(MisHeuristic h) {
    return h == MisHeuristic::Balance ? "balance" : h == MisHeuristic::Power ? "power" : "uniform";
}

json misToJson(const MisSettings& mis) {
    json j{{"heuristic", misHeuristicName(mis.heuristic)}, {"beta", mis.beta}, {"exponent", mis.exponent()}};
    // s = 1's light choice (docs/mis.md, "Light tree in BDPT"); absent: power, as before it existed.
    if (mis.lightSampler != LightSamplerKind::Power) j["lightSampler"] = lightSamplerName(mis.lightSampler);
    return j;
}

json sceneReferenceToJson(const SceneReference& r) {
    json o{{"file", r.file}, {"width", r.width}, {"height", r.height}};
    if (!r.env.empty()) o["env"] = r.env;
    if (!r.envMap.empty()) {
        o["envMap"] = r.envMap;
        o["envScale"] = r.envScale;
        o["envRotate"] = r.envRotate;
    }
    if (!r.camera.empty()) o["camera"] = r.camera;
    if (!r.cameraPos.empty()) {
        o["cameraPos"] = r.cameraPos;
        o["cameraTarget"] = r.cameraTarget;
        o["cameraUp"] = r.cameraUp;
    }
    if (r.fov != 0.0) o["fov"] = r.fov;
    if (!r.crop.empty()) o["crop"] = r.crop;
    if (!r.contentHash.empty()) o["contentHash"] = r.contentHash;
    return o;
}

json vertexToJson(const PathVertex& v, int index, const Scene* scene) {
    json o;
    o["index"] = index;
    sceneFields(o, v, scene);
    o["wo"] = vec(v.wo);
    o["beta"] = vec(v.beta);
    o["pdfFwd"] = num(v.pdfFwd);
    o["pdfRev"] = num(v.pdfRev);
    o["dVCM"] = num(v.dVCM);  // recursive MIS quantities (docs/mis.md, "The recursive form")
    o["dVC"] = num(v.dVC);
    return o;
}

json pathToJson(const std::vector<PathVertex>& path, const PathDensities* densities, const Scene* scene,
                const SceneReference* ref, const MisSettings* mis, int s) {
    json o;
    o["format"] = "bdptref-path";
    o["version"] = 1;
    const int n = int(path.size());
    if (s >= 0) o["strategy"] = json{{"s", s}, {"t", n - s}};
    o["depth"] = n - 2;
    if (ref) o["scene"] = sceneReferenceToJson(*ref);
    if (mis) o["mis"] = misToJson(*mis);
    json vs = json::array();
    for (int i = 0; i < n; ++i) {
        json v;
        v["index"] = i;
        sceneFields(v, path[size_t(i)], scene);
        if (i > 0) addTransmittance(v, scene, path[size_t(i - 1)], path[size_t(i)]);  // of the segment from vertex i - 1
        if (densities && size_t(i) < densities->vertices.size()) {
            const VertexDensities& d = densities->vertices[size_t(i)];
            v["pdfCamera"] = num(d.camera);
            if (i > 0) v["pdfLight"] = num(d.light);
            if (i == n - 1) {
                v["pdfNextEvent"] = num(densities->lightNextEvent);
                v["deltaLight"] = densities->deltaLight;
            }
        }
        vs.push_back(v);
    }
    o["vertices"] = vs;
    return o;
}

PathDescription pathFromJson(const json& j) {
    if (!j.is_object()) bad("path", "expected a JSON object with \"vertices\"");
    if (j.contains("format")) {
        const std::string f = readString(j["format"], "format");
        if (f == "bdptref-trace")
            bad("format", "this is a whole trace; pick one connection's path (bdptref mis FILE --strategy S,T, or "
                          "bdptref trace ... --path S,T)");
        if (f != "bdptref-path") bad("format", "expected \"bdptref-path\", got \"" + f + "\"");
    }
    if (j.contains("version") && readInt(j["version"], "version") != 1) bad("version", "only version 1 is known");
    if (!j.contains("vertices") || !j["vertices"].is_array()) bad("vertices", "missing (an array of vertex objects, camera first)");
    const json& vs = j["vertices"];
    const int n = int(vs.size());
    if (n < 2) bad("vertices", "a full path needs at least 2 vertices (the camera and a point on a light), got " + std::to_string(n));

    PathDescription d;
    d.vertices.resize(size_t(n));
    d.worldPositions.resize(size_t(n));
    d.hasBary.assign(size_t(n), 0);
    d.densities.vertices.resize(size_t(n));
    bool allScene = true, allDensities = true;
    for (int i = 0; i < n; ++i) {
        const json& v = vs[size_t(i)];
        const std::string where = "vertices[" + std::to_string(i) + "]";
        if (!v.is_object()) bad(where, "expected an object");
        PathVertex& p = d.vertices[size_t(i)];
        VertexDensities& dv = d.densities.vertices[size_t(i)];
        if (v.contains("delta")) p.delta = dv.delta = readBool(v["delta"], where + ".delta");
        if (v.contains("infinite")) p.infinite = readBool(v["infinite"], where + ".infinite");
        // Scene form.
        if (v.contains("type") && v.contains("p")) {
            p.type = readType(v["type"], where + ".type");
            d.worldPositions[size_t(i)] = readPosition(v["p"], where + ".p");
            p.p = Vec3(d.worldPositions[size_t(i)]);
            if (v.contains("ng")) p.ng = readVec<3>(v["ng"], where + ".ng");
            else if (p.type == VertexType::Surface || p.infinite) bad(where, "a surface or infinite-light vertex needs \"ng\"");
            p.ns = v.contains("ns") ? readVec<3>(v["ns"], where + ".ns") : p.ng;
            if (v.contains("bary")) p.bary = readVec<2>(v["bary"], where + ".bary");
            d.hasBary[size_t(i)] = v.contains("bary") ? 1 : 0;
            if (v.contains("material")) {
                const int m = readInt(v["material"], where + ".material");
                if (m < 0) bad(where + ".material", "must be >= 0");
                p.material = uint32_t(m);
            } else if (p.type == VertexType::Surface) {
                bad(where, "a surface vertex needs \"material\" (its index in the scene)");
            }
            if (v.contains("light")) p.light = readInt(v["light"], where + ".light");
            if (v.contains("triangle")) {
                const int tri = readInt(v["triangle"], where + ".triangle");
                if (tri < 0) bad(where + ".triangle", "must be >= 0");
                p.triangle = uint32_t(tri);
            }
        } else {
            allScene = false;
        }
        // Densities form.
        if (v.contains("pdfCamera")) dv.camera = readDensity(v["pdfCamera"], where + ".pdfCamera");
        else if (i == 0) dv.camera = 1.0;  // the pinhole
        else allDensities = false;
        if (v.contains("pdfLight")) dv.light = readDensity(v["pdfLight"], where + ".pdfLight");
        else if (i > 0) allDensities = false;
        if (i == n - 1) {
            if (v.contains("pdfNextEvent")) d.densities.lightNextEvent = readDensity(v["pdfNextEvent"], where + ".pdfNextEvent");
            else if (n > 2) allDensities = false;
            if (v.contains("deltaLight")) d.densities.deltaLight = readBool(v["deltaLight"], where + ".deltaLight");
        }
    }
    d.hasSceneVertices = allScene;
    d.hasDensities = allDensities;

    if (j.contains("scene") && !j["scene"].is_null()) {
        const json& s = j["scene"];
        if (!s.is_object() || !s.contains("file")) bad("scene", "expected an object with \"file\"");
        SceneReference& r = d.scene;
        r.file = readString(s["file"], "scene.file");
        if (s.contains("width")) r.width = readInt(s["width"], "scene.width");
        if (s.contains("height")) r.height = readInt(s["height"], "scene.height");
        if (s.contains("env")) r.env = readString(s["env"], "scene.env");
        if (s.contains("envMap")) r.envMap = readString(s["envMap"], "scene.envMap");
        if (s.contains("envScale")) r.envScale = readNumber(s["envScale"], "scene.envScale");
        if (s.contains("envRotate")) r.envRotate = readNumber(s["envRotate"], "scene.envRotate");
        if (s.contains("camera")) r.camera = readString(s["camera"], "scene.camera");
        if (s.contains("cameraPos")) r.cameraPos = readString(s["cameraPos"], "scene.cameraPos");
        if (s.contains("cameraTarget")) r.cameraTarget = readString(s["cameraTarget"], "scene.cameraTarget");
        if (s.contains("cameraUp")) r.cameraUp = readString(s["cameraUp"], "scene.cameraUp");
        if (s.contains("fov")) r.fov = readNumber(s["fov"], "scene.fov");
        if (s.contains("crop")) r.crop = readString(s["crop"], "scene.crop");
        if (s.contains("contentHash")) r.contentHash = readString(s["contentHash"], "scene.contentHash");
        d.hasScene = true;
    }
    if (j.contains("mis") && !j["mis"].is_null()) {
        const json& m = j["mis"];
        if (!m.is_object()) bad("mis", "expected {\"heuristic\": \"balance|power|uniform\", \"beta\": 2}");
        if (m.contains("heuristic")) d.mis.heuristic = parseMisHeuristic(readString(m["heuristic"], "mis.heuristic"));
        if (m.contains("beta")) d.mis.beta = readNumber(m["beta"], "mis.beta");
        if (!(d.mis.beta > 0.0 && d.mis.beta <= 16.0)) bad("mis.beta", "must be in (0, 16]");
        if (m.contains("lightSampler")) {
            const std::string ls = readString(m["lightSampler"], "mis.lightSampler");
            if (ls != "power" && ls != "tree") bad("mis.lightSampler", "expected \"power\" or \"tree\"");
            d.mis.lightSampler = ls == "tree" ? LightSamplerKind::Tree : LightSamplerKind::Power;
        }
        d.hasMis = true;
    }
    if (j.contains("strategy") && j["strategy"].is_object() && j["strategy"].contains("s"))
        d.s = readInt(j["strategy"]["s"], "strategy.s");
    if (d.s >= n) bad("strategy.s", "must be < the number of vertices");
    return d;
}

std::vector<PathVertex> verticesInRenderSpace(const PathDescription& d, const Scene& scene) {
    std::vector<PathVertex> v = d.vertices;
    for (size_t i = 0; i < v.size() && i < d.worldPositions.size(); ++i) {
        v[i].p = scene.toRender(d.worldPositions[i]);
        // A path written without barycentrics: the surface point's own (textures depend on them).
        const bool hasBary = i < d.hasBary.size() && d.hasBary[i];
        if (!hasBary && v[i].type == VertexType::Surface) v[i].bary = scene.barycentricsOf(v[i].triangle, v[i].p);
        // ... and a point on an area light (an emissive texture is evaluated there).
        if (!hasBary && v[i].type == VertexType::Light && v[i].light >= 0 && size_t(v[i].light) < scene.lights.size() &&
            scene.lights[size_t(v[i].light)].type == LightType::Area)
            v[i].bary = scene.barycentricsOf(scene.lights[size_t(v[i].light)].triangle, v[i].p);
    }
    return v;
}

json readPathJson(const std::string& file, int s, int t) {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw InputError("cannot open '" + file + "'");
    json j;
    try {
        j = json::parse(in);
    } catch (const json::parse_error& e) {
        throw InputError("'" + file + "' is not valid JSON: " + e.what());
    }
    if (j.is_object() && j.contains("format") && j["format"] == "bdptref-trace") {
        if (s < 0)
            throw InputError("'" + file + "' is a whole trace: choose the connection with --strategy S,T");
        if (j.contains("connections") && j["connections"].is_array())
            for (const json& c : j["connections"])
                if (c.is_object() && c.value("s", -1) == s && c.value("t", -1) == t) {
                    if (!c.contains("path"))
                        throw InputError("'" + file + "': connection (" + std::to_string(s) + "," + std::to_string(t) +
                                         ") did not contribute (" + c.value("status", std::string("?")) +
                                         "), so it has no path");
                    return c["path"];
                }
        throw InputError("'" + file + "': the trace has no connection (" + std::to_string(s) + "," + std::to_string(t) + ")");
    }
    return j;
}

PathDescription pathFromFileJson(const json& path, const std::string& file) {
    try {
        return pathFromJson(path);
    } catch (const InputError& e) {
        throw InputError("'" + file + "': " + e.what());
    }
}

PathDescription readPathFile(const std::string& file, int s, int t) { return pathFromFileJson(readPathJson(file, s, t), file); }

json traceToJson(const TracedSample& ts, const Scene& scene, const SceneReference* ref) {
    json o;
    o["format"] = "bdptref-trace";
    o["version"] = 1;
    const BdptSettings& b = ts.settings.bdpt;
    const Camera& cam = scene.camera;
    json settings{{"integrator", ts.settings.integrator},
                  {"mode", ts.mode},
                  {"seed", ts.settings.seed},
                  {"pixel", json::array({ts.x, ts.y})},
                  {"pixelIndex", ts.pixelIndex},
                  {"sample", ts.sample},
                  {"imageWidth", cam.width()},
                  {"imageHeight", cam.height()},
                  {"window", json::array({cam.cropX0(), cam.cropY0(), cam.cropX1(), cam.cropY1()})},
                  {"maxDepth", b.maxDepth},
                  {"rouletteStartDepth", b.rouletteStartDepth},
                  {"mis", misToJson(b.mis)},
                  {"sceneHash", scene.info.contentHash},
                  {"worldOrigin", vec(scene.worldOrigin)}};
    if (ref) settings["scene"] = sceneReferenceToJson(*ref);
    o["settings"] = settings;
    o["rng"] = json{{"generator", "philox4x32-10"},
                    {"key", json::array({ts.pixelIndex, ts.settings.seed})},
                    {"counter", "(dimension, sample & 0xffffffff, sample >> 32, stream); stream 0 camera, 1 light"},
                    {"sampleWords", json::array({uint32_t(ts.sample), uint32_t(ts.sample >> 32)})},
                    {"camera", json{{"film", vec(ts.raster - Vec2(float(ts.x), float(ts.y)))}}},
                    {"light", json{{"lightChoice", num(ts.lightChoice)},
                                   {"emitPosition", vec(ts.emitPosition)},
                                   {"emitDirection", vec(ts.emitDirection)}}}};
    o["raster"] = vec(ts.raster);

    auto subpath = [&](const std::vector<PathVertex>& p, const std::vector<VertexRandom>& rnd, bool cameraStream) {
        json a = json::array();
        for (size_t i = 0; i < p.size(); ++i) {
            json v = vertexToJson(p[i], int(i), &scene);
            if (i >= 1) addTransmittance(v, &scene, p[i - 1], p[i]);  // of the segment that found it
            if (i >= 1 && p[i].type == VertexType::Surface && i < rnd.size()) {
                const VertexRandom& r = rnd[i];
                json rj{{"bounce", r.bounce},
                        {"dimensionBase", r.dimensionBase},
                        {"bsdfLobe", num(r.bsdfLobe)},
                        {"bsdfDirection", vec(r.bsdfDirection)},
                        {"roulette", num(r.roulette)}};
                if (cameraStream) {
                    rj["neeLight"] = num(r.neeLight);
                    rj["neePosition"] = vec(r.neePosition);
                }
                v["random"] = rj;
            }
            a.push_back(v);
        }
        return a;
    };
    o["cameraSubpath"] = subpath(ts.cameraPath, ts.cameraRandom, true);
    o["lightSubpath"] = subpath(ts.lightPath, ts.lightRandom, false);

    const int x0 = cam.cropX0(), y0 = cam.cropY0(), x1 = cam.cropX1(), y1 = cam.cropY1();
    json conns = json::array(), splats = json::array();
    int contributions = 0;
    for (const TracedConnection& c : ts.connections) {
        json cj{{"s", c.s}, {"t", c.t}, {"depth", c.depth}, {"status", connectionStatusName(c.status)}};
        if (c.status != ConnectionStatus::Contributed) {
            cj["reason"] = c.reason;
            conns.push_back(cj);
            continue;
        }
        ++contributions;
        cj["unweighted"] = vec(c.unweighted);
        cj["weight"] = num(c.weight);
        cj["weighted"] = vec(c.weighted);
        if (c.s >= 1 && c.t >= 1) {  // the connection segment's absorption (included in unweighted)
            const PathVertex* l = c.s == 1 && c.t > 1 ? &c.sampled
                                  : size_t(c.s) <= ts.lightPath.size() ? &ts.lightPath[size_t(c.s) - 1] : nullptr;
            const PathVertex* e = c.t == 1 ? &c.sampled : size_t(c.t) <= ts.cameraPath.size() ? &ts.cameraPath[size_t(c.t) - 1] : nullptr;
            if (l && e) addTransmittance(cj, &scene, *l, *e);
        }
        cj["splat"] = c.splat;
        if (c.splat) {
            const int px = int(std::floor(c.raster.x)), py = int(std::floor(c.raster.y));
            const bool inWindow = px >= x0 && px < x1 && py >= y0 && py < y1;
            cj["raster"] = vec(c.raster);
            cj["pixel"] = json::array({px, py});
            cj["inWindow"] = inWindow;
            splats.push_back(json{{"s", c.s}, {"t", c.t}, {"raster", vec(c.raster)}, {"pixel", json::array({px, py})},
                                  {"inWindow", inWindow}, {"value", vec(c.weighted)}});
        }
        if (c.hasSampled) cj["sampled"] = vertexToJson(c.sampled, 0, &scene);
        if (!c.path.empty()) {
            json w = json::array();
            for (double v : c.definitionWeights) w.push_back(num(v));
            cj["definitionWeights"] = w;
            if (size_t(c.s) < c.definitionWeights.size()) {
                cj["definitionWeight"] = num(c.definitionWeights[size_t(c.s)]);
                cj["weightDifference"] = num(c.weight - c.definitionWeights[size_t(c.s)]);
            }
            json cannot = json::array();
            double sum = 0.0;
            for (const StrategyVerdict& v : c.strategies) {
                if (!v.valid) cannot.push_back(json{{"s", v.s}, {"t", v.t}, {"reason", v.reason}});
            }
            for (double v : c.definitionWeights) sum += v;
            cj["definitionWeightSum"] = num(sum);
            cj["cannotSample"] = cannot;
            cj["path"] = pathToJson(c.path, &c.densities, &scene, ref, &b.mis, c.s);
        }
        conns.push_back(cj);
    }
    o["connections"] = conns;
    o["total"] = json{{"L", vec(ts.L)},
                      {"splats", splats},
                      {"contributions", contributions},
                      {"note", "L is the camera-side estimate this sample adds to its own pixel; each splat is added "
                               "to the pixel it lands in when inWindow (the film's per-pass value of a pixel is its L "
                               "plus the splats of every pixel's light subpath that land in it)"}};
    return o;
}

namespace {
void formatInto(const json& j, int indent, std::string& out) {
    const std::string pad(size_t(indent) * 2, ' '), inner(size_t(indent + 1) * 2, ' ');
    if (j.is_object()) {
        if (j.empty()) {
            out += "{}";
            return;
        }
        out += "{\n";
        size_t k = 0;
        for (auto it = j.begin(); it != j.end(); ++it, ++k) {
            out += inner + json(it.key()).dump() + ": ";
            formatInto(it.value(), indent + 1, out);
            out += k + 1 < j.size() ? ",\n" : "\n";
        }
        out += pad + "}";
    } else if (j.is_array()) {
        bool scalars = true;
        for (const json& e : j) scalars = scalars && !e.is_structured();
        if (scalars) {
            out += j.dump(-1, ' ', false);
            return;
        }
        out += "[\n";
        for (size_t k = 0; k < j.size(); ++k) {
            out += inner;
            formatInto(j[k], indent + 1, out);
            out += k + 1 < j.size() ? ",\n" : "\n";
        }
        out += pad + "]";
    } else {
        out += j.dump();
    }
}
}  // namespace

std::string formatJson(const json& j) {
    std::string out;
    formatInto(j, 0, out);
    out += "\n";
    return out;
}

}  // namespace bdptref
