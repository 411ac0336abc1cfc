#include "film/png_write.h"

#include <stb/stb_image_write.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace bdptref {

uint8_t unitToByte(float v) {
    // The same float arithmetic as OpenImageIO's scaled_conversion<float, uint8_t> (fmath.h).
    const float s = v * 255.f + (v * 255.f < 0.f ? -0.5f : 0.5f);
    return uint8_t(std::min(255.f, std::max(0.f, s)));
}

uint8_t linearToSrgbByte(double linear) {
    const double c = std::isfinite(linear) ? std::min(1.0, std::max(0.0, linear)) : 0.0;
    return unitToByte(float(c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1.0 / 2.4) - 0.055));
}

std::vector<unsigned char> encodePng8(int width, int height, int channels, const uint8_t* pixels) {
    std::vector<unsigned char> bytes;
    auto append = [](void* context, void* data, int size) {
        auto* out = static_cast<std::vector<unsigned char>*>(context);
        out->insert(out->end(), static_cast<unsigned char*>(data), static_cast<unsigned char*>(data) + size);
    };
    if (!stbi_write_png_to_func(append, &bytes, width, height, channels, pixels, width * channels) || bytes.empty())
        throw std::runtime_error("the PNG encoder failed (out of memory?)");
    return bytes;
}

}  // namespace bdptref
