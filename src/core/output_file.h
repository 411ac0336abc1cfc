// Durable output files (docs/exr.md, "How files are written"). Every file bdptref writes (EXR,
// checkpoint, PNG, JSON) goes through writeOutputBytes, so that:
//   - a regular target (or a new one) is replaced atomically: the bytes go to `.NAME.tmp-PID.EXT`
//     in the target's folder, every write and the close are checked, the temp file is fsync'ed,
//     renamed over the target and the folder fsync'ed. On any failure the temp file is removed,
//     the previous target is untouched and InputError names the file and the reason ("No space
//     left on device").
//   - a symlink is followed: its target is replaced, the link stays a link.
//   - a non-regular target (character device, FIFO) is never renamed over (as root that would
//     replace /dev/null by a file): it is opened for writing without O_CREAT/O_TRUNC and the
//     bytes are written into it. A folder is an InputError.
//   - temp files left by a killed run (`.NAME.tmp-PID.*` whose process is gone) are removed.
// The writers produce their bytes in memory first (OpenEXR through an Imf::OStream, PNGs through
// stb_image_write's callback), so an error can never hide inside a library that does not report it.
#pragma once

#include <string>
#include <vector>

namespace bdptref {

void writeOutputBytes(const std::string& path, const void* data, size_t size);
inline void writeOutputText(const std::string& path, const std::string& text) {
    writeOutputBytes(path, text.data(), text.size());
}

// The temp-file name writeOutputBytes uses for `path` in this process: `.NAME.tmp-PID<suffix>`.
std::string outputTempPath(const std::string& path, const std::string& suffix);
// Removes `.NAME.tmp-PID.*` next to `path` whose process no longer exists. Never throws.
void removeStaleTemps(const std::string& path);

// Fails early (before a long render) if `path` cannot be written: a folder, a missing folder, no
// permission. Also removes stale temp files of `path`. Throws InputError.
void checkOutputWritable(const std::string& path);

// The outputs of one command, by option name; `extension` (e.g. ".exr"), if not empty, is the
// ending the name must have, because that is the format written. An empty path = not requested.
struct NamedOutput {
    std::string option, path, extension;
};
// Before anything is computed: every output must be writable, have its extension, and no two may
// name the same file (same canonical path, or the same existing inode through a link); a device
// node or FIFO may be shared and needs no extension (writing `/dev/null` twice loses nothing).
// Throws InputError naming the options.
void checkOutputs(const std::vector<NamedOutput>& outputs);
void checkDistinctOutputs(const std::vector<NamedOutput>& outputs);
// Throws InputError with a hint unless `path` ends in `ext` (case-insensitive) or is an existing
// device node or FIFO.
void requireExtension(const std::string& path, const std::string& ext, const std::string& option);

}  // namespace bdptref
