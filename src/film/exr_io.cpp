#include "bdptref/exr_io.h"

#include "bdptref/errors.h"
#include "film/film_exact.h"

#include <OpenImageIO/imageio.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <fstream>
#include <unistd.h>

namespace bdptref {

namespace fs = std::filesystem;
using OIIO::ImageInput;
using OIIO::ImageOutput;
using OIIO::ImageSpec;
using OIIO::TypeDesc;

namespace {

std::string tempPathFor(const std::string& path, const std::string& ext) {
    const fs::path p(path);
    const fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
    return (dir / ("." + p.filename().string() + ".tmp-" + std::to_string(::getpid()) + ext)).string();
}

void applyMetadata(ImageSpec& spec, const ExrMetadata& md) {
    for (const auto& [k, v] : md.strings) spec.attribute(k, v);
    for (const auto& [k, v] : md.ints) spec.attribute(k, v);
    for (const auto& [k, v] : md.floats) spec.attribute(k, v);
}

// Writes interleaved pixels of `type` to `path` atomically (temp file + rename).
void writeAtomically(const std::string& path, const ImageSpec& spec, const void* data, TypeDesc type,
                     const std::string& formatExt) {
    const std::string tmp = tempPathFor(path, formatExt);
    auto out = ImageOutput::create(formatExt.substr(1));
    if (!out) throw InputError(path + ": cannot create an image writer: " + OIIO::geterror());
    if (!out->open(tmp, spec)) throw InputError(path + ": cannot write: " + out->geterror());
    const bool ok = out->write_image(type, data);
    const std::string err = ok ? std::string() : out->geterror();
    const bool closed = out->close();
    if (!ok || !closed) {
        std::remove(tmp.c_str());
        throw InputError(path + ": writing failed: " + err);
    }
    std::error_code ec;
    fs::rename(tmp, path, ec);
    if (ec) {
        std::remove(tmp.c_str());
        throw InputError(path + ": cannot move the finished file into place: " + ec.message());
    }
}

}  // namespace

void writeLayersExr(const std::string& path, int width, int height, const std::vector<ExrLayer>& layers,
                    const ExrMetadata& metadata, const std::vector<ExrUintLayer>& uintLayers, const FilmWindow& window) {
    const size_t nf = layers.size(), c = nf + uintLayers.size();
    ImageSpec spec(width, height, int(c), TypeDesc::FLOAT);
    if (window.fullWidth > 0) {  // data window = the crop, display window = the full image
        spec.x = window.x0;
        spec.y = window.y0;
        spec.full_x = spec.full_y = 0;
        spec.full_width = window.fullWidth;
        spec.full_height = window.fullHeight;
    }
    spec.channelnames.clear();
    for (const ExrLayer& l : layers) spec.channelnames.push_back(l.name);
    for (const ExrUintLayer& l : uintLayers) spec.channelnames.push_back(l.name);
    if (!uintLayers.empty()) {
        spec.channelformats.assign(nf, TypeDesc::FLOAT);
        spec.channelformats.resize(c, TypeDesc::UINT);
    }
    spec.attribute("compression", "zip");
    applyMetadata(spec, metadata);
    // Float and UINT channels are both 4 bytes: the native pixel layout is one uint32 per channel.
    const size_t n = size_t(width) * size_t(height);
    std::vector<uint32_t> data(n * c);
    for (size_t k = 0; k < nf; ++k)
        for (size_t i = 0; i < n; ++i) std::memcpy(&data[i * c + k], &layers[k].pixels[i], 4);
    for (size_t k = nf; k < c; ++k)
        for (size_t i = 0; i < n; ++i) data[i * c + k] = uintLayers[k - nf].pixels[i];
    writeAtomically(path, spec, data.data(), uintLayers.empty() ? TypeDesc::FLOAT : TypeDesc::UNKNOWN, ".exr");
}

void writeFilmExr(const std::string& path, const Film& film, const ExrMetadata& metadata, bool lightLayer) {
    const int w = film.width(), h = film.height();
    const size_t n = film.pixelCount();
    std::vector<ExrLayer> layers = {{"R", {}}, {"G", {}}, {"B", {}}, {"variance.R", {}}, {"variance.G", {}},
                                    {"variance.B", {}}, {"count", {}}};
    if (lightLayer)
        for (const char* c : {"light.R", "light.G", "light.B"}) layers.push_back({c, {}});
    const StrategyLayers& st = film.strategies();
    struct StrategyChannel { int s, t; bool weighted, variance; int c; };
    std::vector<StrategyChannel> stChannels;
    if (st.enabled()) {
        const char* rgb[3] = {"R", "G", "B"};
        for (int d = 0; d <= st.maxDepth(); ++d)
            for (int s = 0; s <= d + 1; ++s) {
                const int t = d + 2 - s;
                for (bool weighted : {true, false})
                    for (bool variance : {false, true})
                        for (int c = 0; c < 3; ++c) {
                            layers.push_back({"s" + std::to_string(s) + "t" + std::to_string(t) +
                                                  (weighted ? ".weighted." : ".unweighted.") +
                                                  (variance ? "variance." : "") + rgb[c],
                                              {}});
                            stChannels.push_back({s, t, weighted, variance, c});
                        }
            }
    }
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
            for (size_t k = 0; k < stChannels.size(); ++k) {
                const StrategyChannel& sc = stChannels[k];
                const DVec3 val = sc.variance ? st.varianceOfMean(sc.s, sc.t, sc.weighted, x, y) : st.mean(sc.s, sc.t, sc.weighted, x, y);
                layers[next + k].pixels[i] = float(val[sc.c]);
            }
        }
    ExrMetadata md = metadata;
    appendExactAttributes(film, lightLayer, md);
    writeLayersExr(path, w, h, layers, md, exactChannels(film, lightLayer), film.window());
}

void writeRgb8Png(const std::string& path, int width, int height, const std::vector<uint8_t>& rgb) {
    if (rgb.size() != size_t(width) * size_t(height) * 3) throw std::invalid_argument("writeRgb8Png: wrong pixel count");
    writeAtomically(path, ImageSpec(width, height, 3, TypeDesc::UINT8), rgb.data(), TypeDesc::UINT8, ".png");
}

void writePreviewPng(const std::string& path, const Film& film, float exposure) {
    const int w = film.width(), h = film.height();
    ImageSpec spec(w, h, 3, TypeDesc::UINT8);
    std::vector<float> data(film.pixelCount() * 3);
    auto encode = [](double linear) {  // sRGB OETF of the clamped value
        const double c = std::min(1.0, std::max(0.0, linear));
        return float(c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1.0 / 2.4) - 0.055);
    };
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const DVec3 m = film.mean(x, y) * double(exposure);
            for (int c = 0; c < 3; ++c) data[(size_t(y) * size_t(w) + size_t(x)) * 3 + size_t(c)] = encode(m[c]);
        }
    writeAtomically(path, spec, data.data(), TypeDesc::FLOAT, ".png");
}

ExrImage readImage(const std::string& path) {
    auto in = ImageInput::open(path);
    if (!in) throw InputError(path + ": cannot read image: " + OIIO::geterror());
    const ImageSpec& spec = in->spec();
    ExrImage img;
    img.width = spec.width;
    img.height = spec.height;
    img.window = FilmWindow{spec.full_width, spec.full_height, spec.x - spec.full_x, spec.y - spec.full_y, spec.width, spec.height};
    const size_t n = size_t(spec.width) * size_t(spec.height), c = size_t(spec.nchannels);
    std::vector<float> data(n * c);
    if (!in->read_image(0, 0, 0, int(c), TypeDesc::FLOAT, data.data())) throw InputError(path + ": cannot read pixels: " + in->geterror());
    for (size_t k = 0; k < c; ++k) {
        std::vector<float> ch(n);
        for (size_t i = 0; i < n; ++i) ch[i] = data[i * c + k];
        img.channels[spec.channel_name(int(k))] = std::move(ch);
    }
    for (const auto& attr : spec.extra_attribs) img.attributes[attr.name().string()] = attr.get_string();
    in->close();
    return img;
}

void checkWritable(const std::string& path) {
    if (path.empty()) throw InputError("no output file given");
    const fs::path p(path);
    if (fs::is_directory(p)) throw InputError(path + ": is a directory, not a file");
    const std::string probe = tempPathFor(path, ".probe");
    std::ofstream f(probe);
    if (!f) throw InputError(path + ": cannot write into " +
                             (p.has_parent_path() ? p.parent_path().string() : std::string(".")) +
                             " (missing folder or no permission)");
    f.close();
    std::remove(probe.c_str());
}

}  // namespace bdptref
