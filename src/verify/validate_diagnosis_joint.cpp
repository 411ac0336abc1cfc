// Each failing scene's best term, and several terms at once (docs/diagnosis.md, "Each failing
// scene alone", "Several terms at once"). A foreign renderer differs in several independent
// conventions at once; one ranking over all scenes names only the term that explains most of
// them, so each failing scene is also diagnosed alone (the other failing scenes left untested).
// A scene alone can still be explained by a term of its own that is wrong: lights-room under
// Cycles (1/683 on its spots, Burley's gain on its walls) looks most like a point light's 4 pi
// taken alone. So each scene's term is then weighed against the terms the *other* scenes name
// (explaining away): when those predict the scene's ratio, one of them on its kind of light by
// the scene's light shares, the other on the whole image, they replace the scene's own.
#include "verify/validate_diagnosis.h"

#include <algorithm>
#include <cstdio>
#include <map>
#include <optional>

namespace bdptref {

namespace {

using Range = RatioRange;

std::string num(double v) {
    char b[32];
    std::snprintf(b, sizeof b, "%.3g", v);
    return b;
}

bool exercises(const DiagnosisScene& sc, const std::string& term) {
    return std::find(sc.terms.begin(), sc.terms.end(), term) != sc.terms.end();
}

// One way the terms named elsewhere explain a scene: a factor on some kinds of light, optionally
// times a factor (or range) of another term on the whole image.
struct Explanation {
    std::vector<std::string> terms;
    int namedBy = 0;  // how many other failing scenes name its terms
    std::string words;
    bool onShare = false;  // a factor on some kinds of light, predicted on their share of the image
};

// What a scene measured, as the two kinds of prediction are matched (widened by kSystematicFloor):
// the bias test's ratio for a factor on the whole image, as the scale fit matches it; the plain
// image-mean ratio for a factor on a share of the image (light shares are of the mean; none in an
// older report).
struct Measured {
    std::optional<Range> whole, onShare;
    bool meets(const std::optional<Range>& m, const Range& p) const { return m && p.low <= m->high && p.high >= m->low; }
};

Measured measuredOf(const DiagnosisScene& sc) {
    const auto widened = [](double lo, double hi) { return Range{lo * (1 - kSystematicFloor), hi * (1 + kSystematicFloor)}; };
    Measured m;
    m.whole = widened(sc.low, sc.high);
    if (sc.lightShares.empty()) m.onShare = m.whole;  // one kind of light: its share is the whole image
    else if (sc.hasMean) m.onShare = widened(sc.meanLow, sc.meanHigh);
    return m;
}

// A term's uniform factors of a constant (or a range) on the whole image.
std::vector<const TermFactor*> wholeImageFactors(const Term& t) {
    std::vector<const TermFactor*> out;
    for (const TermFactor& f : t.factors)
        if (f.lights == 0 && f.mode == TermFactor::Mode::Uniform && f.of == TermFactor::Of::Constant) out.push_back(&f);
    return out;
}

std::string rangeText(const Range& r) { return "[" + num(r.low) + ", " + num(r.high) + "]"; }

// The explanations of `sc` from `named` (term -> the other failing scenes that name it first)
// whose prediction meets what the scene measured: one term's factor on the whole image, or on
// its kind of light's share; or a factor on a kind of light times another term's factor on the
// whole image (1/683 on the spots, a Burley gain everywhere). Singles first, then pairs, each by
// how many scenes name their terms.
std::vector<Explanation> explanations(const DiagnosisScene& sc, const std::map<std::string, std::vector<std::string>>& named) {
    const Measured measured = measuredOf(sc);
    const auto by = [&](const std::string& term) { return " (" + named.at(term).front() + " names " + term + ")"; };
    std::vector<Explanation> singles, pairs;
    for (const auto& [a, aScenes] : named) {
        const Term* ta = findTerm(a);
        if (!ta || !exercises(sc, a)) continue;
        for (const TermFactor* f : wholeImageFactors(*ta)) {
            const Range p{f->low, f->high};
            if (measured.meets(measured.whole, p))
                singles.push_back({{a}, int(aScenes.size()), std::string(f->name) + by(a) + " predicts " + rangeText(p)});
        }
        for (const TermFactor& f : ta->factors) {
            if (f.lights == 0 || f.of != TermFactor::Of::Constant) continue;
            const double share = lightShareOf(sc, f.lights);
            if (!(share > 0)) continue;
            const Range p = ratioOnShare(share, f.low);
            const std::string onPart = std::string(f.name) + " on " + (share < 1 ? "the lights' share " + num(share) : "all its light") + by(a);
            if (measured.meets(measured.onShare, p))
                singles.push_back({{a}, int(aScenes.size()), onPart + " predicts " + rangeText(p), share < 1});
            for (const auto& [b, bScenes] : named) {
                const Term* tb = findTerm(b);
                if (b == a || !tb || !exercises(sc, b)) continue;
                for (const TermFactor* g : wholeImageFactors(*tb)) {
                    const Range q{p.low * g->low, p.high * g->high};
                    if (measured.meets(measured.onShare, q))
                        pairs.push_back({{a, b}, int(aScenes.size() + bScenes.size()),
                                         onPart + " times " + g->name + by(b) + " predicts " + rangeText(q), share < 1});
                }
            }
        }
    }
    const auto moreNamed = [](const Explanation& x, const Explanation& y) { return x.namedBy > y.namedBy; };
    std::stable_sort(singles.begin(), singles.end(), moreNamed);
    std::stable_sort(pairs.begin(), pairs.end(), moreNamed);
    singles.insert(singles.end(), pairs.begin(), pairs.end());
    return singles;
}

// Some uniform factor of the term holds the scene's ratio: on the whole image, on its light's
// share, or between 1 and the factor (part of the image).
bool factorHolds(const Term& t, const DiagnosisScene& sc) {
    const Measured measured = measuredOf(sc);
    for (const TermFactor& f : t.factors) {
        if (f.mode != TermFactor::Mode::Uniform || f.of != TermFactor::Of::Constant) continue;
        const bool between = f.high < 1 ? sc.ratio > f.high && sc.ratio < 1 : sc.ratio < f.low && sc.ratio > 1;
        const double share = f.lights ? lightShareOf(sc, f.lights) : 1.0;
        if (measured.meets(measured.whole, {f.low, f.high}) || (f.partial && between) ||
            (share > 0 && measured.meets(measured.onShare, ratioOnShare(share, f.low))))
            return true;
    }
    return false;
}

bool hasUniformConstantFactor(const Term& t) {
    return std::any_of(t.factors.begin(), t.factors.end(), [](const TermFactor& f) {
        return f.mode == TermFactor::Mode::Uniform && f.of == TermFactor::Of::Constant;
    });
}

// The term's factors say it cannot give the scene's ratio: they are exhaustive (docs/diagnosis.md,
// "Scale fit") and none holds it. sun-courtyard under Cycles reads x0.00159: no directional
// irradiance factor (pi, 1/pi), but 1/683 times Burley's gain.
bool factorsMiss(const Term& t, const DiagnosisScene& sc) {
    return t.factorsExhaustive && hasUniformConstantFactor(t) && !factorHolds(t, sc);
}

// The scene taken alone: the other failing scenes left untested, the passing ones kept.
DiagnosisInput alone(const DiagnosisInput& input, size_t k) {
    DiagnosisInput in = input;
    for (size_t j = 0; j < in.scenes.size(); ++j)
        if (j != k && in.scenes[j].outcome == DiagnosisOutcome::Failed) in.scenes[j].outcome = DiagnosisOutcome::Untested;
    return in;
}

// The best explanation of each scene by terms the other scenes name, where its own term is named
// by none of them and either other failing scenes exercise it (they could have shown it and did
// not) or its own factors cannot give the scene's ratio. A term of this scene alone whose factors
// say nothing against it (absorbing-glass's attenuation mapping) is no less likely for being
// named nowhere else. Each scene is weighed against the others' own terms (`own`), so the order
// of the scenes does not matter.
void explainAway(const DiagnosisInput& input, const std::vector<size_t>& index, std::vector<SceneDiagnosis>& out) {
    const std::vector<SceneDiagnosis> own = out;
    for (size_t i = 0; i < out.size(); ++i) {
        std::map<std::string, std::vector<std::string>> named;  // by the other scenes
        bool exercisedElsewhere = false;
        for (size_t j = 0; j < own.size(); ++j)
            if (j != i) {
                named[own[j].best.term].push_back(own[j].scene);
                exercisedElsewhere = exercisedElsewhere || exercises(input.scenes[index[j]], own[i].best.term);
            }
        const DiagnosisScene& sc = input.scenes[index[i]];
        const Term* t = findTerm(own[i].best.term);
        if (named.count(own[i].best.term) || !t) continue;
        // A term none of whose factors holds the ratio (light.spot.falloff has none) predicts
        // nothing of it: the others' terms take the scene when they predict its ratio on its
        // light shares, a prediction as specific as a factor (lights-room under Cycles: 1/683 on
        // the spots, Burley on the walls, where a spot falloff under 1/683 would not even show).
        const bool silent = !factorHolds(*t, sc), missed = factorsMiss(*t, sc);
        if (!(exercisedElsewhere || missed || silent)) continue;
        std::vector<Explanation> found = explanations(sc, named);
        if (!exercisedElsewhere && !missed)
            found.erase(std::remove_if(found.begin(), found.end(), [](const Explanation& x) { return !x.onShare; }), found.end());
        if (found.empty()) continue;
        // The first term's entry in the scene's own ranking, its evidence led by the joint words.
        DiagnosisInput in = alone(input, index[i]);
        in.top = termCatalogue().size();
        for (const DiagnosisEntry& e : diagnose(in))
            if (e.term == found[0].terms[0]) {
                out[i].best = e;
                const bool mean = sc.hasMean && !sc.lightShares.empty();
                out[i].best.evidence = "With the terms other failing scenes name: " + found[0].words + "; " + sc.name +
                                       " measured x" + num(sc.ratio) + " [" + num(sc.low) + ", " + num(sc.high) + "]" +
                                       (mean ? ", its image mean x" + num(sc.meanRatio) + " [" + num(sc.meanLow) + ", " +
                                                   num(sc.meanHigh) + "]"
                                             : "") +
                                       ". " + e.evidence;
                out[i].joint = found[0].terms;
                break;
            }
    }
}

}  // namespace

std::vector<SceneDiagnosis> diagnosePerScene(const DiagnosisInput& input) {
    std::vector<SceneDiagnosis> out;
    std::vector<size_t> index;  // out[i] is input.scenes[index[i]]
    for (size_t k = 0; k < input.scenes.size(); ++k) {
        if (input.scenes[k].outcome != DiagnosisOutcome::Failed) continue;
        DiagnosisInput in = alone(input, k);
        in.top = 0;  // the best term only
        const std::vector<DiagnosisEntry> d = diagnose(in, 1);
        if (!d.empty()) out.push_back({input.scenes[k].name, d.front(), {}}), index.push_back(k);
    }
    explainAway(input, index, out);
    return out;
}

}  // namespace bdptref
