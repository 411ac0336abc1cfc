// 8-bit PNG encoding in memory (stb_image_write, from Debian's libstb, which tinygltf loads
// anyway), so writing a preview needs no image library beyond it.
#pragma once

#include <cstdint>
#include <vector>

namespace bdptref {

// [0, 1] -> 0..255 exactly as OpenImageIO converted float pixels to UINT8 when it wrote the
// previews: clamp(v * 255 + 0.5), truncated (round half up; below 0 is 0, above 1 is 255).
uint8_t unitToByte(float v);

// The byte of a preview pixel: the sRGB OETF of the linear value clamped to [0, 1] (NaN -> 0), then
// unitToByte. Every preview (render's PNG, validate's report) encodes with it.
uint8_t linearToSrgbByte(double linear);

// A PNG of `channels` (1..4) 8-bit channels per pixel, rows top to bottom. Throws
// std::runtime_error if the encoder fails (out of memory).
std::vector<unsigned char> encodePng8(int width, int height, int channels, const uint8_t* pixels);

}  // namespace bdptref
