#include "scene/gltf_input_checks.h"

#include "bdptref/errors.h"

#include <tiny_gltf.h>

#include <cerrno>
#include <cstring>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace bdptref::gltf {
namespace {

std::string typeProblem(const struct stat& st) {
    if (S_ISDIR(st.st_mode)) return "is a directory, not a file";
    if (!S_ISREG(st.st_mode)) return "is not a regular file (a FIFO, device or socket)";
    return "";
}

std::string sizeProblem(uint64_t size, uint64_t maxBytes) {
    if (size <= maxBytes) return "";
    return "is " + std::to_string(size) + " bytes, more than the limit of " + std::to_string(maxBytes);
}

std::string openProblem(int err) {
    if (err == ENOENT || err == ENOTDIR) return "does not exist";
    if (err == EACCES || err == EPERM) return "cannot be read (permission denied)";
    return std::string("cannot be opened (") + std::strerror(err) + ")";
}

uint32_t be32(const unsigned char* p) { return uint32_t(p[0]) << 24 | uint32_t(p[1]) << 16 | uint32_t(p[2]) << 8 | p[3]; }
uint32_t be16(const unsigned char* p) { return uint32_t(p[0]) << 8 | p[1]; }

std::string limitProblem(const ImageHeader& h) {
    const std::string claims = std::string(h.format) + " header claims " + std::to_string(h.width) + " x " +
                               std::to_string(h.height) + " pixels";
    if (h.width <= 0 || h.height <= 0) return claims + " (an empty image)";
    if (h.width > kMaxImageSide || h.height > kMaxImageSide)
        return claims + "; the limit is " + std::to_string(kMaxImageSide) + " per side";
    if (uint64_t(h.width) * uint64_t(h.height) > kMaxImageTexels)
        return claims + "; the limit is " + std::to_string(kMaxImageTexels) + " texels per image";
    return "";
}

// PNG: the IHDR, then every chunk must lie within the data up to IEND. Deflate cannot compress
// better than about 1032:1, so pixel data that small for the claimed size is truncated or forged.
std::string pngProblem(const unsigned char* b, size_t n, ImageHeader* h) {
    if (n < 33 || be32(b + 8) != 13 || std::memcmp(b + 12, "IHDR", 4) != 0) return "truncated PNG (no IHDR header)";
    if (be32(b + 16) > uint32_t(INT32_MAX) || be32(b + 20) > uint32_t(INT32_MAX)) return "corrupt PNG header (size out of range)";
    h->width = int(be32(b + 16));
    h->height = int(be32(b + 20));
    if (std::string p = limitProblem(*h); !p.empty()) return p;
    const int depth = b[24], colour = b[25];
    const int channels = colour == 0 ? 1 : colour == 2 ? 3 : colour == 3 ? 1 : colour == 4 ? 2 : colour == 6 ? 4 : 0;
    if (channels == 0 || !(depth == 1 || depth == 2 || depth == 4 || depth == 8 || depth == 16))
        return "corrupt PNG header (colour type " + std::to_string(colour) + ", bit depth " + std::to_string(depth) + ")";
    uint64_t idat = 0;
    size_t pos = 8;
    for (;;) {
        if (n - pos < 12) return "truncated PNG (it ends before its IEND chunk)";
        const uint64_t len = be32(b + pos);
        if (len > n - pos - 12) return "truncated PNG (a chunk runs past the end of the data)";
        if (std::memcmp(b + pos + 4, "IDAT", 4) == 0) idat += len;
        if (std::memcmp(b + pos + 4, "IEND", 4) == 0) break;
        pos += size_t(len) + 12;
    }
    const uint64_t rawBytes = uint64_t(h->width) * uint64_t(h->height) * uint64_t(channels * depth) / 8;
    if (idat * 1100 + 1024 < rawBytes)
        return "truncated or corrupt PNG (" + std::to_string(idat) + " bytes of pixel data cannot hold " + std::to_string(h->width) +
               " x " + std::to_string(h->height) + " pixels)";
    return "";
}

// JPEG: walk the marker segments to the frame header (SOFn) and the first scan (SOS). The
// entropy-coded data cannot contain FF D9 (FF is stuffed as FF 00), so its absence after the
// scan means the file was cut; every 8x8 block costs at least one bit (its DC code).
std::string jpegProblem(const unsigned char* b, size_t n, ImageHeader* h) {
    size_t pos = 2;
    bool haveFrame = false;
    for (;;) {
        if (pos >= n || b[pos] != 0xFF) return pos >= n ? "truncated JPEG (it ends before its image data)" : "corrupt JPEG (expected a marker)";
        while (pos < n && b[pos] == 0xFF) ++pos;
        if (pos >= n) return "truncated JPEG (it ends before its image data)";
        const unsigned char m = b[pos++];
        if (m == 0x01 || (m >= 0xD0 && m <= 0xD8)) continue;  // markers without a length
        if (m == 0xD9) return "corrupt JPEG (end of image before any image data)";
        if (n - pos < 2) return "truncated JPEG (it ends inside a marker segment)";
        const size_t len = be16(b + pos);
        if (len < 2 || len > n - pos) return "truncated JPEG (it ends inside a marker segment)";
        const bool sof = m >= 0xC0 && m <= 0xCF && m != 0xC4 && m != 0xC8 && m != 0xCC;
        if (sof && !haveFrame) {
            if (len < 8) return "corrupt JPEG (short frame header)";
            h->height = int(be16(b + pos + 3));
            h->width = int(be16(b + pos + 5));
            haveFrame = true;
            if (std::string p = limitProblem(*h); !p.empty()) return p;
        }
        pos += len;
        if (m == 0xDA) break;
    }
    if (!haveFrame) return "corrupt JPEG (no frame header before the image data)";
    bool end = false;
    for (size_t i = pos; i + 1 < n && !end; ++i) end = b[i] == 0xFF && b[i + 1] == 0xD9;
    if (!end) return "truncated JPEG (no end-of-image marker after the image data)";
    // At least one bit per 16x16 block (a DC code per block of the fully sampled component).
    const uint64_t blocks = uint64_t((h->width + 15) / 16) * uint64_t((h->height + 15) / 16);
    if (uint64_t(n - pos) * 8 < blocks)
        return "truncated or corrupt JPEG (" + std::to_string(n - pos) + " bytes of image data cannot hold " +
               std::to_string(h->width) + " x " + std::to_string(h->height) + " pixels)";
    return "";
}

}  // namespace

std::string regularFileProblem(const std::string& path, uint64_t maxBytes, uint64_t* size) {
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0) return openProblem(errno);
    if (std::string p = typeProblem(st); !p.empty()) return p;
    if (std::string p = sizeProblem(uint64_t(st.st_size), maxBytes); !p.empty()) return p;
    const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) return openProblem(errno);
    ::close(fd);
    if (size) *size = uint64_t(st.st_size);
    return "";
}

std::string readRegularFile(const std::string& path, uint64_t maxBytes, std::vector<unsigned char>* out) {
    out->clear();
    // stat first: opening a device node can have effects of its own.
    if (std::string p = regularFileProblem(path, maxBytes, nullptr); !p.empty()) return p;
    const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) return openProblem(errno);
    struct stat st {};
    std::string problem;
    if (::fstat(fd, &st) != 0) problem = openProblem(errno);
    if (problem.empty()) problem = typeProblem(st);
    if (problem.empty()) problem = sizeProblem(uint64_t(st.st_size), maxBytes);
    if (problem.empty()) {
        out->resize(size_t(st.st_size));
        size_t got = 0;
        while (got < out->size()) {
            const ssize_t r = ::read(fd, out->data() + got, out->size() - got);
            if (r < 0 && errno == EINTR) continue;
            if (r < 0) {
                problem = std::string("read error (") + std::strerror(errno) + ")";
                break;
            }
            if (r == 0) {
                problem = "shrank while it was read";
                break;
            }
            got += size_t(r);
        }
    }
    ::close(fd);
    if (!problem.empty()) out->clear();
    return problem;
}

std::string imageProblem(const unsigned char* bytes, size_t size, ImageHeader* header) {
    *header = ImageHeader{};
    static const unsigned char kPng[8] = {0x89, 'P', 'N', 'G', 0x0D, 0x0A, 0x1A, 0x0A};
    if (size >= 8 && std::memcmp(bytes, kPng, 8) == 0) {
        header->format = "PNG";
        return pngProblem(bytes, size, header);
    }
    if (size >= 3 && bytes[0] == 0xFF && bytes[1] == 0xD8 && bytes[2] == 0xFF) {
        header->format = "JPEG";
        return jpegProblem(bytes, size, header);
    }
    if (size == 0) return "no image data";
    return "not a PNG or JPEG image (the only image formats of glTF 2.0)";
}

uint64_t dataUriMaxBytes(const std::string& uri) {
    const size_t comma = uri.find(',');
    if (comma == std::string::npos) return 0;
    return (uint64_t(uri.size() - comma - 1) + 3) / 4 * 3;
}

std::string percentDecode(const std::string& uri) {
    auto hex = [](unsigned char c) -> unsigned {
        if (c >= '0' && c <= '9') return c - '0';
        if (c >= 'a' && c <= 'f') return c - 'a' + 10u;
        if (c >= 'A' && c <= 'F') return c - 'A' + 10u;
        return 0;
    };
    std::string out;
    for (size_t i = 0; i < uri.size(); ++i) {
        if (uri[i] == '+') {
            out += ' ';
        } else if (uri[i] == '%' && uri.size() > i + 2) {
            out += char((hex((unsigned char)uri[i + 1]) << 4) | hex((unsigned char)uri[i + 2]));
            i += 2;
        } else {
            out += uri[i];
        }
    }
    return out;
}

// Every buffer and image the file names by `uri` is checked here, before tinygltf reads it: an
// external file must be a readable regular file of plausible size (tinygltf would ask a directory
// for its size and allocate 2^63 bytes), a data: URI must hold the bytes it declares.
std::vector<std::string> checkExternalFiles(const nlohmann::json& root, const std::string& baseDir, const std::string& scenePath) {
    auto fail = [&](const std::string& what) { throw InputError(scenePath + ": " + what); };
    std::vector<std::string> labels;
    auto resolve = [&](const std::string& uri) {
        const std::string file = percentDecode(uri);
        return baseDir.empty() ? file : baseDir + "/" + file;
    };
    auto declaredLength = [](const nlohmann::json& o) -> uint64_t {
        const auto it = o.find("byteLength");
        return it != o.end() && it->is_number_unsigned() ? it->get<uint64_t>() : 0;
    };
    const auto buffers = root.find("buffers");
    if (buffers != root.end() && buffers->is_array())
        for (size_t i = 0; i < buffers->size(); ++i) {
            const nlohmann::json& b = (*buffers)[i];
            if (!b.is_object() || !b.contains("uri") || !b["uri"].is_string()) continue;
            const std::string uri = b["uri"].get<std::string>();
            const uint64_t length = declaredLength(b);
            const std::string who = "buffer " + std::to_string(i);
            if (tinygltf::IsDataURI(uri)) {
                if (length > dataUriMaxBytes(uri))
                    fail(who + ": byteLength " + std::to_string(length) + " is larger than its data: URI, which holds at most " +
                         std::to_string(dataUriMaxBytes(uri)) + " bytes");
                continue;
            }
            const std::string file = resolve(uri);
            uint64_t size = 0;
            if (const std::string p = regularFileProblem(file, kMaxBufferFileBytes, &size); !p.empty())
                fail(who + " ('" + uri + "'): '" + file + "' " + p);
            if (size != length)
                fail(who + " ('" + uri + "'): '" + file + "' is " + std::to_string(size) + " bytes, but the buffer's byteLength is " +
                     std::to_string(length) + " (they must be equal)");
        }
    const auto images = root.find("images");
    if (images == root.end() || !images->is_array()) return labels;
    for (size_t i = 0; i < images->size(); ++i) {
        const nlohmann::json& im = (*images)[i];
        std::string label = "image " + std::to_string(i);
        const std::string uri = im.is_object() && im.contains("uri") && im["uri"].is_string() ? im["uri"].get<std::string>() : "";
        const bool external = !uri.empty() && !tinygltf::IsDataURI(uri);
        if (external) label += " ('" + uri + "')";
        if (im.is_object() && im.contains("name") && im["name"].is_string()) label += " named '" + im["name"].get<std::string>() + "'";
        labels.push_back(label);
        if (!external) continue;
        const std::string file = resolve(uri);
        if (const std::string p = regularFileProblem(file, kMaxImageFileBytes, nullptr); !p.empty())
            fail(label + ": '" + file + "' " + p);
    }
    return labels;
}

}  // namespace bdptref::gltf
