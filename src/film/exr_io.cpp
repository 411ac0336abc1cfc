#include "bdptref/exr_io.h"

#include "bdptref/errors.h"
#include "core/output_file.h"
#include "film/exr_encode.h"
#include "film/film_exact.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <cmath>
#include <stdexcept>

namespace bdptref {

using OIIO::ImageInput;
using OIIO::ImageOutput;
using OIIO::ImageSpec;
using OIIO::TypeDesc;

namespace {

void applyMetadata(ImageSpec& spec, const ExrMetadata& md) {
    for (const auto& [k, v] : md.strings) spec.attribute(k, v);
    for (const auto& [k, v] : md.ints) spec.attribute(k, v);
    for (const auto& [k, v] : md.floats) spec.attribute(k, v);
}

// Linear Rec.709 / sRGB primaries and D65 white (x,y of R, G, B, white): the colour space of the
// radiance bdptref computes. OpenEXR requires it equal in every part.
void applyColourSpace(ImageSpec& spec) {
    static const float kRec709[8] = {0.64f, 0.33f, 0.30f, 0.60f, 0.15f, 0.06f, 0.3127f, 0.3290f};
    spec.attribute("chromaticities", TypeDesc(TypeDesc::FLOAT, 8), kRec709);
}

// Encodes a PNG in memory (OpenImageIO through an IOProxy), then hands the bytes to
// writeOutputBytes, which replaces `path` durably (core/output_file.h): no write error can be
// lost inside OpenImageIO. (EXRs go through exr_encode.h instead: OpenImageIO 2.4 ignores the
// IOProxy for multi-part EXRs and writes to the path itself.)
void writePng(const std::string& path, const ImageSpec& spec, const void* data, TypeDesc type) {
    auto out = ImageOutput::create("png");
    if (!out) throw InputError(path + ": cannot create an image writer: " + OIIO::geterror());
    std::vector<unsigned char> bytes;
    OIIO::Filesystem::IOVecOutput proxy(bytes);
    if (!out->supports("ioproxy") || !out->set_ioproxy(&proxy)) throw std::logic_error("OpenImageIO's PNG writer cannot write to memory");
    bool ok = out->open(path, spec) && out->write_image(type, data);
    const std::string err = ok ? std::string() : out->geterror();
    if (!out->close() || !ok) throw InputError(path + ": cannot encode the PNG: " + (err.empty() ? out->geterror() : err));
    if (bytes.empty()) throw std::logic_error("OpenImageIO's PNG writer ignored the IOProxy");
    writeOutputBytes(path, bytes.data(), bytes.size());
}

}  // namespace

void writeLayersExr(const std::string& path, int width, int height, const std::vector<ExrLayer>& layers,
                    const ExrMetadata& metadata, const std::vector<ExrUintLayer>& uintLayers, const FilmWindow& window) {
    const size_t n = size_t(width) * size_t(height);
    ImageSpec spec(width, height, int(layers.size()), TypeDesc::FLOAT);
    if (window.fullWidth > 0) {  // data window = the crop, display window = the full image
        spec.x = window.x0;
        spec.y = window.y0;
        spec.full_x = spec.full_y = 0;
        spec.full_width = window.fullWidth;
        spec.full_height = window.fullHeight;
    }
    spec.channelnames.clear();
    for (const ExrLayer& l : layers) spec.channelnames.push_back(l.name);
    spec.attribute("compression", "zip");
    applyColourSpace(spec);
    applyMetadata(spec, metadata);
    std::vector<float> data(n * layers.size());
    for (size_t k = 0; k < layers.size(); ++k)
        for (size_t i = 0; i < n; ++i) data[i * layers.size() + k] = layers[k].pixels[i];
    std::vector<ExrPart> parts{{spec, data.data()}};
    // The UINT channels go into a second part named "exact", so viewers and `oiiotool --info`
    // list only the image layers in the first one.
    std::vector<uint32_t> exact(n * uintLayers.size());
    if (!uintLayers.empty()) {
        ImageSpec es = spec;  // the same data and display windows as the image part
        es.nchannels = int(uintLayers.size());
        es.set_format(TypeDesc::UINT);
        es.channelnames.clear();
        for (const ExrUintLayer& l : uintLayers) es.channelnames.push_back(l.name);
        es.extra_attribs.clear();
        es.attribute("compression", "zip");
        es.attribute("oiio:subimagename", kExactPartName);
        applyColourSpace(es);
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
    writePng(path, ImageSpec(width, height, 3, TypeDesc::UINT8), rgb.data(), TypeDesc::UINT8);
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
    writePng(path, spec, data.data(), TypeDesc::FLOAT);
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

void checkWritable(const std::string& path) { checkOutputWritable(path); }

}  // namespace bdptref
