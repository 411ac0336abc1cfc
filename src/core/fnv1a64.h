// FNV-1a, 64 bit: the content hash of a scene (SceneInfo::contentHash) over the bytes of every
// file it was made from. Not cryptographic: it tells "the same input" from "another input" in
// headers, checkpoints and path dumps.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

namespace bdptref {

struct Fnv1a64 {
    uint64_t h = 14695981039346656037ull;
    void add(const unsigned char* p, size_t n) {
        for (size_t i = 0; i < n; ++i) {
            h ^= uint64_t(p[i]);
            h *= 1099511628211ull;
        }
    }
    void add(const std::string& s) { add(reinterpret_cast<const unsigned char*>(s.data()), s.size()); }
    std::string hex() const {
        char buf[17];
        std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
        return std::string(buf);
    }
};

}  // namespace bdptref
