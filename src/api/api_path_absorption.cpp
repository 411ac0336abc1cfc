// The volume absorption of a path's segments (bdptref.h, pathAbsorption), and the check of what a
// path JSON recorded against it (path_absorption.h). The values come from segmentTransmittance,
// the function every estimator applies: nothing is re-derived here.
#include "api/path_absorption.h"

#include "render/segment_transmittance.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace bdptref {

namespace {

std::string describe(const Rgb& c) {
    char text[96];
    std::snprintf(text, sizeof text, "(%.9g, %.9g, %.9g)", double(c.r), double(c.g), double(c.b));
    return text;
}

std::string segmentName(int from) { return "x" + std::to_string(from) + "-x" + std::to_string(from + 1); }

// Channels equal up to float rounding of the recomputation (a traced path read back gives the
// same bits; a port's own path may differ in the last digits).
bool sameTransmittance(const Rgb& a, const Rgb& b) {
    for (int c = 0; c < 3; ++c)
        if (!(std::abs(double(a[c]) - double(b[c])) <= 1e-5 * std::max(std::abs(double(a[c])), std::abs(double(b[c])))))
            return false;
    return true;
}

bool readRgb(const nlohmann::ordered_json& j, Rgb* out) {
    if (!j.is_array() || j.size() != 3) return false;
    for (size_t c = 0; c < 3; ++c) {
        if (!j[c].is_number()) return false;
        (*out)[int(c)] = j[c].get<float>();
    }
    return true;
}

}  // namespace

std::vector<SegmentAbsorption> pathAbsorption(const Scene& scene, const std::vector<PathVertex>& x) {
    std::vector<SegmentAbsorption> out;
    for (size_t i = 0; i + 1 < x.size(); ++i) {
        const SegmentEnd a = vertexEnd(scene, x[i]), b = vertexEnd(scene, x[i + 1]);
        const Rgb T = segmentTransmittance(scene, a, b);
        if (T == Rgb(1.f)) continue;
        SegmentAbsorption s;
        s.from = int(i);
        s.material = segmentMedium(scene, a, b);  // >= 0: T != 1 needs a medium
        s.materialName = scene.materials[size_t(s.material)].name;
        s.sigma = scene.materials[size_t(s.material)].absorption;
        s.length = a.infinite || b.infinite ? double(kInfinity) : glm::length(DVec3(b.p) - DVec3(a.p));
        s.transmittance = T;
        out.push_back(s);
    }
    return out;
}

void compareRecordedTransmittance(const nlohmann::ordered_json& path, std::vector<SegmentAbsorption>& segments,
                                  std::vector<std::string>* warnings) {
    if (!path.is_object() || !path.contains("vertices") || !path["vertices"].is_array()) return;
    const nlohmann::ordered_json& vs = path["vertices"];
    for (size_t i = 1; i < vs.size(); ++i) {
        if (!vs[i].is_object() || !vs[i].contains("transmittance")) continue;
        const std::string where = "vertices[" + std::to_string(i) + "].transmittance";
        const int from = int(i) - 1;
        Rgb recorded;
        if (!readRgb(vs[i]["transmittance"], &recorded)) {
            warnings->push_back(where + " is not three numbers: ignored");
            continue;
        }
        SegmentAbsorption* s = nullptr;
        for (SegmentAbsorption& c : segments)
            if (c.from == from) s = &c;
        const Rgb scene = s ? s->transmittance : Rgb(1.f);
        if (s) {
            s->recorded = true;
            s->recordedTransmittance = recorded;
        }
        if (!sameTransmittance(recorded, scene))
            warnings->push_back(where + " " + describe(recorded) + " is not the scene's transmittance of the segment " +
                                segmentName(from) + ", " + describe(scene) +
                                (s ? "" : " (no absorption)") +
                                ": the path was traced in another scene, or its vertices moved");
    }
}

}  // namespace bdptref
