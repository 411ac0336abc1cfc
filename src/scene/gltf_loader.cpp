// glTF 2.0 -> Scene. The contract (docs/scenes.md): everything in the file that would change the
// picture is either implemented exactly or rejected with an InputError that names the file, the
// glTF object and the problem. Things that cannot change the picture become info.warnings.
//
// tinygltf parses the JSON and loads buffers and images; it validates very little of what it
// reads, so every index, size and range is checked here before it is used.


#include "scene/gltf_loader_internal.h"

namespace bdptref {
namespace gltfload {

void Loader::warn(const std::string& who, const std::string& what) {
    for (auto& w : warnings_)
        if (w.first == what) {
            w.second.push_back(who);
            return;
        }
    warnings_.push_back({what, {who}});
}

void Loader::flushWarnings() {
    constexpr size_t kNamed = 3;  // objects named in an aggregated line
    for (const auto& [what, whos] : warnings_) {
        if (whos.size() == 1) {
            scene_.info.warnings.push_back(whos[0].empty() ? what : whos[0] + ": " + what);
            continue;
        }
        // "149 materials" when every object is of one kind ("material 3 ('x')"), else "149 times".
        auto kind = [](const std::string& who) { return who.substr(0, who.find(' ')); };
        bool oneKind = !whos[0].empty();
        for (const std::string& w : whos) oneKind = oneKind && kind(w) == kind(whos[0]);
        std::string line = what + " (" + std::to_string(whos.size()) + (oneKind ? " " + kind(whos[0]) + "s" : " times");
        if (!whos[0].empty()) {
            line += ": ";
            for (size_t i = 0; i < std::min(kNamed, whos.size()); ++i) line += (i ? ", " : "") + whos[i];
            if (whos.size() > kNamed) line += " and " + std::to_string(whos.size() - kNamed) + " more";
        }
        scene_.info.warnings.push_back(line + ")");
    }
    warnings_.clear();
}


void Loader::throwCollectedErrors() const {
    if (errors_.empty()) return;
    if (errors_.size() == 1) fail(errors_[0]);
    // Every problem, one per line, so a file is fixed in one round.
    constexpr size_t kListed = 50;
    std::string msg = std::to_string(errors_.size()) + " problems:";
    for (size_t i = 0; i < std::min(kListed, errors_.size()); ++i) msg += "\n  " + errors_[i];
    if (errors_.size() > kListed) msg += "\n  ... and " + std::to_string(errors_.size() - kListed) + " more";
    fail(msg);
}

Scene Loader::load() {
    if (options_.width < 0 || options_.height < 0)
        fail("invalid image size " + std::to_string(options_.width) + "x" + std::to_string(options_.height));
    scene_.info.path = path_;
    readAndParse();
    scene_.info.contentHash = hash_.hex();
    attempt([&] { checkAsset(); });
    checkExtensions();
    attempt([&] { traverse(); });
    if (degenerateTriangles_)
        warn(std::to_string(degenerateTriangles_) + " degenerate (zero-area) triangles skipped");
    if (zeroNormals_)
        warn(std::to_string(zeroNormals_) +
             " vertices have a zero-length normal; the geometric normal is used there (vertexHasNormal = 0)");
    attempt([&] { resolveCameras(); });
    throwCollectedErrors();
    flushWarnings();
    return std::move(scene_);
}

}  // namespace gltfload


Scene loadGltfScene(const std::string& path, const LoadOptions& options) {
    gltfload::Loader loader(path, options);
    return loader.load();
}

}  // namespace bdptref
