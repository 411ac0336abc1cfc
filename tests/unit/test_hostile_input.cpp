// Hostile input (issue 12, "no silent wrong image, bounded memory"): each defect that was found by
// hand or by the fuzzer is reproduced here through the real binary (exit 2, a message naming the
// file and the problem, nothing written) or through the library where the picture itself is the
// point. Everything is tiny: the forged images claim gigabytes in a few dozen bytes, and the test
// passes only because the loader refuses them from the header, before anything is allocated.
// Docs: docs/scenes.md ("Limits"), docs/lights.md ("Limits"), docs/errors.md.
#include "bdptref/errors.h"
#include "bdptref/gltf_loader.h"
#include "support/gltf_builder.h"
#include "support/render_util.h"

#include <catch2/catch.hpp>

#include <sys/stat.h>
#include <sys/sysmacros.h>

#include <filesystem>
#include <string>
#include <vector>

using namespace bdptref;
using namespace bdptref::test;

namespace {

// An 8x8 grey baseline JPEG (oiiotool, quality 50), the same bytes as fuzz/make_hostile_seeds.py.
std::vector<unsigned char> tinyJpeg() {
    static const unsigned char kJpeg[] = {
        0xff, 0xd8, 0xff, 0xe0, 0x00, 0x10, 0x4a, 0x46, 0x49, 0x46, 0x00, 0x01, 0x01, 0x00, 0x00, 0x01, 0x00, 0x01, 0x00, 0x00,
        0xff, 0xdb, 0x00, 0x43, 0x00, 0x10, 0x0b, 0x0c, 0x0e, 0x0c, 0x0a, 0x10, 0x0e, 0x0d, 0x0e, 0x12, 0x11, 0x10, 0x13, 0x18,
        0x28, 0x1a, 0x18, 0x16, 0x16, 0x18, 0x31, 0x23, 0x25, 0x1d, 0x28, 0x3a, 0x33, 0x3d, 0x3c, 0x39, 0x33, 0x38, 0x37, 0x40,
        0x48, 0x5c, 0x4e, 0x40, 0x44, 0x57, 0x45, 0x37, 0x38, 0x50, 0x6d, 0x51, 0x57, 0x5f, 0x62, 0x67, 0x68, 0x67, 0x3e, 0x4d,
        0x71, 0x79, 0x70, 0x64, 0x78, 0x5c, 0x65, 0x67, 0x63, 0xff, 0xc0, 0x00, 0x0b, 0x08, 0x00, 0x08, 0x00, 0x08, 0x01, 0x01,
        0x11, 0x00, 0xff, 0xc4, 0x00, 0x1f, 0x00, 0x00, 0x01, 0x05, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x00, 0x00, 0x00, 0x00,
        0x00, 0x00, 0x00, 0x00, 0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x08, 0x09, 0x0a, 0x0b, 0xff, 0xc4, 0x00, 0xb5, 0x10,
        0x00, 0x02, 0x01, 0x03, 0x03, 0x02, 0x04, 0x03, 0x05, 0x05, 0x04, 0x04, 0x00, 0x00, 0x01, 0x7d, 0x01, 0x02, 0x03, 0x00,
        0x04, 0x11, 0x05, 0x12, 0x21, 0x31, 0x41, 0x06, 0x13, 0x51, 0x61, 0x07, 0x22, 0x71, 0x14, 0x32, 0x81, 0x91, 0xa1, 0x08,
        0x23, 0x42, 0xb1, 0xc1, 0x15, 0x52, 0xd1, 0xf0, 0x24, 0x33, 0x62, 0x72, 0x82, 0x09, 0x0a, 0x16, 0x17, 0x18, 0x19, 0x1a,
        0x25, 0x26, 0x27, 0x28, 0x29, 0x2a, 0x34, 0x35, 0x36, 0x37, 0x38, 0x39, 0x3a, 0x43, 0x44, 0x45, 0x46, 0x47, 0x48, 0x49,
        0x4a, 0x53, 0x54, 0x55, 0x56, 0x57, 0x58, 0x59, 0x5a, 0x63, 0x64, 0x65, 0x66, 0x67, 0x68, 0x69, 0x6a, 0x73, 0x74, 0x75,
        0x76, 0x77, 0x78, 0x79, 0x7a, 0x83, 0x84, 0x85, 0x86, 0x87, 0x88, 0x89, 0x8a, 0x92, 0x93, 0x94, 0x95, 0x96, 0x97, 0x98,
        0x99, 0x9a, 0xa2, 0xa3, 0xa4, 0xa5, 0xa6, 0xa7, 0xa8, 0xa9, 0xaa, 0xb2, 0xb3, 0xb4, 0xb5, 0xb6, 0xb7, 0xb8, 0xb9, 0xba,
        0xc2, 0xc3, 0xc4, 0xc5, 0xc6, 0xc7, 0xc8, 0xc9, 0xca, 0xd2, 0xd3, 0xd4, 0xd5, 0xd6, 0xd7, 0xd8, 0xd9, 0xda, 0xe1, 0xe2,
        0xe3, 0xe4, 0xe5, 0xe6, 0xe7, 0xe8, 0xe9, 0xea, 0xf1, 0xf2, 0xf3, 0xf4, 0xf5, 0xf6, 0xf7, 0xf8, 0xf9, 0xfa, 0xff, 0xda,
        0x00, 0x08, 0x01, 0x01, 0x00, 0x00, 0x3f, 0x00, 0x2b, 0xff, 0xd9};
    return std::vector<unsigned char>(std::begin(kJpeg), std::end(kJpeg));
}

// The 40-byte JPEG of issue 12: SOI, a frame header claiming w x h, a scan header, EOI.
std::vector<unsigned char> jpegClaiming(int w, int h) {
    return {0xff, 0xd8, 0xff, 0xc0, 0x00, 0x0b, 0x08, (unsigned char)(h >> 8), (unsigned char)h, (unsigned char)(w >> 8),
            (unsigned char)w, 0x01, 0x01, 0x11, 0x00, 0xff, 0xda, 0x00, 0x08, 0x01, 0x01, 0x00, 0x00, 0x3f, 0x00,
            0x00, 0x00, 0x00, 0x00, 0xff, 0xd9};
}

// A well-formed 1x1 PNG whose IHDR claims w x h.
std::vector<unsigned char> pngClaiming(uint32_t w, uint32_t h) {
    std::vector<unsigned char> png = makePng(1, 1, 3, 8, {1, 2, 3});
    for (int b = 0; b < 4; ++b) {
        png[size_t(16 + b)] = (unsigned char)(w >> (24 - 8 * b));
        png[size_t(20 + b)] = (unsigned char)(h >> (24 - 8 * b));
    }
    const uint32_t crc = crc32(png.data() + 12, 17);
    for (int b = 0; b < 4; ++b) png[size_t(29 + b)] = (unsigned char)(crc >> (24 - 8 * b));
    return png;
}

// A lit triangle (emissive, so it renders) whose material uses texture 0 = the given image.
Doc texturedWith(const json& image) {
    Doc d;
    d.triangleNode();
    d.j["meshes"][0]["primitives"][0]["material"] = d.lambert({0.5, 0.5, 0.5}, {1, 1, 1});
    d.j["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = d.floats({0, 0, 1, 0, 0, 1}, "VEC2");
    d.j["images"] = json::array({image});
    d.j["textures"] = json::array({json{{"source", 0}}});
    d.j["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
    return d;
}

json dataImage(const std::vector<unsigned char>& bytes, const char* mime) {
    return json{{"uri", std::string("data:") + mime + ";base64," + base64(bytes)}};
}

// A grey floor (two triangles) lit by one punctual light 1 above it.
Doc litByLight(const json& light) {
    Doc d;
    const int pos = d.floats({-1, 0, -1, 1, 0, -1, 1, 0, 1, -1, 0, 1}, "VEC3");
    const int idx = d.indices<uint16_t>({0, 2, 1, 0, 3, 2});
    d.node({{"mesh", d.mesh(Doc::prim(pos, idx, -1, -1, 4, d.lambert({0.5, 0.5, 0.5})))}});
    d.use("KHR_lights_punctual");
    d.j["extensions"]["KHR_lights_punctual"]["lights"] = json::array({light});
    d.node({{"translation", {0, 1, 0}}, {"rotation", {-0.7071068, 0, 0, 0.7071068}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
    d.j["cameras"] = json::array({json{{"type", "perspective"}, {"perspective", {{"yfov", 0.9}, {"znear", 0.01}}}}});
    d.node({{"camera", 0}, {"translation", {0, 0.5, 2.5}}});
    return d;
}

std::string renderArgs(const std::string& scene, const std::string& dir, const std::string& extra = "") {
    return "render " + scene + " -o " + dir + "/out.exr --spp 1 --width 8 --height 8 -q " + extra;
}

Scene loadFinalized(const std::string& path) {
    LoadOptions o;
    o.width = 16;
    o.height = 16;
    Scene s = loadGltfScene(path, o);
    s.finalize();
    return s;
}

bool hasWarning(const Scene& s, const std::string& phrase) {
    for (const std::string& w : s.info.warnings)
        if (w.find(phrase) != std::string::npos) return true;
    return false;
}

}  // namespace

TEST_CASE("Hostile input: a directory, FIFO, device or missing file as the scene exits 2 naming it", "[hostile][cli]") {
    const std::string dir = makeTempDir("hostile-scene-path");
    namespace fs = std::filesystem;
    fs::create_directories(dir + "/folder.gltf");
    REQUIRE(::mkfifo((dir + "/pipe.gltf").c_str(), 0600) == 0);
    // A device node of our own (never a system one): a character device with no driver behind it.
    std::string device = dir + "/device.gltf";
    if (::mknod(device.c_str(), S_IFCHR | 0600, makedev(1, 3)) != 0) device = "/dev/zero";  // only stat()ed, never opened
    // Each must answer at once: a blocking open of the FIFO would hang here (CTest's timeout).
    checkInputError(renderArgs(dir + "/folder.gltf", dir), dir + "/folder.gltf: is a directory, not a file");
    checkInputError(renderArgs(dir + "/pipe.gltf", dir), dir + "/pipe.gltf: is not a regular file");
    checkInputError(renderArgs(device, dir), device + ": is not a regular file");
    checkInputError(renderArgs(dir + "/missing.gltf", dir), dir + "/missing.gltf: does not exist");
    checkInputError("info " + dir + "/pipe.gltf", dir + "/pipe.gltf: is not a regular file");
    CHECK_FALSE(fs::exists(dir + "/out.exr"));
    CHECK_FALSE(fs::exists(dir + "/out.png"));
}

TEST_CASE("Hostile input: every external uri must be a regular file of the declared size", "[hostile][cli]") {
    const std::string dir = makeTempDir("hostile-uri");
    Doc base;
    base.triangleNode();
    base.j["meshes"][0]["primitives"][0]["material"] = base.lambert({0.5, 0.5, 0.5}, {1, 1, 1});
    auto withBufferUri = [&](const std::string& uri, size_t byteLength, const std::string& name) {
        json j = base.finished();
        j["buffers"][0] = json{{"byteLength", byteLength}, {"uri", uri}};
        return writeFile(name, j.dump());
    };
    const size_t n = base.bin.size();
    writeFile("buffer.bin", base.bin);
    std::vector<unsigned char> longer = base.bin;
    longer.resize(n + 100);
    writeFile("longer.bin", longer);
    // The ASan abort / std::bad_alloc of issue 12: tinygltf asked the directory for its size.
    const std::string dirUri = withBufferUri(".", n, "buffer-dir.gltf");
    checkInputError(renderArgs(dirUri, dir), "buffer 0 ('.'): '" + tempDir().string() + "/.' is a directory, not a file");
    checkInputError(renderArgs(withBufferUri("longer.bin", n, "buffer-longer.gltf"), dir),
                    "longer.bin' is " + std::to_string(n + 100) + " bytes, but the buffer's byteLength is " + std::to_string(n));
    checkInputError(renderArgs(withBufferUri("buffer.bin", n + 8, "buffer-short.gltf"), dir),
                    "buffer.bin' is " + std::to_string(n) + " bytes, but the buffer's byteLength is " + std::to_string(n + 8));
    checkInputError(renderArgs(withBufferUri("data:application/octet-stream;base64,AAAA", size_t(1) << 50, "buffer-data.gltf"), dir),
                    "buffer 0: byteLength 1125899906842624 is larger than its data: URI, which holds at most 3 bytes");
    checkInputError(renderArgs(texturedWith(json{{"uri", "."}}).write("image-dir.gltf"), dir), "image 0 ('.'): '");
    checkInputError(renderArgs(texturedWith(json{{"uri", "."}}).write("image-dir.gltf"), dir), "/.' is a directory, not a file");
    // The same file, correctly sized, loads (the checks do not refuse valid scenes).
    CHECK(loadFinalized(withBufferUri("buffer.bin", n, "buffer-ok.gltf")).mesh.triangleCount() == 1);
    CHECK_FALSE(std::filesystem::exists(dir + "/out.exr"));
}

TEST_CASE("Hostile input: image headers are checked before decoding, for PNG and JPEG", "[hostile][cli]") {
    const std::string dir = makeTempDir("hostile-image");
    // Issue 12: 31 bytes claiming 16383 x 16383 made the loader allocate 5.4 GB. Refused from the
    // header, so this test's memory stays small (CTest would report an out-of-memory kill).
    const std::string jpeg = texturedWith(dataImage(jpegClaiming(16383, 16383), "image/jpeg")).write("huge-jpeg.gltf");
    checkInputError(renderArgs(jpeg, dir), "image 0: JPEG header claims 16383 x 16383 pixels; the limit is 67108864 texels per image");
    checkInputError(renderArgs(jpeg, dir), "huge-jpeg.gltf");
    const std::string wide = texturedWith(dataImage(jpegClaiming(20000, 2), "image/jpeg")).write("wide-jpeg.gltf");
    checkInputError(renderArgs(wide, dir), "JPEG header claims 20000 x 2 pixels; the limit is 16384 per side");
    // Within the caps but far more pixels than the bytes can encode: a forged or cut file.
    const std::string small = texturedWith(dataImage(jpegClaiming(4096, 4096), "image/jpeg")).write("forged-jpeg.gltf");
    checkInputError(renderArgs(small, dir), "truncated or corrupt JPEG");
    const std::string png = texturedWith(dataImage(pngClaiming(16383, 16383), "image/png")).write("huge-png.gltf");
    checkInputError(renderArgs(png, dir), "image 0: PNG header claims 16383 x 16383 pixels");
    const std::string png2 = texturedWith(dataImage(pngClaiming(2048, 2048), "image/png")).write("forged-png.gltf");
    checkInputError(renderArgs(png2, dir), "truncated or corrupt PNG");
    // A JPEG cut before its end-of-image marker: stb_image would decode it as garbage.
    std::vector<unsigned char> cut = tinyJpeg();
    cut.resize(cut.size() - 2);
    const std::string cutPath = texturedWith(dataImage(cut, "image/jpeg")).write("cut-jpeg.gltf");
    checkInputError(renderArgs(cutPath, dir), "image 0: truncated JPEG (no end-of-image marker after the image data)");
    // An external truncated PNG is named by its file.
    std::vector<unsigned char> half = makePng(4, 4, 3, 8, std::vector<uint16_t>(48, 128));
    half.resize(half.size() / 2);
    writeFile("half.png", half);
    checkInputError(renderArgs(texturedWith(json{{"uri", "half.png"}}).write("half-png.gltf"), dir), "image 0 ('half.png'): truncated PNG");
    // Not PNG or JPEG (stb_image would accept a BMP that glTF does not allow).
    std::vector<unsigned char> bmp(62, 0);
    bmp[0] = 'B';
    bmp[1] = 'M';
    checkInputError(renderArgs(texturedWith(dataImage(bmp, "image/bmp")).write("bmp.gltf"), dir), "image 0: not a PNG or JPEG image");
    CHECK_FALSE(std::filesystem::exists(dir + "/out.exr"));

    // The intact JPEG and a PNG load and decode to the right size.
    const Scene ok = loadFinalized(texturedWith(dataImage(tinyJpeg(), "image/jpeg")).write("ok-jpeg.gltf"));
    REQUIRE(ok.textures.size() == 1);
    CHECK(ok.textures[0].width == 8);
    CHECK(ok.textures[0].height == 8);
    const Scene okPng = loadFinalized(texturedWith(dataImage(makePng(3, 2, 3, 8, std::vector<uint16_t>(18, 7)), "image/png")).write("ok-png.gltf"));
    REQUIRE(okPng.textures.size() == 1);
    CHECK(okPng.textures[0].width == 3);
}

TEST_CASE("Hostile input: a light beyond single precision is refused, never rendered black", "[hostile][cli][lights]") {
    const std::string dir = makeTempDir("hostile-light");
    // Issue 12: intensity 3e37 made the light's power overflow float; it vanished from the image
    // with exit 0 (all black with --integrator lt).
    for (const char* type : {"point", "directional", "spot"}) {
        json light = {{"type", type}, {"intensity", 3e37}};
        if (std::string(type) == "spot") light["spot"] = {{"innerConeAngle", 0.1}, {"outerConeAngle", 0.5}};
        const std::string path = litByLight(light).write(std::string("light-3e37-") + type + ".gltf");
        INFO(type);
        for (const char* integrator : {"bdpt", "lt", "path"})
            checkInputError(renderArgs(path, dir, std::string("--integrator ") + integrator),
                            "KHR_lights_punctual light 0: " + std::string(std::string(type) == "directional" ? "irradiance" : "intensity") +
                                " 3e+37 exceeds the renderer's limit of 1e25");
    }
    // A constant environment is a light too.
    checkInputError(renderArgs(litByLight({{"type", "point"}, {"intensity", 1}}).write("env.gltf"), dir, "--env 1e30,1e30,1e30"),
                    "the environment (--env): radiance 1e+30 exceeds the renderer's limit of 1e25");
    // Power in double: 5e24 is allowed per light, but two of them exceed the total.
    Doc two = litByLight({{"type", "point"}, {"intensity", 5e23}});
    two.j["extensions"]["KHR_lights_punctual"]["lights"].push_back({{"type", "point"}, {"intensity", 5e24}});
    two.node({{"translation", {0.3, 1, 0}}, {"extensions", {{"KHR_lights_punctual", {{"light", 1}}}}}});
    checkInputError(renderArgs(two.write("two-lights.gltf"), dir), "light 1: the lights' total power");
    // A light that could never be selected (its probability underflows float) next to a normal one.
    Doc faint = litByLight({{"type", "point"}, {"intensity", 1e6}});
    faint.j["extensions"]["KHR_lights_punctual"]["lights"].push_back({{"type", "point"}, {"intensity", 1e-33}});
    faint.node({{"translation", {0.3, 1, 0}}, {"extensions", {{"KHR_lights_punctual", {{"light", 1}}}}}});
    checkInputError(renderArgs(faint.write("faint-light.gltf"), dir), "KHR_lights_punctual light 1: its power");
    checkInputError(renderArgs(faint.write("faint-light.gltf"), dir), "would be missing from the image");
    // A denormal intensity: render threads run flush-to-zero, so it would be 0.
    checkInputError(renderArgs(litByLight({{"type", "point"}, {"intensity", 1e-40}}).write("denormal-light.gltf"), dir),
                    "KHR_lights_punctual light 0: emission 9.99995e-41 is below the smallest normal float");
    CHECK_FALSE(std::filesystem::exists(dir + "/out.exr"));
}

TEST_CASE("Hostile input: a bright light within the limit renders the scaled image exactly", "[hostile][lights]") {
    // The same scene at intensity 1 and 1e23 (power 1.3e24, near the limit): with the same random
    // numbers every estimate scales by exactly 1e23 up to float rounding (relative 1e-5 is ~100
    // float ulps of headroom).
    const Scene dim = loadFinalized(litByLight({{"type", "point"}, {"intensity", 1.0}}).write("dim.gltf"));
    const Scene bright = loadFinalized(litByLight({{"type", "point"}, {"intensity", 1e23}}).write("bright.gltf"));
    for (const char* integrator : {"lt", "bdpt"}) {
        INFO(integrator);
        const PooledMean a = pooledMean(renderFilm(dim, integrator, 4, 5, 7, 1));
        const PooledMean b = pooledMean(renderFilm(bright, integrator, 4, 5, 7, 1));
        REQUIRE(a.mean.x > 0.0);
        CHECK(b.mean.x == Approx(a.mean.x * 1e23).epsilon(1e-5));
        CHECK(b.mean.y == Approx(a.mean.y * 1e23).epsilon(1e-5));
    }
}

TEST_CASE("Hostile input: dark lights and unlit scenes warn and say how to light them", "[hostile][lights]") {
    const Scene s = loadFinalized(litByLight({{"type", "point"}, {"intensity", 0.0}}).write("dark.gltf"));
    CHECK(hasWarning(s, "KHR_lights_punctual light 0: emits nothing"));
    CHECK(hasWarning(s, "the scene has no lights; the image will be black"));
    CHECK(hasWarning(s, "--env R,G,B"));
    std::string out;
    const std::string dir = makeTempDir("hostile-dark");
    CHECK(runCli(renderArgs(litByLight({{"type", "point"}, {"intensity", 0.0}}).write("dark.gltf"), dir), &out) == 0);
    CHECK(out.find("--env R,G,B") != std::string::npos);
    // With an environment there is a light, and no such warning.
    Scene lit = loadGltfScene(litByLight({{"type", "point"}, {"intensity", 0.0}}).write("dark.gltf"), LoadOptions{});
    lit.setEnvironment(Rgb(1.f));
    lit.finalize();
    CHECK_FALSE(hasWarning(lit, "the scene has no lights"));
}

TEST_CASE("Hostile input: repeated warnings are one line with a count", "[hostile][gltf]") {
    Doc d;
    const auto png = makePng(1, 1, 3, 8, {1, 2, 3});
    d.j["images"] = json::array({dataImage(png, "image/png")});
    d.j["textures"] = json::array({json{{"source", 0}}});
    const int pos = d.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3");
    for (int i = 0; i < 149; ++i) {
        const int m = d.material({{"name", "m" + std::to_string(i)}, {"occlusionTexture", {{"index", 0}}}});
        d.node({{"mesh", d.mesh(Doc::prim(pos, -1, -1, -1, 4, m))}});
    }
    LoadOptions o;
    const Scene s = loadGltfScene(d.write("occlusion-149.gltf"), o);
    size_t lines = 0;
    for (const std::string& w : s.info.warnings)
        if (w.find("occlusionTexture ignored") != std::string::npos) {
            ++lines;
            CHECK(w.find("149 materials: material 0 ('m0'), material 1 ('m1'), material 2 ('m2') and 146 more") != std::string::npos);
        }
    CHECK(lines == 1);
}
