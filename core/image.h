// A float RGBA image with string metadata, read and written through OpenImageIO.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "core/math.h"

namespace refray {

class Image {
public:
    Image() = default;
    Image(uint32_t width, uint32_t height, vec4 fill = vec4(0.0f));

    uint32_t width() const { return width_; }
    uint32_t height() const { return height_; }
    bool empty() const { return pixels_.empty(); }

    vec4& at(uint32_t x, uint32_t y) { return pixels_[size_t(y) * width_ + x]; }
    const vec4& at(uint32_t x, uint32_t y) const { return pixels_[size_t(y) * width_ + x]; }
    const std::vector<vec4>& pixels() const { return pixels_; }
    std::vector<vec4>& pixels() { return pixels_; }

    // String metadata (provenance). Written to EXR/PNG headers, read back by readImage.
    std::map<std::string, std::string> metadata;

private:
    uint32_t width_ = 0, height_ = 0;
    std::vector<vec4> pixels_;
};

// The conversion a DXR R8G8B8A8_UNORM render target applies to a float written by a
// shader: NaN -> 0, clamp to [0,1], x255, round to nearest (D3D float->UNORM rule).
uint8_t floatToUnorm8(float value);

// Writes by extension: .exr keeps the floats as written (half-free, 32-bit float);
// .png stores what an R8G8B8A8_UNORM target holds (floatToUnorm8, no sRGB transfer).
// The file is written whole or not at all (core/file_output.h). Throws refray::Error naming the path on failure.
void writeImage(const std::string& path, const Image& image);

// What an image file's header declares, read without its pixels (to check sizes before reading two images).
struct ImageHeader {
    uint32_t width = 0, height = 0, channels = 0;
};
// Throws refray::Error naming the path, as readImage does for the same file.
ImageHeader readImageHeader(const std::string& path);

// Reads any format OpenImageIO knows; 8-bit data becomes value/255. Missing channels:
// RGB gets alpha 1, grey is replicated. Throws refray::Error naming the path, also for a directory, a
// device or a header declaring more than kMaxImagePixels (core/file_input.h), before any pixel is allocated.
Image readImage(const std::string& path);

}  // namespace refray
