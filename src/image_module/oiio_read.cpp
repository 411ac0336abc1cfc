// libbdptref_oiio.so: readImage (exr_io.h) for formats other than EXR and Radiance .hdr (PNG,
// TIFF, PFM, JPEG, ...), through OpenImageIO. A separate module, loaded by film/image_module.cpp
// on the first such read, so that no other command pays for loading OpenImageIO and the ~260
// libraries it links. Built with the same compiler and headers as bdptref (one CMake project), so
// the C++ types may cross the extern "C" boundary.
#include "bdptref/exr_io.h"

#include <OpenImageIO/imageio.h>

extern "C" __attribute__((visibility("default"))) bool bdptref_module_read_image(const char* path, bdptref::ExrImage* out,
                                                                                  std::string* error) {
    try {
        auto in = OIIO::ImageInput::open(path);
        if (!in) {
            *error = "cannot read image: " + OIIO::geterror();
            return false;
        }
        const OIIO::ImageSpec& spec = in->spec();
        bdptref::ExrImage img;
        img.width = spec.width;
        img.height = spec.height;
        img.window = bdptref::FilmWindow{spec.full_width, spec.full_height, spec.x - spec.full_x, spec.y - spec.full_y,
                                         spec.width, spec.height};
        const size_t n = size_t(spec.width) * size_t(spec.height), c = size_t(spec.nchannels);
        std::vector<float> data(n * c);
        if (!in->read_image(0, 0, 0, int(c), OIIO::TypeDesc::FLOAT, data.data())) {
            *error = "cannot read pixels: " + in->geterror();
            return false;
        }
        for (size_t k = 0; k < c; ++k) {
            std::vector<float> ch(n);
            for (size_t i = 0; i < n; ++i) ch[i] = data[i * c + k];
            img.channels[spec.channel_name(int(k))] = std::move(ch);
        }
        for (const auto& attr : spec.extra_attribs) img.attributes[attr.name().string()] = attr.get_string();
        in->close();
        *out = std::move(img);
        return true;
    } catch (const std::exception& e) {
        *error = e.what();
        return false;
    }
}
