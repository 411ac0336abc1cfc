#include "core/output_file.h"

#include "bdptref/errors.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <climits>
#include <cstring>
#include <filesystem>

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

namespace bdptref {

namespace fs = std::filesystem;

namespace {

[[noreturn]] void fail(const std::string& path, const std::string& what, int err) {
    throw InputError(path + ": " + what + ": " + std::strerror(err));
}

// The file a path finally names: symlinks are followed (a dangling one names the file it would
// create), so the link itself is never replaced.
fs::path resolveLinks(const std::string& path) {
    fs::path cur(path);
    for (int hops = 0; hops < 40; ++hops) {
        std::error_code ec;
        if (!fs::is_symlink(fs::symlink_status(cur, ec))) return cur;
        const fs::path to = fs::read_symlink(cur, ec);
        if (ec) return cur;
        cur = to.is_absolute() ? to : cur.parent_path() / to;
    }
    throw InputError(path + ": too many levels of symbolic links");
}

fs::path folderOf(const fs::path& p) { return p.has_parent_path() ? p.parent_path() : fs::path("."); }

// Writes everything or reports errno (a short write is retried; 0 bytes written = out of space).
int writeAll(int fd, const void* data, size_t size) {
    const char* p = static_cast<const char*>(data);
    while (size > 0) {
        const ssize_t k = ::write(fd, p, std::min<size_t>(size, size_t(1) << 30));
        if (k < 0) {
            if (errno == EINTR) continue;
            return errno;
        }
        if (k == 0) return ENOSPC;
        p += k;
        size -= size_t(k);
    }
    return 0;
}

// A device node or FIFO: the bytes go into it; it is never replaced.
void writeInPlace(const std::string& path, const fs::path& target, const void* data, size_t size) {
    const int fd = ::open(target.c_str(), O_WRONLY | O_CLOEXEC | O_NOCTTY);
    if (fd < 0) fail(path, "cannot open for writing", errno);
    const int err = writeAll(fd, data, size);
    const int closed = ::close(fd) == 0 ? 0 : errno;
    if (err) fail(path, "writing failed", err);
    if (closed) fail(path, "writing failed (on close)", closed);
}

// The folder entry of the rename must reach the disk too, or a crash can bring the old file back.
int syncFolder(const fs::path& dir) {
    const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd < 0) return errno;
    int err = ::fsync(fd) == 0 ? 0 : errno;
    if (err == EINVAL || err == EROFS) err = 0;  // file systems that cannot sync folders
    ::close(fd);
    return err;
}

bool isSpecialFile(const std::string& path) {  // an existing device node, FIFO or socket
    struct stat st;
    return ::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode) && !S_ISDIR(st.st_mode);
}

}  // namespace

std::string outputTempPath(const std::string& path, const std::string& suffix) {
    const fs::path p(path);
    return (folderOf(p) / ("." + p.filename().string() + ".tmp-" + std::to_string(::getpid()) + suffix)).string();
}

void removeStaleTemps(const std::string& path) {
    std::error_code ec;
    const fs::path target = resolveLinks(path);
    const std::string prefix = "." + target.filename().string() + ".tmp-";
    for (fs::directory_iterator it(folderOf(target), ec), end; !ec && it != end; it.increment(ec)) {
        const std::string name = it->path().filename().string();
        if (name.compare(0, prefix.size(), prefix) != 0) continue;
        size_t k = prefix.size();
        long long pid = 0;
        while (k < name.size() && std::isdigit(static_cast<unsigned char>(name[k])) && pid <= INT_MAX) pid = pid * 10 + (name[k++] - '0');
        if (k == prefix.size() || (k < name.size() && name[k] != '.')) continue;  // not one of ours
        std::error_code sec;
        if (!fs::is_regular_file(it->symlink_status(sec))) continue;
        // A PID that cannot exist or whose process is gone: a run killed mid-write left it.
        const bool dead = pid > INT_MAX || pid == 0 || (::kill(pid_t(pid), 0) != 0 && errno == ESRCH);
        if (dead && pid != ::getpid()) fs::remove(it->path(), sec);
    }
}

void writeOutputBytes(const std::string& path, const void* data, size_t size) {
    if (path.empty()) throw InputError("no output file given");
    // stat() follows links the way the kernel does (also /dev/stdout -> /proc/self/fd/1 -> a pipe).
    struct stat st;
    const bool exists = ::stat(path.c_str(), &st) == 0;
    if (exists && S_ISDIR(st.st_mode)) throw InputError(path + ": is a directory, not a file");
    if (exists && !S_ISREG(st.st_mode)) return writeInPlace(path, path, data, size);
    const fs::path target = resolveLinks(path);

    removeStaleTemps(path);
    const std::string tmp = outputTempPath(target.string(), target.extension().string());
    int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (fd < 0) fail(path, "cannot create the temporary file " + tmp, errno);
    auto abandon = [&](const std::string& what, int err) {
        if (fd >= 0) ::close(fd);
        ::unlink(tmp.c_str());
        fail(path, what, err);
    };
    if (exists) (void)::fchmod(fd, st.st_mode & 07777);  // keep the permissions of the file replaced
    if (const int err = writeAll(fd, data, size)) abandon("writing failed", err);
    // Delayed allocation (NFS, quotas) may report the error only here or at close.
    if (::fsync(fd) != 0) abandon("writing failed (fsync)", errno);
    const int closed = ::close(fd);
    fd = -1;
    if (closed != 0) abandon("writing failed (on close)", errno);
    struct stat written;
    if (::stat(tmp.c_str(), &written) != 0) abandon("the temporary file vanished", errno);
    if (uint64_t(written.st_size) != uint64_t(size)) abandon("the temporary file is short", EIO);
    if (::rename(tmp.c_str(), target.c_str()) != 0) abandon("cannot move the finished file into place", errno);
    if (const int err = syncFolder(folderOf(target))) fail(path, "written, but syncing its folder failed", err);
}

void checkOutputWritable(const std::string& path) {
    if (path.empty()) throw InputError("no output file given");
    struct stat st;
    if (::stat(path.c_str(), &st) == 0) {
        if (S_ISDIR(st.st_mode)) throw InputError(path + ": is a directory, not a file");
        if (!S_ISREG(st.st_mode)) {  // written in place: it must accept writes
            if (::access(path.c_str(), W_OK) != 0) fail(path, "cannot write", errno);
            return;
        }
    }
    const fs::path target = resolveLinks(path);
    removeStaleTemps(path);
    const std::string probe = outputTempPath(target.string(), ".probe");
    const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (fd < 0)
        throw InputError(path + ": cannot write into " + folderOf(target).string() + " (" + std::strerror(errno) + ")");
    ::close(fd);
    ::unlink(probe.c_str());
}

void requireExtension(const std::string& path, const std::string& ext, const std::string& option) {
    std::string lower = path;
    std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    if (lower.size() > ext.size() && lower.compare(lower.size() - ext.size(), ext.size(), ext) == 0) return;
    if (isSpecialFile(path)) return;
    const std::string format = ext == ".exr" ? "OpenEXR" : ext == ".png" ? "PNG" : ext.substr(1);
    throw InputError(option + " " + path + ": the file name must end in '" + ext + "' (" + option + " writes " + format +
                     "; e.g. " + option + " " + fs::path(path).replace_extension(ext).string() + ")");
}

void checkDistinctOutputs(const std::vector<NamedOutput>& outputs) {
    struct Key {
        std::string option, path, canonical;
        bool exists;
        struct stat st;
    };
    std::vector<Key> keys;
    for (const NamedOutput& o : outputs) {
        if (o.path.empty()) continue;
        Key k{o.option, o.path, "", false, {}};
        std::error_code ec;
        const fs::path c = fs::weakly_canonical(resolveLinks(o.path), ec);
        k.canonical = ec ? fs::absolute(o.path, ec).lexically_normal().string() : c.string();
        k.exists = ::stat(o.path.c_str(), &k.st) == 0;
        if (k.exists && !S_ISREG(k.st.st_mode) && !S_ISDIR(k.st.st_mode)) continue;  // a device may be shared
        for (const Key& prev : keys) {
            const bool same = prev.canonical == k.canonical ||
                              (prev.exists && k.exists && prev.st.st_dev == k.st.st_dev && prev.st.st_ino == k.st.st_ino);
            if (same)
                throw InputError(prev.option + " " + prev.path + " and " + k.option + " " + k.path +
                                 " name the same file: one output would overwrite the other; give each its own file" +
                                 (k.option == "--preview" || prev.option == "--preview"
                                      ? " (or --no-preview)"
                                      : ""));
        }
        keys.push_back(std::move(k));
    }
}

void checkOutputs(const std::vector<NamedOutput>& outputs) {
    // A folder first ("is a directory" says more than a missing extension), then extensions:
    // "-o x.png" (whose default preview is also x.png) is a wrong extension.
    for (const NamedOutput& o : outputs) {
        std::error_code ec;
        if (!o.path.empty() && std::filesystem::is_directory(o.path, ec)) checkOutputWritable(o.path);
    }
    for (const NamedOutput& o : outputs)
        if (!o.path.empty() && !o.extension.empty()) requireExtension(o.path, o.extension, o.option);
    checkDistinctOutputs(outputs);
    for (const NamedOutput& o : outputs)
        if (!o.path.empty()) checkOutputWritable(o.path);
}

}  // namespace bdptref
