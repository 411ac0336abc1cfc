// Checks on the bytes the glTF loader reads besides the JSON itself: the scene file, every file an
// external `uri` names, and image headers. They run BEFORE anything is read or decoded, so a
// directory, a FIFO, a device or an image whose header claims 16383 x 16383 pixels is refused with
// a message instead of a hang, a 5 GB allocation or garbage texels. Limits: docs/scenes.md, "Limits".
#pragma once

#include <nlohmann/json.hpp>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace bdptref::gltf {

constexpr uint64_t kMaxSceneFileBytes = (uint64_t(1) << 32) - 1;   // the GLB length field is 32 bit
constexpr uint64_t kMaxBufferFileBytes = (uint64_t(1) << 32) - 1;  // same as a GLB BIN chunk
constexpr uint64_t kMaxImageFileBytes = uint64_t(256) << 20;       // stb_image takes an int size
constexpr int kMaxImageSide = 16384;
// Texels are stored as float RGBA (16 bytes), so these bound texture memory at 1 GiB per image and
// 2 GiB per scene (twice that for an image used both as colour and as data).
constexpr uint64_t kMaxImageTexels = uint64_t(1) << 26;
constexpr uint64_t kMaxSceneTexels = uint64_t(1) << 27;

// Checks every buffer and image `uri` of the raw glTF JSON before tinygltf reads anything: an
// external file must be a readable regular file (buffers: of exactly byteLength bytes), a data:
// URI must hold its byteLength. Throws InputError naming scenePath and the object; returns a label
// per image ("image 2 ('wood.png') named 'oak'") for later messages.
std::vector<std::string> checkExternalFiles(const nlohmann::json& root, const std::string& baseDir, const std::string& scenePath);

// "" when `path` is a readable regular file of at most maxBytes bytes (its size in *size),
// otherwise the problem ("is a directory, not a file", "does not exist", ...). Never blocks.
std::string regularFileProblem(const std::string& path, uint64_t maxBytes, uint64_t* size);

// Reads a whole regular file (opened non-blocking and checked with fstat on the same descriptor,
// so a FIFO or device swapped in after a check cannot hang or flood the reader). "" on success.
std::string readRegularFile(const std::string& path, uint64_t maxBytes, std::vector<unsigned char>* out);

struct ImageHeader {
    const char* format = "";  // "PNG" or "JPEG"
    int width = 0, height = 0;
};

// Reads the header of a PNG or JPEG (the only image formats of glTF 2.0) without decoding it and
// checks it against the limits above and for truncation (a JPEG without its end-of-image marker;
// fewer bytes than the smallest possible encoding of the claimed size). "" when acceptable.
std::string imageProblem(const unsigned char* bytes, size_t size, ImageHeader* header);

// An upper bound of the bytes a base64 data: URI decodes to (0 when it has no payload).
uint64_t dataUriMaxBytes(const std::string& uri);
// %XX and '+' decoding, exactly as tinygltf applies it to an external URI before opening it.
std::string percentDecode(const std::string& uri);

}  // namespace bdptref::gltf
