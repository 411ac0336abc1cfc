// Production MIS weights in the recursive form: the dVCM/dVC quantities of Georgiev et al. 2012
// ("Implementing VCM") / van Antwerpen 2011, restricted to BDPT (no merging), with pbrt-v3's
// conventions for delta vertices so that the weights equal the ratio walk (mis_production.cpp)
// and the definition (mis_definition.cpp). Derivation with these names: docs/mis.md, "The
// recursive form".
//
// Every vertex x_j of a subpath carries, for the heuristic's exponent b and P(p) = misPower(p, b):
//   dVCM(j) = c_j / P(pdfFwd(j))                      c_j: a connection x_{j-1}--x_j is possible
//   dVC(j)  = P(g_{j-1}) / (P(pdfFwd(j)) P(pdfFwd(j-1))) * (valid_{j-1} + A(j-2))
// where g_{j-1} = convertDensity(1, x_j, x_{j-1}) turns a density at x_j towards x_{j-1} into
// x_{j-1}'s measure, valid_i = !delta(i) && c_i, and A(i) = sum of the ratio walk's terms of the
// strategies that connect at or before x_i (their ratios use only stored densities):
//   A(-1) = 0,  A(i) = P(pdfRev(i)) / P(pdfFwd(i)) * (valid_i + A(i-1)).
// The connection supplies the four densities that depend on it (ConnectionDensities) and
//   w = 1 / (1 + P(ptRev) (dVCM(pt) + P(ptPrevRev) dVC(pt)) + P(qsRev) (dVCM(qs) + P(qsPrevRev) dVC(qs))).
// With a next-event sampler other than the light subpaths' power sampler (MisSettings::lightSampler,
// docs/mis.md "Light tree in BDPT"), the s' = 1 strategy's density of the light vertex differs from
// the light subpath's by rho = pmf_tree(x_1) / pmf_power: light subpath vertex 1 weighs strategy 1
// by P(rho) in place of valid_1, s = 0 takes the s' = 1 term with ptRevNextEvent, and s = 1 scales
// ptRev by pmf_power / pmf_tree (its own density is the fresh sample's pdfFwd).
#include "bdptref/bdpt.h"
#include "render/bdpt_vertex.h"
#include "render/mis.h"

namespace bdptref {

namespace {

// A stored density of zero stands for a Dirac factor (a vertex sampled through a delta lobe):
// pbrt's convention makes it 1 (docs/mis.md, "Delta vertices"), as the ratio walk's remap0.
inline double remap0(double p) { return p != 0.0 ? p : 1.0; }

// a * b where a = 0 wins over an infinite b: a strategy of zero density contributes nothing even
// when the running sum it multiplies has overflowed (the limit, not NaN).
inline double timesOrZero(double a, double b) { return a == 0.0 ? 0.0 : a * b; }

// Is a connection between x_{j-1} and x_j possible as far as x_{j-1} goes (c_j above)? Camera
// subpath: not at j = 0 (no strategy has zero camera vertices); light subpath: at j = 0 unless the
// light is delta (s = 0 cannot hit it); elsewhere unless x_{j-1} scattered through a delta lobe.
bool connectibleBefore(const Scene& scene, const PathVertex* path, int j) {
    if (j > 0) return !path[j - 1].delta;
    return path[0].type == VertexType::Light && !isDeltaLightVertex(scene, path[0]);
}

// The weight of strategy j among its neighbours, as a multiple of valid_j: 1, except for strategy
// 1 of a light subpath with a next-event sampler other than power (P(rho), rho =
// pmf_sampler(x_1) / pmf_power; docs/mis.md, "Light tree in BDPT").
double strategyScale(const Scene& scene, const PathVertex* path, int j, const MisSettings& mis) {
    if (j != 1 || mis.lightSampler == LightSamplerKind::Power || path[0].type != VertexType::Light) return 1.0;
    return misPower(nextEventPmfRatio(scene, mis.lightSampler, path[1], path[0].light), mis.exponent());
}

}  // namespace

void fillRecursiveMis(const Scene& scene, PathVertex* path, int n, const MisSettings& mis) {
    const double b = mis.exponent();
    double a = 0.0;            // A(j-2): the walk's terms of strategies connecting before x_{j-1}
    double validPrev = 0.0;    // valid_{j-1}, times strategy j-1's scale (strategyScale)
    for (int j = 0; j < n; ++j) {
        PathVertex& v = path[j];
        const bool c = connectibleBefore(scene, path, j);
        const double fwd = misPower(remap0(v.pdfFwd), b);
        const double scale = strategyScale(scene, path, j, mis);
        v.dVCM = c ? scale / fwd : 0.0;
        if (j == 0) {
            v.dVC = 0.0;
        } else {
            const PathVertex& prev = path[j - 1];
            const double fwdPrev = misPower(remap0(prev.pdfFwd), b);
            const double prevTerms = validPrev + a;  // valid_{j-1} + A(j-2)
            v.dVC = timesOrZero(misPower(convertDensity(1.0, v, prev), b) / fwd, prevTerms / fwdPrev);
            // A(j-1) for the next vertex: pdfRev(j-1) is final once x_{j+1} exists.
            a = misPower(remap0(prev.pdfRev), b) / fwdPrev * prevTerms;
        }
        validPrev = c && !v.delta ? scale : 0.0;
    }
}

ConnectionDensities connectionDensities(const Scene& scene, const PathVertex* lightPath, int s, const PathVertex* cameraPath,
                                        int t, const PathVertex& sampled, const MisSettings& mis, const SubpathBsdfs& bsdfs) {
    // The surface endpoints' pair of densities from their BSDFs (evaluateConnection finds the same
    // bits with f: Bsdf::evaluateBothWays).
    EndpointDensities cameraEnd, lightEnd;
    if (t >= 1 && s + t >= 3 && s >= 1) {
        const PathVertex& pt = t == 1 ? sampled : cameraPath[t - 1];
        const PathVertex& qs = s == 1 ? sampled : lightPath[s - 1];
        const EndpointBsdfs endpoints(scene, lightPath, s, cameraPath, t, bsdfs);
        const Vec3 ptToQs = directionTo(pt, qs);
        if (t >= 2)
            endpoints.get().camera[t - 1].pdfBothWays(pt.toPrev, ptToQs, &cameraEnd.towardsOther, &cameraEnd.towardsPrev);
        if (s >= 2)
            endpoints.get().light[s - 1].pdfBothWays(qs.toPrev, -ptToQs, &lightEnd.towardsOther, &lightEnd.towardsPrev);
    }
    return connectionDensities(scene, lightPath, s, cameraPath, t, sampled, mis, cameraEnd, lightEnd);
}

ConnectionDensities connectionDensities(const Scene& scene, const PathVertex* lightPath, int s, const PathVertex* cameraPath,
                                        int t, const PathVertex& sampled, const MisSettings& mis,
                                        const EndpointDensities& cameraEnd, const EndpointDensities& lightEnd) {
    ConnectionDensities d;
    if (t < 1 || s + t < 3) return d;
    const PathVertex& pt = t == 1 ? sampled : cameraPath[t - 1];
    if (s == 0) {  // the camera subpath hit the light: its densities as the light subpath's origin
        d.ptRev = lightOriginDensity(scene, pt);
        // ... and as next-event estimation from x_{t-2} samples it (s' = 1)
        d.ptRevNextEvent = nextEventOriginDensity(scene, mis.lightSampler, cameraPath[t - 2], pt);
        d.ptPrevRev = emissionDensityTowards(scene, pt, cameraPath[t - 2]);
        return d;
    }
    const PathVertex& qs = s == 1 ? sampled : lightPath[s - 1];
    // An endpoint v's density towards the other endpoint, in the other's measure.
    auto towardsOther = [](const EndpointDensities& e, const PathVertex& v, const PathVertex& other) {
        return convertDensity(double(e.towardsOther), v, other);
    };
    // At a surface endpoint one BSDF query answered both densities: towards the other endpoint
    // arriving from its own previous vertex, and back towards that vertex arriving from the other
    // endpoint. Directions between the stored positions (docs/mis.md, "Densities are functions of
    // the vertex positions"), as the stored pdfFwd/pdfRev: the direction towards each endpoint's
    // previous vertex is the one fillSubpathDensities stored (PathVertex::toPrev).
    // Camera side.
    if (t >= 2) {
        if (s == 1) d.ptRev = pdfLightToVertex(scene, qs, pt);
        // The strategies s' >= 2 start at qs with the light subpath's origin density, s = 1 with the
        // fresh sample's (docs/mis.md, "Light tree in BDPT").
        if (s == 1 && mis.lightSampler != LightSamplerKind::Power)
            d.ptRev = qs.pdfFwd > 0.0 ? d.ptRev * (lightOriginDensity(scene, qs) / qs.pdfFwd) : 0.0;
        d.qsRev = towardsOther(cameraEnd, pt, qs);
        d.ptPrevRev = cameraEnd.towardsPrev;
    } else {
        d.qsRev = vertexPdf(scene, pt, nullptr, qs);  // the camera's density of the direction to qs
    }
    // Light side (s >= 2: qs is a surface vertex of the light subpath).
    if (s >= 2) {
        d.ptRev = towardsOther(lightEnd, qs, pt);
        d.qsPrevRev = lightEnd.towardsPrev;
    }
    return d;
}

double misWeightRecursive(const Scene& scene, const PathVertex* lightPath, int s, const PathVertex* cameraPath, int t,
                          const PathVertex& sampled, const ConnectionDensities& d, const MisSettings& mis) {
    if (s + t == 2) return 1.0;  // emitters seen directly: only s = 0 is used (docs/mis.md)
    const double b = mis.exponent();
    double sum = 0.0;
    if (t >= 2) {  // strategies with more light vertices (none for t = 1)
        const PathVertex& pt = cameraPath[t - 1];
        if (s == 0 && mis.lightSampler != LightSamplerKind::Power)  // s' = 1 apart from s' >= 2
            sum += timesOrZero(misPower(d.ptRevNextEvent, b), pt.dVCM) +
                   timesOrZero(misPower(d.ptRev, b), timesOrZero(misPower(d.ptPrevRev, b), pt.dVC));
        else
            sum += timesOrZero(misPower(d.ptRev, b), pt.dVCM + timesOrZero(misPower(d.ptPrevRev, b), pt.dVC));
    }
    if (s >= 1) {  // strategies with more camera vertices (none for s = 0)
        if (s == 1) {  // the fresh light sample: dVCM from its origin density, nothing before it
            const double dVCM = isDeltaLightVertex(scene, sampled) ? 0.0 : 1.0 / misPower(remap0(sampled.pdfFwd), b);
            sum += timesOrZero(misPower(d.qsRev, b), dVCM);
        } else {
            const PathVertex& qs = lightPath[s - 1];
            sum += timesOrZero(misPower(d.qsRev, b), qs.dVCM + timesOrZero(misPower(d.qsPrevRev, b), qs.dVC));
        }
    }
    return 1.0 / (1.0 + sum);
}

}  // namespace bdptref
