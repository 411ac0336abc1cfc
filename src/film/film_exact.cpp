#include "film/film_exact.h"

#include "bdptref/checkpoint.h"
#include "bdptref/errors.h"

#include "film/exr_read.h"

#include <cstring>
#include <functional>

namespace bdptref {

namespace {

const char* const kRgb[3] = {"R", "G", "B"};

// One 64-bit per-pixel quantity: its channel name (without .hi/.lo) and how to get/set its bits.
struct ExactField {
    std::string name;
    std::function<uint64_t(size_t)> get;
    std::function<void(size_t, uint64_t)> set;
};

uint64_t bitsOf(double v) {
    uint64_t b;
    std::memcpy(&b, &v, 8);
    return b;
}
double doubleOf(uint64_t b) {
    double v;
    std::memcpy(&v, &b, 8);
    return v;
}

void addDoubleFields(std::vector<ExactField>& out, const std::string& prefix, std::vector<DVec3>* v, size_t offset) {
    for (int c = 0; c < 3; ++c)
        out.push_back({prefix + "." + kRgb[c], [v, offset, c](size_t i) { return bitsOf((*v)[offset + i][c]); },
                       [v, offset, c](size_t i, uint64_t b) { (*v)[offset + i][c] = doubleOf(b); }});
}

// The sum and sum of squares of one layer of a PassLayers: `<prefix>.sum.{R,G,B}`, `<prefix>.sumSquares.{R,G,B}`.
void addLayerFields(std::vector<ExactField>& out, const std::string& prefix, PassLayers& layers, int layer) {
    const size_t offset = size_t(layer) * layers.pixels();
    addDoubleFields(out, prefix + ".sum", &layers.sums(), offset);
    addDoubleFields(out, prefix + ".sumSquares", &layers.sumSquares(), offset);
}

// Every exact field of the film, in a fixed order. Takes a non-const film because the same list
// serves reading; writing only calls `get`.
std::vector<ExactField> exactFields(Film& film, bool lightLayer) {
    std::vector<ExactField> f;
    Film::Accumulators a = film.accumulators();
    addDoubleFields(f, "exact.sum", &a.sum, 0);
    addDoubleFields(f, "exact.sumSquares", &a.sumSquares, 0);
    std::vector<uint64_t>* count = &a.count;
    f.push_back({"exact.count", [count](size_t i) { return (*count)[i]; }, [count](size_t i, uint64_t b) { (*count)[i] = b; }});
    if (lightLayer) addDoubleFields(f, "exact.lightSum", &a.lightSum, 0);
    StrategyLayers& st = film.strategies();
    if (st.enabled()) {
        for (int d = 0; d <= st.maxDepth(); ++d)
            for (int s = 0; s <= d + 1; ++s) {
                const int t = d + 2 - s;
                const std::string layer = "exact.s" + std::to_string(s) + "t" + std::to_string(t);
                for (bool weighted : {true, false})
                    addLayerFields(f, layer + (weighted ? ".weighted" : ".unweighted"), st.of(weighted), StrategyLayers::index(s, t));
            }
    }
    DepthLayers& depths = film.depths();
    for (int d = 0; d <= depths.maxDepth(); ++d) addLayerFields(f, "exact.depth" + std::to_string(d), depths, d);
    return f;
}

uint64_t parseU64(const FilmFile& f, const char* attr) {
    const std::string s = f.attribute(attr);
    if (s.empty() || s.find_first_not_of("0123456789") != std::string::npos || s.size() > 20)
        throw InputError(f.path + ": header attribute " + attr + " is missing or not an unsigned integer ('" + s + "')");
    return std::stoull(s);
}

}  // namespace

std::vector<ExrUintLayer> exactChannels(const Film& film, bool lightLayer) {
    // exactFields only reads through `get` here.
    const std::vector<ExactField> fields = exactFields(const_cast<Film&>(film), lightLayer);
    const size_t n = film.pixelCount();
    std::vector<ExrUintLayer> out;
    out.reserve(fields.size() * 2);
    for (const ExactField& fd : fields) {
        ExrUintLayer hi{fd.name + ".hi", std::vector<uint32_t>(n)}, lo{fd.name + ".lo", std::vector<uint32_t>(n)};
        for (size_t i = 0; i < n; ++i) {
            const uint64_t b = fd.get(i);
            hi.pixels[i] = uint32_t(b >> 32);
            lo.pixels[i] = uint32_t(b);
        }
        out.push_back(std::move(hi));
        out.push_back(std::move(lo));
    }
    return out;
}

void appendExactAttributes(const Film& film, bool lightLayer, ExrMetadata& md) {
    const StrategyLayers& st = film.strategies();
    md.strings.push_back({kAttrExactFormat, "1"});
    md.strings.push_back({kAttrSampleRanges, film.samples().text()});
    md.strings.push_back({kAttrExactNonFinite, std::to_string(film.nonFiniteSamples())});
    md.strings.push_back({kAttrExactStrategyDepth, std::to_string(st.maxDepth())});
    md.strings.push_back({kAttrExactStrategyPasses, std::to_string(st.passes())});
    md.strings.push_back({kAttrExactLayerNonFinite, std::to_string(st.nonFiniteValues())});
    md.strings.push_back({kAttrExactLight, lightLayer ? "1" : "0"});
    // Only with depth layers: files without them stay as they were.
    const DepthLayers& depths = film.depths();
    if (depths.enabled()) {
        md.strings.push_back({kAttrExactDepthMaxDepth, std::to_string(depths.maxDepth())});
        md.strings.push_back({kAttrExactDepthPasses, std::to_string(depths.passes())});
        md.strings.push_back({kAttrExactDepthNonFinite, std::to_string(depths.nonFiniteValues())});
    }
}

FilmFile readFilmExr(const std::string& path) {
    ExrReader in(path);
    const ExrPartInfo& spec = in.part(0);
    FilmFile f;
    f.path = path;
    auto typedAs = [](const auto& list, const std::string& name) {
        for (const auto& kv : list)
            if (kv.first == name) return &kv.second;
        return static_cast<decltype(&list.front().second)>(nullptr);
    };
    for (const auto& [name, text] : spec.attributes) {
        f.attributes[name] = text;
        if (name.rfind("bdptref:", 0) != 0 || name.rfind("bdptref:exact.", 0) == 0 || name == kAttrSampleRanges) continue;
        if (const int* i = typedAs(spec.typed.ints, name)) f.metadata.ints.push_back({name, *i});
        else if (const float* v = typedAs(spec.typed.floats, name)) f.metadata.floats.push_back({name, *v});
        else f.metadata.strings.push_back({name, text});
    }
    if (f.attribute(kAttrExactFormat) != "1")
        throw InputError(path + ": holds no exact film state (" + kAttrExactFormat +
                         " missing): only EXRs written by this version of 'bdptref render' or 'merge' can be resumed or merged");
    f.lightLayer = f.attribute(kAttrExactLight) == "1";
    auto depthAttribute = [&](const char* attr, bool required) {
        const std::string text = f.attribute(attr);
        if (text.empty() && !required) return -1;
        size_t used = 0;
        int v = -2;
        try {
            v = std::stoi(text, &used);
        } catch (const std::exception&) {
        }
        if (used != text.size() || v < -1 || v > 100000)
            throw InputError(path + ": header attribute " + std::string(attr) + " is not a depth (-1..100000): '" + text + "'");
        return v;
    };
    const int strategyDepth = depthAttribute(kAttrExactStrategyDepth, true);
    const int depthLayersDepth = depthAttribute(kAttrExactDepthMaxDepth, false);
    // A crop render's film is the data window inside the display window (the full image).
    const FilmWindow window{spec.fullWidth, spec.fullHeight, spec.x - spec.fullX, spec.y - spec.fullY, spec.width,
                            spec.height};
    if (spec.fullX != 0 || spec.fullY != 0 || window.x0 < 0 || window.y0 < 0 || window.width < 1 || window.height < 1 ||
        window.x0 + window.width > window.fullWidth || window.y0 + window.height > window.fullHeight)
        throw InputError(path + ": its data window (" + window.text() + ", display window origin " +
                         std::to_string(spec.fullX) + "," + std::to_string(spec.fullY) +
                         ") is not inside a display window at 0,0, as bdptref writes them");
    f.film = Film(window);
    if (strategyDepth >= 0) f.film.enableStrategies(strategyDepth);
    if (depthLayersDepth >= 0) {
        f.film.enableDepthLayers(depthLayersDepth);
        f.film.depths().setPasses(parseU64(f, kAttrExactDepthPasses));
        f.film.depths().setNonFiniteValues(parseU64(f, kAttrExactDepthNonFinite));
    }
    f.film.samples() = parseSampleRanges(f.attribute(kAttrSampleRanges), path + ": " + kAttrSampleRanges);
    f.film.accumulators().nonFinite = parseU64(f, kAttrExactNonFinite);
    f.film.strategies().setPasses(parseU64(f, kAttrExactStrategyPasses));
    if (!f.attribute(kAttrExactLayerNonFinite).empty())
        f.film.strategies().setNonFiniteValues(parseU64(f, kAttrExactLayerNonFinite));

    // The exact channels live in the part named "exact" (exr_io.h); files of earlier versions
    // hold them in the first part, next to the image.
    const int part = in.parts() > 1 && in.part(1).name == kExactPartName ? 1 : 0;
    const ExrPartInfo& exactSpec = in.part(part);
    if (exactSpec.width != spec.width || exactSpec.height != spec.height)
        throw InputError(path + ": the '" + kExactPartName + "' part is not the size of the image");
    const std::vector<ExactField> fields = exactFields(f.film, f.lightLayer);
    std::map<std::string, bool> isUint;  // channel name -> UINT?
    for (size_t k = 0; k < exactSpec.channels.size(); ++k) isUint[exactSpec.channels[k]] = exactSpec.channelIsUint[k];
    std::vector<std::string> names;
    for (const ExactField& fd : fields) {
        for (const char* half : {".hi", ".lo"}) {
            const std::string name = fd.name + half;
            const auto it = isUint.find(name);
            if (it == isUint.end() || !it->second)
                throw InputError(path + ": exact channel " + name + " is missing or not of type UINT (looked in " +
                                 (part == 1 ? std::string("the '") + kExactPartName + "' part" : "the first part: no '" + std::string(kExactPartName) + "' part") + ")");
            names.push_back(name);
        }
    }
    const std::map<std::string, std::vector<uint32_t>> data = in.readUint(part, names);
    const size_t n = f.film.pixelCount();
    for (const ExactField& fd : fields) {
        const std::vector<uint32_t>& hi = data.at(fd.name + ".hi");
        const std::vector<uint32_t>& lo = data.at(fd.name + ".lo");
        for (size_t i = 0; i < n; ++i) fd.set(i, (uint64_t(hi[i]) << 32) | lo[i]);
    }
    // The counts must be the number of passes where sampled and 0 elsewhere (crop).
    const uint64_t passes = f.film.samples().total();
    for (int y = 0; y < spec.height; ++y)
        for (int x = 0; x < spec.width; ++x)
            if (f.film.count(x, y) != 0 && f.film.count(x, y) != passes)
                throw InputError(path + ": inconsistent exact state: pixel (" + std::to_string(x + window.x0) + ", " +
                                 std::to_string(y + window.y0) +
                                 ") holds " + std::to_string(f.film.count(x, y)) + " samples, the sample ranges " +
                                 std::to_string(passes));
    return f;
}

}  // namespace bdptref
