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

using OIIO::ImageSpec;
using OIIO::TypeDesc;

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

Imf::Header headerOf(const ImageSpec& s) {
    const Imath::Box2i data({s.x, s.y}, {s.x + s.width - 1, s.y + s.height - 1});
    const Imath::Box2i display({s.full_x, s.full_y}, {s.full_x + s.full_width - 1, s.full_y + s.full_height - 1});
    Imf::Header h(display, data);
    h.compression() = Imf::ZIP_COMPRESSION;
    for (int k = 0; k < s.nchannels; ++k) {
        const TypeDesc f = s.channelformat(k);
        if (f != TypeDesc::FLOAT && f != TypeDesc::UINT) throw std::logic_error("encodeExr: channels must be FLOAT or UINT");
        h.channels().insert(s.channel_name(k), Imf::Channel(f == TypeDesc::UINT ? Imf::UINT : Imf::FLOAT));
    }
    for (const OIIO::ParamValue& p : s.extra_attribs) {
        const std::string name = p.name().string();
        const TypeDesc t = p.type();
        if (name == "compression") {
            h.compression() = p.get_string() == "none" ? Imf::NO_COMPRESSION : Imf::ZIP_COMPRESSION;
        } else if (name == "oiio:subimagename") {
            h.setName(p.get_string());
        } else if (name == "chromaticities" && t == TypeDesc(TypeDesc::FLOAT, 8)) {
            const float* c = static_cast<const float*>(p.data());
            Imf::addChromaticities(h, Imf::Chromaticities({c[0], c[1]}, {c[2], c[3]}, {c[4], c[5]}, {c[6], c[7]}));
        } else if (t == TypeDesc::STRING) {
            h.insert(name, Imf::StringAttribute(p.get_string()));
        } else if (t == TypeDesc::INT) {
            h.insert(name, Imf::IntAttribute(p.get_int()));
        } else if (t == TypeDesc::FLOAT) {
            h.insert(name, Imf::FloatAttribute(p.get_float()));
        } else {
            throw std::logic_error("encodeExr: attribute " + name + " has an unsupported type " + t.c_str());
        }
    }
    return h;
}

Imf::FrameBuffer frameBufferOf(const ExrPart& part) {
    const ImageSpec& s = part.spec;
    const size_t xStride = 4 * size_t(s.nchannels), yStride = xStride * size_t(s.width);
    // OpenEXR addresses pixel (x, y) of the data window at base + x*xStride + y*yStride.
    char* origin = const_cast<char*>(static_cast<const char*>(part.pixels)) - (ptrdiff_t(s.x) * ptrdiff_t(xStride) +
                                                                                 ptrdiff_t(s.y) * ptrdiff_t(yStride));
    Imf::FrameBuffer fb;
    for (int k = 0; k < s.nchannels; ++k)
        fb.insert(s.channel_name(k), Imf::Slice(s.channelformat(k) == TypeDesc::UINT ? Imf::UINT : Imf::FLOAT,
                                                origin + 4 * k, xStride, yStride));
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
