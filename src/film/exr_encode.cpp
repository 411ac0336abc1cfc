#include "film/exr_encode.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFloatAttribute.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfIO.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfMultiPartOutputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfOutputPart.h>
#include <OpenEXR/ImfPartType.h>
#include <OpenEXR/ImfStandardAttributes.h>
#include <OpenEXR/ImfStringAttribute.h>

#include <cstring>
#include <stdexcept>

namespace bdptref {

namespace {

class MemoryStream : public Imf::OStream {
public:
    MemoryStream() : Imf::OStream("memory") {}
    void write(const char c[], int n) override {
        if (pos_ + uint64_t(n) > bytes.size()) bytes.resize(size_t(pos_) + size_t(n));
        std::memcpy(bytes.data() + pos_, c, size_t(n));
        pos_ += uint64_t(n);
    }
    uint64_t tellp() override { return pos_; }
    void seekp(uint64_t pos) override { pos_ = pos; }
    std::vector<char> bytes;

private:
    uint64_t pos_ = 0;
};

Imf::Header headerOf(const ExrPartSpec& s) {
    const Imath::Box2i data({s.x, s.y}, {s.x + s.width - 1, s.y + s.height - 1});
    const Imath::Box2i display({0, 0}, {s.fullWidth - 1, s.fullHeight - 1});
    Imf::Header h(display, data);
    h.compression() = s.compress ? Imf::ZIP_COMPRESSION : Imf::NO_COMPRESSION;
    // zlib level 1: lossless like any level; on a 128 x 128 render with its variance and count
    // channels the default level spent more CPU than the sampling of a few spp (bench/README.md).
    h.zipCompressionLevel() = 1;
    for (const ExrPartSpec::Channel& c : s.channels) h.channels().insert(c.name, Imf::Channel(c.isUint ? Imf::UINT : Imf::FLOAT));
    if (!s.name.empty()) h.setName(s.name);
    // Linear Rec.709 / sRGB primaries and D65 white (x,y of R, G, B, white): the colour space of
    // the radiance bdptref computes. OpenEXR requires it equal in every part.
    if (s.chromaticities)
        Imf::addChromaticities(h, Imf::Chromaticities({0.64f, 0.33f}, {0.30f, 0.60f}, {0.15f, 0.06f}, {0.3127f, 0.3290f}));
    for (const auto& [k, v] : s.metadata.strings) h.insert(k, Imf::StringAttribute(v));
    for (const auto& [k, v] : s.metadata.ints) h.insert(k, Imf::IntAttribute(v));
    for (const auto& [k, v] : s.metadata.floats) h.insert(k, Imf::FloatAttribute(v));
    return h;
}

Imf::FrameBuffer frameBufferOf(const ExrPart& part) {
    const ExrPartSpec& s = part.spec;
    const size_t xStride = 4 * s.channels.size(), yStride = xStride * size_t(s.width);
    // OpenEXR addresses pixel (x, y) of the data window at base + x*xStride + y*yStride.
    char* origin = const_cast<char*>(static_cast<const char*>(part.pixels)) - (ptrdiff_t(s.x) * ptrdiff_t(xStride) +
                                                                                 ptrdiff_t(s.y) * ptrdiff_t(yStride));
    Imf::FrameBuffer fb;
    for (size_t k = 0; k < s.channels.size(); ++k)
        fb.insert(s.channels[k].name, Imf::Slice(s.channels[k].isUint ? Imf::UINT : Imf::FLOAT, origin + 4 * k, xStride, yStride));
    return fb;
}

}  // namespace

std::vector<char> encodeExr(const std::vector<ExrPart>& parts) {
    MemoryStream stream;
    if (parts.size() == 1) {  // a plain single-part file, readable by every EXR reader
        Imf::OutputFile out(stream, headerOf(parts[0].spec));
        out.setFrameBuffer(frameBufferOf(parts[0]));
        out.writePixels(parts[0].spec.height);
    } else {
        std::vector<Imf::Header> headers;
        for (size_t k = 0; k < parts.size(); ++k) {
            headers.push_back(headerOf(parts[k].spec));
            if (!headers.back().hasName()) headers.back().setName(k == 0 ? "image" : "part" + std::to_string(k));
            headers.back().setType(Imf::SCANLINEIMAGE);
        }
        Imf::MultiPartOutputFile out(stream, headers.data(), int(headers.size()));
        for (size_t k = 0; k < parts.size(); ++k) {
            Imf::OutputPart part(out, int(k));
            part.setFrameBuffer(frameBufferOf(parts[k]));
            part.writePixels(parts[k].spec.height);
        }
    }
    return std::move(stream.bytes);
}

}  // namespace bdptref
