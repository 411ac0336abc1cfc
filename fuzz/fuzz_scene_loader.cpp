// libFuzzer target: scene loading (glTF JSON or GLB bytes) followed by Scene::finalize. Every
// input must either load or throw bdptref::InputError; anything else (a crash, an ASan/UBSan
// report, another exception type, a hang) is a bug. See docs/errors.md ("Fuzzing").
#include "bdptref/errors.h"
#include "bdptref/gltf_loader.h"

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

#include <unistd.h>

namespace {

// The loader reads files (external buffers and images are resolved relative to the file), so
// the input is written to a per-process file; GLB by its magic, JSON otherwise.
std::string inputPath(bool glb) {
    static const std::string base = "/tmp/bdptref-fuzz-" + std::to_string(::getpid());
    return base + (glb ? ".glb" : ".gltf");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const bool glb = size >= 4 && data[0] == 'g' && data[1] == 'l' && data[2] == 'T' && data[3] == 'F';
    const std::string path = inputPath(glb);
    FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) return 0;
    if (size) std::fwrite(data, 1, size, f);
    std::fclose(f);
    try {
        bdptref::LoadOptions o;
        o.width = 8;
        o.height = 8;
        bdptref::Scene s = bdptref::loadGltfScene(path, o);
        s.finalize();
    } catch (const bdptref::InputError&) {
        // the expected outcome for malformed input
    }
    return 0;
}
