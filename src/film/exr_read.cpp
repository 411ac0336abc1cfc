#include "film/exr_read.h"

#include "bdptref/errors.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfChromaticitiesAttribute.h>
#include <OpenEXR/ImfCompressionAttribute.h>
#include <OpenEXR/ImfDoubleAttribute.h>
#include <OpenEXR/ImfFloatAttribute.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputPart.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfLineOrderAttribute.h>
#include <OpenEXR/ImfMultiPartInputFile.h>
#include <OpenEXR/ImfPartType.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/ImfVecAttribute.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

namespace bdptref {

namespace {

std::string formatFloats(const float* v, int n) {  // OpenImageIO's ParamValue::get_string: "%g", ", "
    std::string s;
    char buf[32];
    for (int k = 0; k < n; ++k) {
        std::snprintf(buf, sizeof buf, "%g", double(v[k]));
        s += (k ? ", " : "") + std::string(buf);
    }
    return s;
}

const char* compressionName(Imf::Compression c) {  // OpenImageIO's names
    switch (c) {
        case Imf::NO_COMPRESSION: return "none";
        case Imf::RLE_COMPRESSION: return "rle";
        case Imf::ZIPS_COMPRESSION: return "zips";
        case Imf::ZIP_COMPRESSION: return "zip";
        case Imf::PIZ_COMPRESSION: return "piz";
        case Imf::PXR24_COMPRESSION: return "pxr24";
        case Imf::B44_COMPRESSION: return "b44";
        case Imf::B44A_COMPRESSION: return "b44a";
        case Imf::DWAA_COMPRESSION: return "dwaa";
        case Imf::DWAB_COMPRESSION: return "dwab";
        default: return "unknown";
    }
}

// The header's attributes as text. Windows, channels, tiles and type are geometry, not metadata.
void readAttributes(const Imf::Header& h, ExrPartInfo& info) {
    for (auto it = h.begin(); it != h.end(); ++it) {
        const std::string name = it.name();
        const Imf::Attribute& a = it.attribute();
        if (name == "dataWindow" || name == "displayWindow" || name == "channels" || name == "tiles" || name == "type")
            continue;
        if (name == "chunkCount") {  // multi-part files only
            info.attributes["openexr:chunkCount"] = std::to_string(h.chunkCount());
        } else if (name == "compression") {
            info.attributes["compression"] = compressionName(h.compression());
        } else if (name == "name") {
            info.attributes["name"] = info.attributes["oiio:subimagename"] = h.name();
        } else if (name == "lineOrder") {  // OpenImageIO names only the unusual orders
            const Imf::LineOrder o = h.lineOrder();
            if (o != Imf::INCREASING_Y) info.attributes["openexr:lineOrder"] = o == Imf::DECREASING_Y ? "decreasingY" : "randomY";
        } else if (const auto* s = dynamic_cast<const Imf::StringAttribute*>(&a)) {
            info.attributes[name] = s->value();
            info.typed.strings.push_back({name, s->value()});
        } else if (const auto* i = dynamic_cast<const Imf::IntAttribute*>(&a)) {
            info.attributes[name] = std::to_string(i->value());
            info.typed.ints.push_back({name, i->value()});
        } else if (const auto* f = dynamic_cast<const Imf::FloatAttribute*>(&a)) {
            const std::string key = name == "pixelAspectRatio" ? "PixelAspectRatio" : name;
            info.attributes[key] = formatFloats(&f->value(), 1);
            info.typed.floats.push_back({key, f->value()});
        } else if (const auto* d = dynamic_cast<const Imf::DoubleAttribute*>(&a)) {
            const float v = float(d->value());
            info.attributes[name] = formatFloats(&v, 1);
        } else if (const auto* v2 = dynamic_cast<const Imf::V2fAttribute*>(&a)) {
            info.attributes[name] = formatFloats(&v2->value().x, 2);
        } else if (const auto* c = dynamic_cast<const Imf::ChromaticitiesAttribute*>(&a)) {
            const Imf::Chromaticities& v = c->value();
            const float xy[8] = {v.red.x, v.red.y, v.green.x, v.green.y, v.blue.x, v.blue.y, v.white.x, v.white.y};
            info.attributes[name] = formatFloats(xy, 8);
        } else {
            info.attributes[name] = std::string("(") + a.typeName() + ")";
        }
    }
}

}  // namespace

bool hasExrMagic(const std::string& path) {
    // Only a regular file: opening a FIFO or a device to read its first bytes would block or
    // consume it; the caller's own checks then name what it is.
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) return false;
    std::ifstream in(path, std::ios::binary);
    unsigned char m[4] = {0, 0, 0, 0};
    in.read(reinterpret_cast<char*>(m), 4);
    return in.gcount() == 4 && m[0] == 0x76 && m[1] == 0x2f && m[2] == 0x31 && m[3] == 0x01;
}

ExrReader::ExrReader(const std::string& path) : path_(path) {
    try {
        file_ = std::make_unique<Imf::MultiPartInputFile>(path.c_str());
        for (int k = 0; k < file_->parts(); ++k) {
            const Imf::Header& h = file_->header(k);
            if (h.hasType() && Imf::isDeepData(h.type()))
                throw InputError(path + ": part " + std::to_string(k) + " holds deep data, which bdptref does not read");
            ExrPartInfo info;
            if (h.hasName()) info.name = h.name();
            const Imath::Box2i& dw = h.dataWindow();
            const Imath::Box2i& disp = h.displayWindow();
            info.x = dw.min.x;
            info.y = dw.min.y;
            info.width = dw.max.x - dw.min.x + 1;
            info.height = dw.max.y - dw.min.y + 1;
            info.fullX = disp.min.x;
            info.fullY = disp.min.y;
            info.fullWidth = disp.max.x - disp.min.x + 1;
            info.fullHeight = disp.max.y - disp.min.y + 1;
            for (auto c = h.channels().begin(); c != h.channels().end(); ++c) {
                info.channels.push_back(c.name());
                info.channelIsUint.push_back(c.channel().type == Imf::UINT);
            }
            readAttributes(h, info);
            parts_.push_back(std::move(info));
        }
    } catch (const InputError&) {
        throw;
    } catch (const std::exception& e) {
        throw InputError(path + ": cannot read the EXR: " + e.what());
    }
}

ExrReader::~ExrReader() = default;

std::map<std::string, std::vector<float>> ExrReader::readFloat(int k) {
    const ExrPartInfo& p = part(k);
    const size_t n = size_t(p.width) * size_t(p.height), c = p.channels.size();
    std::map<std::string, std::vector<float>> out;
    std::map<std::string, std::vector<uint32_t>> uints;  // UINT channels, converted below
    try {
        Imf::InputPart in(*file_, k);
        Imf::FrameBuffer fb;
        // OpenEXR addresses pixel (x, y) of the data window at base + (x + y * width) * 4.
        const ptrdiff_t originOffset = ptrdiff_t(p.x) + ptrdiff_t(p.y) * ptrdiff_t(p.width);
        for (size_t j = 0; j < c; ++j) {
            const bool u = p.channelIsUint[j];
            char* base = u ? reinterpret_cast<char*>((uints[p.channels[j]] = std::vector<uint32_t>(n)).data())
                           : reinterpret_cast<char*>((out[p.channels[j]] = std::vector<float>(n)).data());
            fb.insert(p.channels[j], Imf::Slice(u ? Imf::UINT : Imf::FLOAT, base - originOffset * 4, 4, 4 * size_t(p.width)));
        }
        in.setFrameBuffer(fb);
        in.readPixels(p.y, p.y + p.height - 1);
    } catch (const std::exception& e) {
        throw InputError(path_ + ": cannot read pixels: " + e.what());
    }
    for (const auto& [name, v] : uints) {
        std::vector<float>& ch = out[name];
        ch.resize(n);
        for (size_t i = 0; i < n; ++i) ch[i] = float(v[i]) * (1.0f / 4294967295.0f);
    }
    return out;
}

std::map<std::string, std::vector<uint32_t>> ExrReader::readUint(int k, const std::vector<std::string>& names) {
    const ExrPartInfo& p = part(k);
    const size_t n = size_t(p.width) * size_t(p.height);
    std::map<std::string, std::vector<uint32_t>> out;
    try {
        Imf::InputPart in(*file_, k);
        Imf::FrameBuffer fb;
        const ptrdiff_t originOffset = ptrdiff_t(p.x) + ptrdiff_t(p.y) * ptrdiff_t(p.width);
        for (const std::string& name : names) {
            std::vector<uint32_t>& v = out[name];
            v.resize(n);
            fb.insert(name, Imf::Slice(Imf::UINT, reinterpret_cast<char*>(v.data()) - originOffset * 4, 4, 4 * size_t(p.width)));
        }
        in.setFrameBuffer(fb);
        in.readPixels(p.y, p.y + p.height - 1);
    } catch (const std::exception& e) {
        throw InputError(path_ + ": cannot read pixels: " + e.what());
    }
    return out;
}

ExrImage readExrImage(const std::string& path) {
    ExrReader r(path);
    const ExrPartInfo& p = r.part(0);
    ExrImage img;
    img.width = p.width;
    img.height = p.height;
    img.window = p.window();
    img.attributes = p.attributes;
    img.channels = r.readFloat(0);
    return img;
}

}  // namespace bdptref
