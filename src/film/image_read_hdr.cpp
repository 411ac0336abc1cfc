#include "film/image_read.h"

#include "bdptref/errors.h"

#include <stb/stb_image.h>

#include <cstring>
#include <fstream>
#include <memory>

namespace bdptref {

bool hasRadianceMagic(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    char m[10] = {};
    in.read(m, 10);
    const std::string head(m, size_t(in.gcount()));
    return head.rfind("#?RADIANCE", 0) == 0 || head.rfind("#?RGBE", 0) == 0;
}

// stb_image decodes RGBE as OpenImageIO's hdrinput did (Walter's rgbe.c: mantissa * 2^(e-136),
// no +0.5), so the floats are the same; rows top to bottom for the standard "-Y H +X W" layout
// (stb_image refuses the others; those go to the OpenImageIO module, which reads them).
ExrImage readRadianceImage(const std::string& path) {
    int w = 0, h = 0, comp = 0;
    std::unique_ptr<float, void (*)(void*)> px(stbi_loadf(path.c_str(), &w, &h, &comp, 3), stbi_image_free);
    if (!px) {
        const std::string why = stbi_failure_reason() ? stbi_failure_reason() : "unknown error";
        if (why == "unsupported data layout" || why == "Unsupported HDR format")
            return readImageWithModule(path);  // e.g. "+Y H +X W"
        throw InputError(path + ": cannot read the Radiance HDR image: " + why);
    }
    ExrImage img;
    img.width = w;
    img.height = h;
    img.window = FilmWindow::full(w, h);
    const size_t n = size_t(w) * size_t(h);
    const char* names[3] = {"R", "G", "B"};
    for (size_t c = 0; c < 3; ++c) {
        std::vector<float>& ch = img.channels[names[c]];
        ch.resize(n);
        for (size_t i = 0; i < n; ++i) ch[i] = px.get()[i * 3 + c];
    }
    return img;
}

}  // namespace bdptref
