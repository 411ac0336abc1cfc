// `bdptref merge PARTS... -o OUT.exr`: combines renders of disjoint sample ranges of the same
// settings exactly (film_merge.h). docs/distributed.md.
#include "bdptref/checkpoint.h"
#include "bdptref/errors.h"
#include "bdptref/exr_io.h"
#include "bdptref/film_merge.h"
#include "cli/commands.h"
#include "cli/render_record.h"
#include "core/output_file.h"

#include <algorithm>
#include <climits>
#include <cstdio>
#include <memory>

namespace bdptref::cli {

namespace {

struct MergeArgs {
    std::vector<std::string> parts;
    std::string output, preview;
    bool allowGaps = false, quiet = false;
};

template <typename T>
void setAttribute(std::vector<std::pair<std::string, T>>& list, const std::string& name, const T& value) {
    for (auto& kv : list)
        if (kv.first == name) {
            kv.second = value;
            return;
        }
    list.push_back({name, value});
}

int run(const MergeArgs& a) {
    checkOutputs({{"-o", a.output, ".exr"}, {"--preview", a.preview, ".png"}});
    std::vector<FilmFile> parts;
    for (const std::string& p : a.parts) parts.push_back(readFilmExr(p));
    MergeOptions mo;
    mo.allowGaps = a.allowGaps;
    MergedFilm merged = mergeFilms(parts, mo);
    for (const std::string& w : merged.warnings) std::fprintf(stderr, "bdptref: warning: %s\n", w.c_str());

    double seconds = 0;
    std::string from;
    bool allComplete = true;
    for (size_t k : merged.order) {
        const FilmFile& p = parts[k];
        try {
            seconds += std::stod(p.attribute("bdptref:renderSecondsExact"));
        } catch (const std::exception&) {
        }
        from += (from.empty() ? "" : " ") + shellQuote(p.path) + "=" + p.film.samples().text();
        allComplete = allComplete && p.attribute("bdptref:status") == "complete";
    }
    const Film& film = merged.film;
    ExrMetadata& md = merged.metadata;
    const bool gaps = !film.samples().contiguous();
    setAttribute<int>(md.ints, "bdptref:spp", int(std::min<uint64_t>(film.samples().total(), INT_MAX)));
    setAttribute<int>(md.ints, "bdptref:sppRequested", int(std::min<uint64_t>(film.samples().total(), INT_MAX)));
    setAttribute<int>(md.ints, "bdptref:nonFiniteSamples", int(std::min<uint64_t>(film.nonFiniteSamples(), INT_MAX)));
    setAttribute<int>(md.ints, "bdptref:nonFiniteLayerValues", int(std::min<uint64_t>(film.nonFiniteLayerValues(), INT_MAX)));
    setAttribute<float>(md.floats, "bdptref:renderSeconds", float(seconds));
    setAttribute<std::string>(md.strings, "bdptref:renderSecondsExact", exactNumber(seconds));
    setAttribute<std::string>(md.strings, "bdptref:status", gaps ? "merged with gaps" : (allComplete ? "complete" : "merged from interrupted parts"));
    setAttribute<std::string>(md.strings, "bdptref:mergedFrom", from);
    setAttribute<std::string>(md.strings, "bdptref:commandLine",
                              retargetCommand(parts[merged.order.front()].attribute("bdptref:commandLine"), film.samples(), a.output));
    writeFilmExr(a.output, film, md, merged.lightLayer);
    if (!a.preview.empty()) writePreviewPng(a.preview, film);
    if (!a.quiet)
        std::fprintf(stderr, "bdptref: merged %zu parts into %s (samples %s, %llu spp)\n", parts.size(), a.output.c_str(),
                     film.samples().text().c_str(), static_cast<unsigned long long>(film.samples().total()));
    return 0;
}

}  // namespace

std::function<int()> addMergeCommand(CLI::App& app) {
    auto args = std::make_shared<MergeArgs>();
    CLI::App* cmd = app.add_subcommand("merge", "combine renders of disjoint sample ranges (render --sample-range) exactly");
    cmd->add_option("parts", args->parts, "EXRs written by 'bdptref render' (any order)")->required();
    cmd->add_option("-o,--output", args->output, "merged EXR (written durably: temp file, fsync, rename; itself mergeable and resumable)")->required();
    cmd->add_flag("--allow-gaps", args->allowGaps, "accept parts whose sample ranges leave samples unrendered between them");
    cmd->add_option("--preview", args->preview, "also write a PNG preview of the merged image");
    cmd->add_flag("-q,--quiet", args->quiet, "no summary on stderr");
    cmd->footer(
        "The parts must share the scene (content hash) and every setting that decides the pixels\n"
        "(bdptref:settings) and hold disjoint sample ranges. Sums, sums of squares and counts are added\n"
        "exactly in sample order: merging [0,32) and [32,64) equals rendering [0,64) to double precision.\n"
        "Exit codes: 0 merged, 2 unusable or incompatible parts (the message names them).");
    return [args] { return run(*args); };
}

}  // namespace bdptref::cli
