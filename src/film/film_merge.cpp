#include "bdptref/film_merge.h"

#include "bdptref/errors.h"

#include <algorithm>
#include <map>
#include <numeric>
#include <sstream>

namespace bdptref {

std::map<std::string, std::string> parseSettingsText(const std::string& text) {
    std::map<std::string, std::string> m;
    std::istringstream in(text);
    std::string line;
    while (std::getline(in, line)) {
        const size_t eq = line.find('=');
        if (eq != std::string::npos) m[line.substr(0, eq)] = line.substr(eq + 1);
    }
    return m;
}

std::string describeSettingsDifference(const std::string& a, const std::string& b) {
    const auto ma = parseSettingsText(a), mb = parseSettingsText(b);
    std::map<std::string, bool> keys;
    for (const auto& kv : ma) keys[kv.first] = true;
    for (const auto& kv : mb) keys[kv.first] = true;
    std::string out;
    for (const auto& kv : keys) {
        const auto ia = ma.find(kv.first), ib = mb.find(kv.first);
        const std::string va = ia == ma.end() ? "(absent)" : ia->second, vb = ib == mb.end() ? "(absent)" : ib->second;
        if (va == vb) continue;
        if (!out.empty()) out += "; ";
        out += kv.first + ": " + va + " vs " + vb;
    }
    return out.empty() ? "(identical)" : out;
}

MergedFilm mergeFilms(const std::vector<FilmFile>& parts, const MergeOptions& options) {
    if (parts.empty()) throw InputError("merge: no parts given");
    for (const FilmFile& p : parts)
        if (p.film.samples().empty()) throw InputError(p.path + ": holds no samples");
    std::vector<size_t> order(parts.size());
    std::iota(order.begin(), order.end(), size_t(0));
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
        return parts[a].film.samples().firstIndex() < parts[b].film.samples().firstIndex();
    });
    const FilmFile& first = parts[order.front()];
    MergedFilm out;
    out.lightLayer = first.lightLayer;
    out.metadata = first.metadata;
    out.order = order;
    const std::string settings = first.attribute(kAttrSettings);
    if (settings.empty()) throw InputError(first.path + ": has no " + std::string(kAttrSettings) + " header attribute");
    out.film = Film(first.film.window());
    if (first.film.strategies().enabled()) out.film.enableStrategies(first.film.strategies().maxDepth());
    if (first.film.depths().enabled()) out.film.enableDepthLayers(first.film.depths().maxDepth());
    for (size_t k : order) {
        const FilmFile& p = parts[k];
        if (p.attribute("bdptref:sceneHash") != first.attribute("bdptref:sceneHash"))
            throw InputError(p.path + ": rendered from another scene than " + first.path + " (scene hash " +
                             p.attribute("bdptref:sceneHash") + " vs " + first.attribute("bdptref:sceneHash") + ")");
        if (p.attribute(kAttrSettings) != settings)
            throw InputError(p.path + ": rendered with other settings than " + first.path + ": " +
                             describeSettingsDifference(p.attribute(kAttrSettings), settings));
        if (p.film.window() != first.film.window())
            throw InputError(p.path + ": its data window (" + p.film.window().text() + ") differs from " + first.path +
                             "'s (" + first.film.window().text() + "): parts must hold the same pixels");
        if (p.film.width() != first.film.width() || p.film.height() != first.film.height() ||
            p.film.strategies().maxDepth() != first.film.strategies().maxDepth() ||
            p.film.depths().maxDepth() != first.film.depths().maxDepth() || p.lightLayer != first.lightLayer)
            throw InputError(p.path + ": its image size or layers differ from " + first.path);
        for (const char* fact : {"bdptref:version", "bdptref:gitRevision"})
            if (p.attribute(fact) != first.attribute(fact))
                out.warnings.push_back(p.path + ": made by " + fact + " " + p.attribute(fact) + ", " + first.path + " by " +
                                       first.attribute(fact) + " (the merge is exact only if both revisions render the same samples)");
        for (const SampleRange& r : p.film.samples().ranges())
            for (size_t j : order) {
                if (j == k) continue;
                for (const SampleRange& o : parts[j].film.samples().ranges())
                    if (r.begin < o.end && o.begin < r.end)
                        throw InputError(p.path + " and " + parts[j].path + ": overlapping sample ranges (" +
                                         p.film.samples().text() + " and " + parts[j].film.samples().text() +
                                         "): the same samples would be counted twice");
            }
        out.film.accumulate(p.film);
    }
    if (!options.allowGaps && !out.film.samples().contiguous()) {
        std::string gaps;
        const auto& rs = out.film.samples().ranges();
        for (size_t i = 1; i < rs.size(); ++i)
            gaps += (gaps.empty() ? "" : ", ") + std::to_string(rs[i - 1].end) + ":" + std::to_string(rs[i].begin);
        throw InputError("merge: the parts leave samples " + gaps + " unrendered (sample ranges " +
                         out.film.samples().text() + "); render them, or pass --allow-gaps");
    }
    return out;
}

}  // namespace bdptref
