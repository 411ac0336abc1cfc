#include "bdptref/exr_io.h"

#include "bdptref/errors.h"
#include "core/output_file.h"
#include "film/exr_encode.h"
#include "film/exr_read.h"
#include "film/film_exact.h"
#include "film/image_read.h"
#include "film/png_write.h"

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>

namespace bdptref {

namespace {

// Encodes the PNG in memory, then hands the bytes to writeOutputBytes, which replaces `path`
// durably (core/output_file.h).
void writePng(const std::string& path, int width, int height, const uint8_t* rgb) {
    std::vector<unsigned char> bytes;
    try {
        bytes = encodePng8(width, height, 3, rgb);
    } catch (const std::exception& e) {
        throw InputError(path + ": cannot encode the PNG: " + e.what());
    }
    writeOutputBytes(path, bytes.data(), bytes.size());
}

}  // namespace

void writeLayersExr(const std::string& path, int width, int height, const std::vector<ExrLayer>& layers,
                    const ExrMetadata& metadata, const std::vector<ExrUintLayer>& uintLayers, const FilmWindow& window) {
    writeLayersExr(path, width, height, layers, metadata, uintLayers, window, true);
}

void writeLayersExr(const std::string& path, int width, int height, const std::vector<ExrLayer>& layers,
                    const ExrMetadata& metadata, const std::vector<ExrUintLayer>& uintLayers, const FilmWindow& window,
                    bool compress) {
    const size_t n = size_t(width) * size_t(height);
    ExrPartSpec spec;
    spec.compress = compress;
    spec.width = spec.fullWidth = width;
    spec.height = spec.fullHeight = height;
    if (window.fullWidth > 0) {  // data window = the crop, display window = the full image
        spec.x = window.x0;
        spec.y = window.y0;
        spec.fullWidth = window.fullWidth;
        spec.fullHeight = window.fullHeight;
    }
    for (const ExrLayer& l : layers) spec.channels.push_back({l.name, false});
    spec.chromaticities = true;
    spec.metadata = metadata;
    std::vector<float> data(n * layers.size());
    for (size_t k = 0; k < layers.size(); ++k)
        for (size_t i = 0; i < n; ++i) data[i * layers.size() + k] = layers[k].pixels[i];
    std::vector<ExrPart> parts{{spec, data.data()}};
    // The UINT channels go into a second part named "exact", so viewers and `oiiotool --info`
    // list only the image layers in the first one.
    std::vector<uint32_t> exact(n * uintLayers.size());
    if (!uintLayers.empty()) {
        ExrPartSpec es = spec;  // the same data and display windows as the image part
        es.channels.clear();
        for (const ExrUintLayer& l : uintLayers) es.channels.push_back({l.name, true});
        es.metadata = {};
        es.name = kExactPartName;
        const size_t c = uintLayers.size();
        for (size_t k = 0; k < c; ++k)
            for (size_t i = 0; i < n; ++i) exact[i * c + k] = uintLayers[k].pixels[i];
        parts.push_back({es, exact.data()});
    }
    std::vector<char> bytes;
    try {
        bytes = encodeExr(parts);
    } catch (const std::logic_error&) {
        throw;
    } catch (const std::exception& e) {
        throw InputError(path + ": cannot encode the EXR: " + e.what());
    }
    writeOutputBytes(path, bytes.data(), bytes.size());
}

void writeFilmExr(const std::string& path, const Film& film, const ExrMetadata& metadata, bool lightLayer) {
    writeFilmExr(path, film, metadata, lightLayer, true);
}

void writeFilmExr(const std::string& path, const Film& film, const ExrMetadata& metadata, bool lightLayer, bool compress) {
    const int w = film.width(), h = film.height();
    const size_t n = film.pixelCount();
    std::vector<ExrLayer> layers = {{"R", {}}, {"G", {}}, {"B", {}}, {"variance.R", {}}, {"variance.G", {}},
                                    {"variance.B", {}}, {"count", {}}};
    if (lightLayer)
        for (const char* c : {"light.R", "light.G", "light.B"}) layers.push_back({c, {}});
    // Every layer channel: which PassLayers, which of its layers, mean or variance, which colour.
    struct LayerChannel {
        const PassLayers* layers;
        int layer;
        bool variance;
        int c;
    };
    std::vector<LayerChannel> layerChannels;
    const char* rgb[3] = {"R", "G", "B"};
    auto addLayer = [&](const std::string& name, const PassLayers& from, int layer) {
        for (bool variance : {false, true})
            for (int c = 0; c < 3; ++c) {
                layers.push_back({name + (variance ? ".variance." : ".") + rgb[c], {}});
                layerChannels.push_back({&from, layer, variance, c});
            }
    };
    const StrategyLayers& st = film.strategies();
    for (int d = 0; d <= st.maxDepth(); ++d)
        for (int s = 0; s <= d + 1; ++s) {
            const int t = d + 2 - s;
            for (bool weighted : {true, false})
                addLayer("s" + std::to_string(s) + "t" + std::to_string(t) + (weighted ? ".weighted" : ".unweighted"),
                         st.of(weighted), StrategyLayers::index(s, t));
        }
    const DepthLayers& depths = film.depths();
    for (int d = 0; d <= depths.maxDepth(); ++d) addLayer("depth" + std::to_string(d), depths, d);
    for (ExrLayer& l : layers) l.pixels.resize(n);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const size_t i = size_t(y) * size_t(w) + size_t(x);
            const DVec3 m = film.mean(x, y), v = film.varianceOfMean(x, y);
            for (int c = 0; c < 3; ++c) {
                layers[size_t(c)].pixels[i] = float(m[c]);
                layers[size_t(3 + c)].pixels[i] = float(v[c]);
            }
            layers[6].pixels[i] = float(film.count(x, y));
            size_t next = 7;
            if (lightLayer) {
                const DVec3 lm = film.lightMean(x, y);
                for (int c = 0; c < 3; ++c) layers[next + size_t(c)].pixels[i] = float(lm[c]);
                next += 3;
            }
            for (size_t k = 0; k < layerChannels.size(); ++k) {
                const LayerChannel& lc = layerChannels[k];
                const DVec3 val = lc.variance ? lc.layers->varianceOfMean(lc.layer, x, y) : lc.layers->mean(lc.layer, x, y);
                layers[next + k].pixels[i] = float(val[lc.c]);
            }
        }
    ExrMetadata md = metadata;
    appendExactAttributes(film, lightLayer, md);
    writeLayersExr(path, w, h, layers, md, exactChannels(film, lightLayer), film.window(), compress);
}

void writeRgb8Png(const std::string& path, int width, int height, const std::vector<uint8_t>& rgb) {
    if (rgb.size() != size_t(width) * size_t(height) * 3) throw std::invalid_argument("writeRgb8Png: wrong pixel count");
    writePng(path, width, height, rgb.data());
}

void writePreviewPng(const std::string& path, const Film& film, float exposure) {
    const int w = film.width(), h = film.height();
    std::vector<uint8_t> data(film.pixelCount() * 3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const DVec3 m = film.mean(x, y) * double(exposure);
            for (int c = 0; c < 3; ++c)
                data[(size_t(y) * size_t(w) + size_t(x)) * 3 + size_t(c)] = linearToSrgbByte(m[c]);
        }
    writePng(path, w, h, data.data());
}

ExrImage readImage(const std::string& path) {
    // A missing or unreadable file is reported here, before any reader (or module) is chosen.
    if (FILE* f = std::fopen(path.c_str(), "rb")) {
        std::fclose(f);
    } else {
        throw InputError(path + ": cannot read image: " + std::strerror(errno));
    }
    struct stat st {};
    if (::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode)) throw InputError(path + ": cannot read image: it is a folder");
    if (hasExrMagic(path)) return readExrImage(path);
    if (hasRadianceMagic(path)) return readRadianceImage(path);
    return readImageWithModule(path);
}

void checkWritable(const std::string& path) { checkOutputWritable(path); }

}  // namespace bdptref
