#include "film/image_read.h"

#include "bdptref/errors.h"

#include <dlfcn.h>
#include <unistd.h>

#include <cstdlib>
#include <mutex>
#include <vector>

#ifndef BDPTREF_INSTALL_LIBDIR
#define BDPTREF_INSTALL_LIBDIR "lib"
#endif
#ifndef BDPTREF_MODULE_DIRS
#define BDPTREF_MODULE_DIRS ""
#endif

namespace bdptref {

namespace {

std::string folderOf(const std::string& file) {
    const size_t slash = file.rfind('/');
    return slash == std::string::npos ? std::string(".") : file.substr(0, slash);
}

// Where the module may be: $BDPTREF_IMAGE_MODULE alone if set; else, in order, next to the binary or shared library
// holding this code (the build tree: bdptref, bdptref_tests, libbdptref.so); next to the running
// executable; PREFIX/lib of an installed bdptref (bin/../lib); the install and build folders
// known when this was compiled (a Python process has neither next to it); the loader's path.
std::vector<std::string> candidates() {
    std::vector<std::string> c;
    if (const char* env = std::getenv("BDPTREF_IMAGE_MODULE"); env && *env) return {env};
    std::vector<std::string> dirs;
    Dl_info info;
    if (dladdr(reinterpret_cast<void*>(&readImageWithModule), &info) && info.dli_fname && *info.dli_fname)
        dirs.push_back(folderOf(info.dli_fname));
    std::vector<char> exe(4096);
    const ssize_t len = readlink("/proc/self/exe", exe.data(), exe.size() - 1);
    if (len > 0) dirs.push_back(folderOf(std::string(exe.data(), size_t(len))));
    for (const std::string& d : std::vector<std::string>(dirs)) dirs.push_back(d + "/../" + BDPTREF_INSTALL_LIBDIR);
    const std::string known = BDPTREF_MODULE_DIRS;
    for (size_t b = 0, e; b < known.size(); b = e + 1) {
        e = known.find(':', b);
        if (e == std::string::npos) e = known.size();
        if (e > b) dirs.push_back(known.substr(b, e - b));
    }
    for (const std::string& d : dirs) c.push_back(d + "/" + kModuleFileName);
    c.push_back(kModuleFileName);
    return c;
}

struct Module {
    ModuleReadFunction read = nullptr;
    std::string error;  // why it could not be loaded
};

const Module& module() {
    static Module m;
    static std::once_flag once;
    std::call_once(once, [] {
        std::string tried;
        for (const std::string& path : candidates()) {
            void* h = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
            if (!h) {
                const char* e = dlerror();
                tried += "\n  " + path + ": " + (e ? e : "not loadable");
                continue;
            }
            m.read = reinterpret_cast<ModuleReadFunction>(dlsym(h, kModuleReadSymbol));
            if (m.read) return;
            tried += "\n  " + path + ": has no " + kModuleReadSymbol;
        }
        m.error = std::string("reading formats other than EXR and Radiance .hdr needs ") + kModuleFileName +
                  " (bdptref's OpenImageIO module, built with bdptref and installed next to it; or set "
                  "BDPTREF_IMAGE_MODULE to its path), which could not be loaded:" + tried;
    });
    return m;
}

}  // namespace

ExrImage readImageWithModule(const std::string& path) {
    const Module& m = module();
    if (!m.read) throw InputError(path + ": " + m.error);
    ExrImage img;
    std::string error;
    if (!m.read(path.c_str(), &img, &error)) throw InputError(path + ": " + error);
    return img;
}

}  // namespace bdptref
