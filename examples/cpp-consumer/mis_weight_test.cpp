// A port's own unit test of its MIS weights, written against the installed bdptref: the balance
// and power heuristic weights of a 4-vertex path, computed by hand from per-vertex densities (the
// way a port would compute them), must equal bdptref's (docs/mis.md, "The density of a strategy").
// Plain checks; the exit code is the number of failures (CTest: nonzero = failed).
#include <bdptref/bdptref.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace {

int failures = 0;

void check(bool ok, const std::string& what) {
    if (!ok) {
        ++failures;
        std::printf("FAILED: %s\n", what.c_str());
    }
}

// Both sides evaluate exact closed forms in double or better: 1e-12 relative leaves ~1000x the
// rounding of a product of four densities and a sum of four terms.
bool near(double a, double b) { return std::fabs(a - b) <= 1e-12 * std::max(std::fabs(a), std::fabs(b)); }

// The hand-written weight: path x0 (camera) .. x3 (on an area light); strategy s has t = 4 - s
// camera vertices. p_s = prod_{i<t} pc[i] * (s == 1 ? nee : s >= 2 ? pl[3] : 1) * prod_{t<=k<3} pl[k].
std::vector<double> handWeights(const std::vector<double>& pc, const std::vector<double>& pl, double nee, double beta) {
    const int n = int(pc.size());
    std::vector<double> p(size_t(n), 1.0);
    for (int s = 0; s < n; ++s) {
        const int t = n - s;
        for (int i = 0; i < t; ++i) p[size_t(s)] *= pc[size_t(i)];
        if (s == 1) p[size_t(s)] *= nee;
        if (s >= 2) p[size_t(s)] *= pl[size_t(n - 1)];
        for (int k = t; k < n - 1; ++k) p[size_t(s)] *= pl[size_t(k)];
    }
    double sum = 0;
    for (double& v : p) sum += (v = std::pow(v, beta));
    for (double& v : p) v /= sum;
    return p;
}

}  // namespace

int main() {
    // Densities of a camera -> diffuse -> diffuse -> area light path (area measure, made up but
    // of realistic magnitudes: the camera's is large near the pinhole, the light's small).
    const std::vector<double> pc = {1.0, 2.5e-2, 3.0e-1, 4.0e-2};  // p->(x_i)
    const std::vector<double> pl = {0.0, 6.0e-3, 2.0e-1, 5.0e-2};  // p<-(x_i); x3: the light's origin density
    const double nee = 8.0e-2;                                     // next-event density of x3 from x2

    bdptref::PathDensities path;
    for (size_t i = 0; i < pc.size(); ++i) path.vertices.push_back({pc[i], pl[i], false});
    path.lightNextEvent = nee;

    for (double beta : {1.0, 2.0}) {
        bdptref::MisSettings mis;
        mis.heuristic = beta == 1.0 ? bdptref::MisHeuristic::Balance : bdptref::MisHeuristic::Power;
        mis.beta = beta;
        const bdptref::MisReport r = bdptref::misWeights(path, mis);
        const std::vector<double> expected = handWeights(pc, pl, nee, beta);
        check(r.strategies.size() == expected.size(), "one weight per strategy");
        for (size_t s = 0; s < expected.size() && s < r.strategies.size(); ++s) {
            check(r.strategies[s].valid, "strategy s=" + std::to_string(s) + " can sample the path");
            check(near(r.strategies[s].weight, expected[s]),
                  "beta " + std::to_string(beta) + ", s=" + std::to_string(s) + ": bdptref " +
                      std::to_string(r.strategies[s].weight) + ", by hand " + std::to_string(expected[s]));
        }
        check(std::fabs(r.sum - 1.0) <= 1e-12, "the weights sum to 1");
    }

    // A point light cannot be hit: s = 0 drops out and the other weights renormalise.
    path.deltaLight = true;
    const bdptref::MisReport point = bdptref::misWeights(path);
    std::vector<double> expected = handWeights(pc, pl, nee, 1.0);
    check(!point.strategies[0].valid && point.strategies[0].weight == 0.0, "s=0 cannot hit a point light");
    for (size_t s = 1; s < expected.size(); ++s)
        check(near(point.strategies[s].weight, expected[s] / (1.0 - expected[0])), "point light, s=" + std::to_string(s));

    // Bad input is an InputError with the CLI's message, also across the shared library boundary.
    path.vertices[2].camera = -1.0;
    bool threw = false;
    try {
        bdptref::misWeights(path);
    } catch (const bdptref::InputError& e) {
        threw = std::string(e.what()).find("densities must be >= 0") != std::string::npos;
    }
    check(threw, "a negative density throws InputError with the CLI message");

    // The headers and the library linked are the same version.
    const bdptref::LibraryVersion v = bdptref::libraryVersion();
    check(v.text == BDPTREF_VERSION && v.major == BDPTREF_VERSION_MAJOR && v.major >= 1, "library version " + v.text);

    std::printf("%s: %d failure(s)\n", failures ? "FAILED" : "passed", failures);
    return failures;
}
