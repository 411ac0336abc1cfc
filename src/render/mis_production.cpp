// Production MIS weights: the pdf-ratio walk (Veach 1997 sec. 10.2; pbrt-v3's MISWeight) in double.
// Derivation: docs/mis.md, "The ratio walk"; with the light tree (MisSettings::lightSampler), the
// s' = 1 ratios of "Light tree in BDPT".
#include "bdptref/bdpt.h"
#include "render/bdpt_vertex.h"

#include <cmath>

namespace bdptref {

namespace {
// A density of zero stands for a delta distribution: it cancels between numerator and
// denominator of the ratios, so it is replaced by 1 (pbrt's remap0).
inline double remap0(double p) { return p != 0.0 ? p : 1.0; }
}  // namespace

double misWeight(const Scene& scene, const PathVertex* lightPath, int s, const PathVertex* cameraPath, int t,
                 const PathVertex& sampled, const MisSettings& mis, const SubpathBsdfs& bsdfs) {
    if (s + t == 2) return 1.0;  // emitters seen directly: only s = 0 is used (docs/mis.md)
    const double b = mis.exponent();
    // pow(r, 2) and r * r are both the correctly rounded square: the power heuristic's common case
    // skips the libm call.
    // A ratio of zero (a connection density of zero, below) is an impossible strategy for every
    // heuristic, the uniform one included.
    auto term = [b](double ratio) {
        return ratio == 0.0 ? 0.0 : b == 1.0 ? ratio : b == 2.0 ? ratio * ratio : b == 0.0 ? 1.0 : std::pow(ratio, b);
    };

    // The (at most four) vertices whose densities change for this strategy, and their new
    // reverse densities. (No copies of the vertices: clearing 4 x 104 bytes per connection cost
    // more than the walk itself.)
    const bool hasQs = s > 0, hasPt = t > 0, hasQsMinus = s > 1, hasPtMinus = t > 1;
    const PathVertex* qs = hasQs ? (s == 1 ? &sampled : &lightPath[s - 1]) : nullptr;
    const PathVertex* pt = hasPt ? (t == 1 ? &sampled : &cameraPath[t - 1]) : nullptr;
    const PathVertex* qsMinus = hasQsMinus ? &lightPath[s - 2] : nullptr;
    const PathVertex* ptMinus = hasPtMinus ? &cameraPath[t - 2] : nullptr;
    double qsRev = 0.0, ptRev = 0.0, qsMinusRev = 0.0, ptMinusRev = 0.0;

    // Reverse densities across the connection. Each surface endpoint's BSDF is used for its two
    // densities: the side array's copy, or built here once. A surface endpoint is a stored subpath
    // vertex (the fresh endpoint of s == 1 or t == 1 is a light or the camera).
    const EndpointBsdfs endpoints(scene, lightPath, s, cameraPath, t, bsdfs);
    const Bsdf* bsdfQs = hasQs && hasPt && qs->type == VertexType::Surface ? &endpoints.get().light[s - 1] : nullptr;
    const Bsdf* bsdfPt = hasPt && s > 0 && pt->type == VertexType::Surface ? &endpoints.get().camera[t - 1] : nullptr;
    auto pdfFrom = [&](const PathVertex& v, const Bsdf* bsdf, const PathVertex* prev, const PathVertex& next) {
        return bsdf ? vertexPdf(scene, v, *bsdf, prev, next) : vertexPdf(scene, v, prev, next);
    };
    if (hasPt) ptRev = s > 0 ? pdfFrom(*qs, bsdfQs, qsMinus, *pt) : lightOriginDensity(scene, *pt);
    if (hasPtMinus) ptMinusRev = s > 0 ? pdfFrom(*pt, bsdfPt, qs, *ptMinus) : pdfLightToVertex(scene, *pt, *ptMinus);
    if (hasQs) qsRev = pdfFrom(*pt, bsdfPt, ptMinus, *qs);
    if (hasQsMinus) qsMinusRev = pdfFrom(*qs, bsdfQs, pt, *qsMinus);

    // Vertex i of each subpath as this strategy sees it: its own vertex, with the reverse density
    // replaced next to the connection, and the connection endpoints evaluated through their
    // non-delta parts (delta = false).
    auto cam = [&](int i) -> const PathVertex& { return i == t - 1 ? *pt : cameraPath[i]; };
    auto lig = [&](int i) -> const PathVertex& { return i == s - 1 ? *qs : lightPath[i]; };
    // A stored reverse density of zero is a Dirac factor (remap0); one that depends on the
    // connection was evaluated through the non-delta parts, so zero there is an impossible
    // strategy (docs/mis.md, rule 5), as in the recursive form and the definition.
    auto camRev = [&](int i) { return i == t - 1 ? ptRev : i == t - 2 ? ptMinusRev : remap0(cameraPath[i].pdfRev); };
    auto ligRev = [&](int i) { return i == s - 1 ? qsRev : i == s - 2 ? qsMinusRev : remap0(lightPath[i].pdfRev); };
    auto camDelta = [&](int i) { return i != t - 1 && cameraPath[i].delta; };
    auto ligDelta = [&](int i) { return i != s - 1 && lightPath[i].delta; };

    // The s' = 1 strategy's light choice differs from the light subpath's (power) by the factor
    // nextEventPmfRatio at x_1, the vertex next to the light (docs/mis.md, "Light tree in BDPT"):
    // its ratio alone takes the factor; the walk goes on with the light subpath's densities.
    const bool tree = mis.lightSampler != LightSamplerKind::Power;
    double sum = 0.0, ri = 1.0;
    // s = 1: the strategies s' >= 2 start with the light subpath's origin density, not the sample's.
    // (A sample of density 0 is never connected; the guard keeps a hand-made one from giving NaN.)
    if (tree && s == 1) ri = qs->pdfFwd > 0.0 ? lightOriginDensity(scene, *qs) / qs->pdfFwd : 0.0;
    // Strategies with more light vertices: move the connection towards the camera.
    for (int i = t - 1; i > 0; --i) {
        ri *= camRev(i) / remap0(cam(i).pdfFwd);
        if (camDelta(i) || camDelta(i - 1)) continue;
        if (tree && s == 0 && i == t - 1)  // s' = 1: next-event estimation from x_{t-2} samples pt
            sum += term(nextEventOriginDensity(scene, mis.lightSampler, cameraPath[t - 2], *pt) / remap0(pt->pdfFwd));
        else
            sum += term(ri);
    }
    // Strategies with more camera vertices: move the connection towards the light.
    ri = 1.0;
    for (int i = s - 1; i >= 0; --i) {
        ri *= ligRev(i) / remap0(lig(i).pdfFwd);
        const bool deltaLight = i > 0 ? ligDelta(i - 1) : isDeltaLightVertex(scene, lig(0));
        if (ligDelta(i) || deltaLight) continue;
        if (tree && i == 1)  // s' = 1: next-event estimation from x_1 samples the light vertex
            sum += term(ri * nextEventPmfRatio(scene, mis.lightSampler, lig(1), lig(0).light));
        else
            sum += term(ri);
    }
    return 1.0 / (1.0 + sum);
}

}  // namespace bdptref
