// Image input and output without OpenImageIO in bdptref's start-up path (issue 16, "Start-up";
// src/film/image_read.h), proven against OpenImageIO itself, which only this test binary links:
// - readImage of EXRs written here with OpenEXR in the layouts bdptref may meet (HALF, FLOAT and
//   UINT channels; scanline and tiled; a data window inside a display window; multi-part; every
//   compression OpenEXR has): the same window, the same channels bit for bit, and the same text
//   for every attribute both report (all user attributes, compression, chromaticities, ...);
// - readFilmExr of a tiled, PIZ-compressed copy of a checkpoint: the same film bit for bit;
// - readImage of a Radiance .hdr (stb_image) and of a PNG (the OpenImageIO module): the same
//   floats as OpenImageIO's own reading;
// - the preview PNG: decodes (stb_image) to exactly the bytes OpenImageIO's PNG writer produced
//   from the same floats, and unitToByte equals OpenImageIO's float -> UINT8 conversion on 2^20
//   floats in [-0.01, 1.01] and on every rounding boundary (k + 0.5) / 255;
// - the CLI: reading a PNG with the module missing exits 2 naming libbdptref_oiio.so; `compare`
//   of two EXRs and `--version` load no OpenImageIO library (LD_DEBUG=files).
#include "bdptref/checkpoint.h"
#include "bdptref/exr_io.h"
#include "film/png_write.h"
#include "support/render_util.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfCompression.h>
#include <OpenEXR/ImfFloatAttribute.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfMultiPartInputFile.h>
#include <OpenEXR/ImfMultiPartOutputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfOutputPart.h>
#include <OpenEXR/ImfInputPart.h>
#include <OpenEXR/ImfPartType.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/ImfTiledOutputFile.h>
#include <OpenEXR/ImfTiledOutputPart.h>
#include <OpenImageIO/imageio.h>
#include <catch2/catch.hpp>

#include <fstream>
#include <stb/stb_image.h>
#include <stb/stb_image_write.h>

#include <sys/wait.h>

#include <xmmintrin.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>

using namespace bdptref;
using namespace bdptref::test;

namespace {

std::string testDir() {
    static const std::string dir = makeTempDir("image-io");
    return dir;
}

// Clears FTZ/DAZ on this thread while it lives. A render earlier in this process sets them
// (Embree's advice) and OpenImageIO's SIMD half -> float conversion then reads half denormals as
// 0, where OpenEXR's table conversion (ours) is exact; a CLI process reading an image (what this
// file compares against) has them off.
struct DenormalsOn {
    unsigned saved = _mm_getcsr();
    DenormalsOn() { _mm_setcsr(saved & ~0x8040u); }  // 0x8000 FTZ, 0x0040 DAZ
    ~DenormalsOn() { _mm_setcsr(saved); }
};

// readImage as it was before issue 16: OpenImageIO, first subimage, every channel as FLOAT.
ExrImage readWithOiio(const std::string& path) {
    const DenormalsOn denormals;
    auto in = OIIO::ImageInput::open(path);
    REQUIRE(in);
    const OIIO::ImageSpec& spec = in->spec();
    ExrImage img;
    img.width = spec.width;
    img.height = spec.height;
    img.window = FilmWindow{spec.full_width, spec.full_height, spec.x - spec.full_x, spec.y - spec.full_y, spec.width, spec.height};
    const size_t n = size_t(spec.width) * size_t(spec.height), c = size_t(spec.nchannels);
    std::vector<float> data(n * c);
    REQUIRE(in->read_image(0, 0, 0, int(c), OIIO::TypeDesc::FLOAT, data.data()));
    for (size_t k = 0; k < c; ++k) {
        std::vector<float> ch(n);
        for (size_t i = 0; i < n; ++i) ch[i] = data[i * c + k];
        img.channels[spec.channel_name(int(k))] = std::move(ch);
    }
    for (const auto& attr : spec.extra_attribs) img.attributes[attr.name().string()] = attr.get_string();
    return img;
}

bool sameBits(const std::vector<float>& a, const std::vector<float>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

// Attributes OpenImageIO invents rather than reads from the header (nothing bdptref reads).
bool oiioOnly(const std::string& name) {
    return name.rfind("oiio:", 0) == 0 && name != "oiio:subimagename";
}

void requireSameImage(const ExrImage& ours, const ExrImage& theirs) {
    CHECK(ours.width == theirs.width);
    CHECK(ours.height == theirs.height);
    CHECK(ours.window == theirs.window);
    REQUIRE(ours.channels.size() == theirs.channels.size());
    for (const auto& [name, px] : theirs.channels) {
        INFO("channel " << name);
        REQUIRE(ours.has(name));
        CHECK(sameBits(ours.channels.at(name), px));
    }
    for (const auto& [name, text] : theirs.attributes) {
        INFO("attribute " << name << " = " << text);
        if (oiioOnly(name)) continue;
        REQUIRE(ours.attributes.count(name) == 1);
        CHECK(ours.attributes.at(name) == text);
    }
    for (const auto& [name, text] : ours.attributes) {
        INFO("attribute " << name << " = " << text << " is not one OpenImageIO reported");
        CHECK(theirs.attributes.count(name) == 1);
    }
}

// Values of every kind a render holds: signed, tiny, large, exact zeros.
float testValue(size_t channel, size_t i) {
    const double u = std::sin(double(i) * 12.9898 + double(channel) * 78.233) * 43758.5453;
    const double f = u - std::floor(u);
    if (i % 7 == 3) return 0.f;
    return float((f - 0.2) * std::pow(10.0, double(int(i % 9) - 4)));
}

struct ExrLayout {
    Imf::Compression compression = Imf::ZIP_COMPRESSION;
    Imf::PixelType type = Imf::FLOAT;
    bool tiled = false;
    Imath::Box2i data{{2, 1}, {12, 9}}, display{{0, 0}, {15, 11}};
};

// An EXR with R,G,B,A, variance.R/G/B and count, and user attributes of each type.
void writeTestExr(const std::string& path, const ExrLayout& l) {
    const std::vector<std::string> names = {"R", "G", "B", "A", "variance.R", "variance.G", "variance.B", "count"};
    Imf::Header h(l.display, l.data);
    h.compression() = l.compression;
    for (const std::string& c : names) h.channels().insert(c, Imf::Channel(l.type));
    h.insert("bdptref:seed", Imf::StringAttribute("17"));
    h.insert("bdptref:spp", Imf::IntAttribute(64));
    h.insert("bdptref:renderSeconds", Imf::FloatAttribute(1.2345678f));
    const int w = l.data.max.x - l.data.min.x + 1, hgt = l.data.max.y - l.data.min.y + 1;
    const size_t n = size_t(w) * size_t(hgt);
    std::vector<float> px(n * names.size());
    std::vector<uint32_t> upx(n * names.size());
    std::vector<Imath::half> hpx(n * names.size());
    for (size_t c = 0; c < names.size(); ++c)
        for (size_t i = 0; i < n; ++i) {
            px[c * n + i] = testValue(c, i);
            upx[c * n + i] = uint32_t(i * 2654435761u + c);
            hpx[c * n + i] = Imath::half(px[c * n + i]);
        }
    Imf::FrameBuffer fb;
    const ptrdiff_t origin = ptrdiff_t(l.data.min.x) + ptrdiff_t(l.data.min.y) * w;
    for (size_t c = 0; c < names.size(); ++c) {
        const size_t bytes = l.type == Imf::HALF ? 2 : 4;
        char* base = l.type == Imf::UINT   ? reinterpret_cast<char*>(upx.data() + c * n)
                     : l.type == Imf::HALF ? reinterpret_cast<char*>(hpx.data() + c * n)
                                           : reinterpret_cast<char*>(px.data() + c * n);
        fb.insert(names[c], Imf::Slice(l.type, base - origin * ptrdiff_t(bytes), bytes, bytes * size_t(w)));
    }
    if (l.tiled) {
        h.setTileDescription(Imf::TileDescription(4, 3));
        Imf::TiledOutputFile out(path.c_str(), h);
        out.setFrameBuffer(fb);
        out.writeTiles(0, out.numXTiles() - 1, 0, out.numYTiles() - 1);
    } else {
        Imf::OutputFile out(path.c_str(), h);
        out.setFrameBuffer(fb);
        out.writePixels(hgt);
    }
}

}  // namespace

TEST_CASE("readImage reads EXRs of every channel type, layout and compression as OpenImageIO did", "[exr][image-io]") {
    const std::vector<Imf::Compression> compressions = {
        Imf::NO_COMPRESSION, Imf::RLE_COMPRESSION,   Imf::ZIPS_COMPRESSION, Imf::ZIP_COMPRESSION, Imf::PIZ_COMPRESSION,
        Imf::PXR24_COMPRESSION, Imf::B44_COMPRESSION, Imf::B44A_COMPRESSION, Imf::DWAA_COMPRESSION, Imf::DWAB_COMPRESSION};
    int files = 0;
    for (Imf::PixelType type : {Imf::HALF, Imf::FLOAT, Imf::UINT})
        for (bool tiled : {false, true})
            for (Imf::Compression c : compressions) {
                ExrLayout l;
                l.type = type;
                l.tiled = tiled;
                l.compression = c;
                const std::string path = testDir() + "/t" + std::to_string(files++) + ".exr";
                INFO("type " << int(type) << (tiled ? " tiled" : " scanline") << " compression " << int(c));
                writeTestExr(path, l);
                requireSameImage(readImage(path), readWithOiio(path));
            }
    // A full data window, and a data window that starts left of and above the display window.
    for (const Imath::Box2i& data : {Imath::Box2i({0, 0}, {15, 11}), Imath::Box2i({-3, -2}, {7, 5})}) {
        ExrLayout l;
        l.type = Imf::HALF;
        l.data = data;
        const std::string path = testDir() + "/w" + std::to_string(files++) + ".exr";
        writeTestExr(path, l);
        const ExrImage img = readImage(path);
        CHECK(img.window.x0 == data.min.x);
        requireSameImage(img, readWithOiio(path));
    }
}

TEST_CASE("readImage and readFilmExr read bdptref's own multi-part EXR as OpenImageIO did", "[exr][image-io]") {
    const std::string exr = testDir() + "/render.exr";
    REQUIRE(runCli("render " + sourcePath("scenes/cornell-box.gltf") +
                   " -o " + exr + " --width 12 --height 10 --crop 2,1,11,9 --spp 3 --max-depth 3 --seed 5 --integrator bdpt --strategies -q --no-preview") == 0);
    const ExrImage img = readImage(exr);
    CHECK(img.has("s1t2.weighted.R"));
    CHECK(!img.has("exact.count.hi"));  // part 0 only
    CHECK(img.window == FilmWindow{12, 10, 2, 1, 9, 8});
    requireSameImage(img, readWithOiio(exr));

    // The same file rewritten tiled, PIZ-compressed (OpenEXR copies every part and attribute):
    // the exact state must come back bit for bit.
    const std::string tiled = testDir() + "/render-tiled.exr";
    {
        Imf::MultiPartInputFile in(exr.c_str());
        std::vector<Imf::Header> headers;
        for (int k = 0; k < in.parts(); ++k) {
            Imf::Header h = in.header(k);
            h.compression() = Imf::PIZ_COMPRESSION;
            h.setTileDescription(Imf::TileDescription(5, 4));
            h.setType(Imf::TILEDIMAGE);
            headers.push_back(h);
        }
        Imf::MultiPartOutputFile out(tiled.c_str(), headers.data(), int(headers.size()));
        for (int k = 0; k < in.parts(); ++k) {
            const Imf::Header& h = in.header(k);
            const Imath::Box2i dw = h.dataWindow();
            const int w = dw.max.x - dw.min.x + 1, hh = dw.max.y - dw.min.y + 1;
            std::vector<std::vector<uint32_t>> store;
            Imf::FrameBuffer fb;
            for (auto c = h.channels().begin(); c != h.channels().end(); ++c) {
                store.emplace_back(size_t(w) * size_t(hh));
                char* base = reinterpret_cast<char*>(store.back().data()) - (ptrdiff_t(dw.min.x) + ptrdiff_t(dw.min.y) * w) * 4;
                fb.insert(c.name(), Imf::Slice(c.channel().type == Imf::UINT ? Imf::UINT : Imf::FLOAT, base, 4, 4 * size_t(w)));
            }
            Imf::InputPart ip(in, k);
            ip.setFrameBuffer(fb);
            ip.readPixels(dw.min.y, dw.max.y);
            Imf::TiledOutputPart op(out, k);
            op.setFrameBuffer(fb);
            op.writeTiles(0, op.numXTiles() - 1, 0, op.numYTiles() - 1);
        }
    }
    const FilmFile a = readFilmExr(exr), b = readFilmExr(tiled);
    CHECK(a.film.window() == b.film.window());
    CHECK(a.film.samples().text() == b.film.samples().text());
    for (const auto& [name, text] : a.attributes)  // the copy differs in compression and tiles only
        if (name.rfind("bdptref:", 0) == 0) CHECK(b.attributes.at(name) == text);
    for (int y = 0; y < a.film.height(); ++y)
        for (int x = 0; x < a.film.width(); ++x) {
            CHECK(a.film.count(x, y) == b.film.count(x, y));
            const DVec3 ma = a.film.mean(x, y), mb = b.film.mean(x, y);
            CHECK(std::memcmp(&ma, &mb, sizeof ma) == 0);
        }
    CHECK(a.metadata.strings.size() == b.metadata.strings.size());
    CHECK(a.metadata.ints == b.metadata.ints);
    CHECK(a.metadata.floats == b.metadata.floats);
    requireSameImage(readImage(tiled), readWithOiio(tiled));
}

TEST_CASE("readImage reads a Radiance .hdr and a PNG as OpenImageIO did", "[image-io]") {
    const int w = 9, h = 7;
    std::vector<float> rgb(size_t(w) * size_t(h) * 3);
    std::vector<unsigned char> bytes(rgb.size());
    for (size_t i = 0; i < rgb.size(); ++i) {
        rgb[i] = std::fabs(testValue(i % 3, i / 3)) * 50.f;
        bytes[i] = static_cast<unsigned char>((i * 37) % 256);
    }
    const std::string hdr = testDir() + "/env.hdr", png = testDir() + "/in.png";
    REQUIRE(stbi_write_hdr(hdr.c_str(), w, h, 3, rgb.data()));
    REQUIRE(stbi_write_png(png.c_str(), w, h, 3, bytes.data(), w * 3));
    const ExrImage fromHdr = readImage(hdr), fromPng = readImage(png);
    CHECK(fromHdr.width == w);
    CHECK(fromHdr.height == h);
    REQUIRE(fromHdr.has("R"));
    // RGBE keeps 8 bits of mantissa: close to what was written, and exactly what OpenImageIO read.
    CHECK(fromHdr.at("G", 4, 3) == Approx(rgb[(3 * size_t(w) + 4) * 3 + 1]).epsilon(1.0 / 128));
    const ExrImage oiioHdr = readWithOiio(hdr), oiioPng = readWithOiio(png);
    for (const char* c : {"R", "G", "B"}) {
        INFO(c);
        CHECK(sameBits(fromHdr.channels.at(c), oiioHdr.channels.at(c)));
    }
    requireSameImage(fromPng, oiioPng);

    // A bottom-up .hdr ("+Y 2 +X 3"; flat RGBE, too narrow for RLE): stb_image refuses the
    // layout, so it goes to the module, which reads it as OpenImageIO does.
    const std::string flipped = testDir() + "/flipped.hdr";
    {
        std::FILE* f = std::fopen(flipped.c_str(), "wb");
        REQUIRE(f);
        std::fputs("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n+Y 2 +X 3\n", f);
        for (int i = 0; i < 6; ++i) {
            const unsigned char rgbe[4] = {static_cast<unsigned char>(40 * i + 10), 128, 200, 129};
            std::fwrite(rgbe, 1, 4, f);
        }
        std::fclose(f);
    }
    const ExrImage fromFlipped = readImage(flipped);
    CHECK(fromFlipped.width == 3);
    CHECK(fromFlipped.height == 2);
    const ExrImage oiioFlipped = readWithOiio(flipped);
    for (const char* c : {"R", "G", "B"}) {
        INFO(c);
        REQUIRE(fromFlipped.has(c));
        CHECK(sameBits(fromFlipped.channels.at(c), oiioFlipped.channels.at(c)));
    }
    CHECK(fromPng.at("B", 2, 1) == Approx(bytes[(1 * size_t(w) + 2) * 3 + 2] / 255.0));
}

TEST_CASE("preview PNG bytes equal those of OpenImageIO's PNG writer", "[image-io]") {
    // unitToByte against OpenImageIO's own conversion, densely and on every rounding boundary.
    std::vector<float> f;
    for (int i = 0; i <= (1 << 20); ++i) f.push_back(-0.01f + 1.02f * float(i) / float(1 << 20));
    for (int k = 0; k < 255; ++k)
        for (float d : {-1e-7f, 0.f, 1e-7f}) f.push_back((float(k) + 0.5f) / 255.f + d);
    std::vector<uint8_t> theirs(f.size());
    REQUIRE(OIIO::convert_pixel_values(OIIO::TypeDesc::FLOAT, f.data(), OIIO::TypeDesc::UINT8, theirs.data(), int(f.size())));
    size_t differ = 0;
    for (size_t i = 0; i < f.size(); ++i) differ += unitToByte(f[i]) != theirs[i];
    CHECK(differ == 0);

    // A film with values across [0, 1.2] (clamped above 1): our preview decodes to OpenImageIO's.
    Film film(FilmWindow::full(13, 11));
    for (int y = 0; y < 11; ++y)
        for (int x = 0; x < 13; ++x)
            film.addSample(x, y, Rgb(float(x) / 10.f, float(y) / 9.f, std::fabs(testValue(0, size_t(x * 11 + y)))));
    const std::string ours = testDir() + "/preview.png", old = testDir() + "/preview-oiio.png";
    writePreviewPng(ours, film, 1.5f);
    std::vector<float> tone(size_t(13 * 11 * 3));
    for (int y = 0; y < 11; ++y)
        for (int x = 0; x < 13; ++x)
            for (int c = 0; c < 3; ++c) {  // the tone curve of writePreviewPng (clamp, sRGB OETF)
                const double v = std::min(1.0, std::max(0.0, film.mean(x, y)[c] * 1.5));
                tone[size_t((y * 13 + x) * 3 + c)] = float(v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055);
            }
    {
        auto out = OIIO::ImageOutput::create(old);
        REQUIRE(out);
        REQUIRE(out->open(old, OIIO::ImageSpec(13, 11, 3, OIIO::TypeDesc::UINT8)));
        REQUIRE(out->write_image(OIIO::TypeDesc::FLOAT, tone.data()));
        REQUIRE(out->close());
    }
    int w = 0, h = 0, comp = 0, w2 = 0, h2 = 0, comp2 = 0;
    std::unique_ptr<unsigned char, void (*)(void*)> a(stbi_load(ours.c_str(), &w, &h, &comp, 0), stbi_image_free);
    std::unique_ptr<unsigned char, void (*)(void*)> b(stbi_load(old.c_str(), &w2, &h2, &comp2, 0), stbi_image_free);
    REQUIRE(a);
    REQUIRE(b);
    REQUIRE(w == 13);
    REQUIRE(h == 11);
    REQUIRE(comp == 3);
    REQUIRE((w2 == w && h2 == h && comp2 == comp));
    CHECK(std::memcmp(a.get(), b.get(), size_t(w * h * comp)) == 0);
    for (size_t i = 0; i < tone.size(); ++i) {
        INFO("byte " << i);
        REQUIRE(a.get()[i] == unitToByte(tone[i]));
    }
    CHECK(a.get()[0] == 0);                      // black pixel (0, 0)
    CHECK(a.get()[(10 * 13 + 12) * 3 + 1] == 255);  // clamped
}

TEST_CASE("CLI: EXR commands load no OpenImageIO, other formats need the module and say so", "[image-io][cli]") {
    const std::string dir = testDir(), a = dir + "/cli-a.exr", b = dir + "/cli-b.exr", pfm = dir + "/cli.pfm";
    const std::string base = "render " + sourcePath("scenes/cornell-box.gltf") + " --width 8 --height 8 --max-depth 2 -q --no-preview";
    REQUIRE(runCli(base + " -o " + a + " --sample-range 0:2") == 0);
    REQUIRE(runCli(base + " -o " + b + " --sample-range 2:4") == 0);
    for (const std::string& args : {std::string("--version"), "compare " + a + " " + b, "merge -q " + a + " " + b + " -o " + dir + "/m.exr"}) {
        std::string out;
        INFO(args);
        runCli(args, &out);  // compare exits 0 or 1 (noise), that is not the point here
        // LD_DEBUG=files names every library the loader opens.
        std::string trace;
        const std::string cmd = "LD_DEBUG=files " + std::string(bdptref::test::bdptrefBinary()) + " " + args + " 2>&1 >/dev/null";
        FILE* p = ::popen(cmd.c_str(), "r");
        REQUIRE(p);
        char buf[4096];
        size_t k;
        while ((k = std::fread(buf, 1, sizeof buf, p)) > 0) trace.append(buf, k);
        ::pclose(p);
        CHECK(trace.find("libembree3") != std::string::npos);  // the trace is real
        CHECK(trace.find("OpenImageIO") == std::string::npos);
        CHECK(trace.find("bdptref_oiio") == std::string::npos);
    }
    // A float PFM (compare refuses 8-bit PNGs, docs/compare.md): read through the module.
    {
        std::ofstream f(pfm, std::ios::binary);
        f << "PF\n8 8\n-1.0\n";
        const std::vector<float> px(8 * 8 * 3, 0.5f);
        f.write(reinterpret_cast<const char*>(px.data()), std::streamsize(px.size() * sizeof(float)));
        REQUIRE(f.good());
    }
    std::string out;
    CHECK(runCli("compare --metrics-only " + pfm + " " + a, &out) == 0);  // through the module: read and compared
    INFO(out);
    CHECK(out.find("libbdptref_oiio") == std::string::npos);

    // The module missing (BDPTREF_IMAGE_MODULE names the only place to look): exit 2, saying what.
    const std::string cmd = "BDPTREF_IMAGE_MODULE=" + dir + "/nowhere/libbdptref_oiio.so " + std::string(bdptref::test::bdptrefBinary()) +
                            " compare --metrics-only " + pfm + " " + a + " 2>&1";
    FILE* p = ::popen(cmd.c_str(), "r");
    REQUIRE(p);
    std::string err;
    char buf[4096];
    size_t k;
    while ((k = std::fread(buf, 1, sizeof buf, p)) > 0) err.append(buf, k);
    const int status = ::pclose(p);
    INFO(err);
    CHECK(WIFEXITED(status));
    CHECK(WEXITSTATUS(status) == 2);
    CHECK(err.find(pfm + ": reading formats other than EXR and Radiance .hdr needs libbdptref_oiio.so") != std::string::npos);
    CHECK(err.find(dir + "/nowhere/libbdptref_oiio.so: ") != std::string::npos);
    // An EXR still reads without it.
    const std::string cmd2 = "BDPTREF_IMAGE_MODULE=" + dir + "/nowhere/libbdptref_oiio.so " + std::string(bdptref::test::bdptrefBinary()) +
                             " merge -q " + a + " " + b + " -o " + dir + "/m2.exr";
    CHECK(std::system(cmd2.c_str()) == 0);
}
