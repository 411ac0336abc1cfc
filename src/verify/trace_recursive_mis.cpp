// The recursive MIS quantities of a full scene path, for `bdptref mis` (docs/trace-and-mis.md):
// the path is read as one camera subpath x_0..x_{n-1} and one light subpath x_{n-1}..x_0, whose
// densities and dVCM/dVC the renderer's own functions fill (fillSubpathDensities); strategy (s, t)
// then reads the camera subpath's vertex t-1 and the light subpath's vertex s-1, exactly as a
// render whose subpaths were these prefixes would (docs/mis.md, "The recursive form").
#include "bdptref/bdpt.h"
#include "bdptref/trace.h"
#include "render/bdpt_vertex.h"

namespace bdptref {

RecursiveMisPath recursiveMisOfScenePath(const Scene& scene, const std::vector<PathVertex>& x, const MisSettings& mis) {
    RecursiveMisPath out;
    const int n = int(x.size());
    if (n < 2) return out;
    std::vector<PathVertex> camera(x), light(x.rbegin(), x.rend());
    // A path found by s = 0 ends on a surface that lies on an area light: as the light subpath's
    // origin it is the light's vertex (its emission densities, c_0 of the recursion), as a render's
    // light subpath stores it.
    if (light[0].type == VertexType::Surface && light[0].light >= 0) light[0].type = VertexType::Light;
    camera[0].pdfFwd = 1.0;  // set where the subpaths begin (the pinhole; the light's origin density)
    light[0].pdfFwd = lightOriginDensity(scene, light[0]);
    fillSubpathDensities(scene, camera.data(), n, mis);
    fillSubpathDensities(scene, light.data(), n, mis);
    out.vertices.resize(size_t(n));
    for (int i = 0; i < n; ++i) {
        const PathVertex &c = camera[size_t(i)], &l = light[size_t(n - 1 - i)];
        out.vertices[size_t(i)] = RecursiveMisVertex{c.dVCM, c.dVC, l.dVCM, l.dVC};
    }
    // Weights of the strategies that can sample the path (the definition says which).
    const std::vector<double> definition = misWeightsDefinition(scene, x, mis);
    out.weights.assign(size_t(n), 0.0);
    for (int s = 0; s < n; ++s) {
        if (!(definition[size_t(s)] > 0.0)) continue;
        const int t = n - s;
        // The fresh endpoint of t = 1 / s = 1; s = 1's light vertex with the density of next-event
        // estimation from x_{t-1} (the light subpath's origin density with the power sampler).
        PathVertex sampled = t == 1 ? camera[0] : light[0];
        if (s == 1 && t >= 2) sampled.pdfFwd = nextEventOriginDensity(scene, mis.lightSampler, camera[size_t(t - 1)], light[0]);
        const ConnectionDensities d = connectionDensities(scene, light.data(), s, camera.data(), t, sampled, mis);
        out.weights[size_t(s)] = misWeightRecursive(scene, light.data(), s, camera.data(), t, sampled, d, mis);
    }
    return out;
}

}  // namespace bdptref
