#include "core/draw.h"

#include <algorithm>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

namespace refray {

namespace {
constexpr const char* kFont = "DejaVuSans";
}

void fillRect(Image& image, int x, int y, int w, int h, vec4 colour) {
    const int x0 = std::max(x, 0), y0 = std::max(y, 0);
    const int x1 = std::min(x + w, int(image.width())), y1 = std::min(y + h, int(image.height()));
    for (int j = y0; j < y1; ++j)
        for (int i = x0; i < x1; ++i) image.at(uint32_t(i), uint32_t(j)) = colour;
}

bool drawText(Image& image, int x, int y, const std::string& text, int size, vec4 colour) {
    if (image.empty() || text.empty()) return true;
    // Wraps the image's pixels: the text is composited straight into them.
    OIIO::ImageSpec spec(int(image.width()), int(image.height()), 4, OIIO::TypeDesc::FLOAT);
    OIIO::ImageBuf buffer(spec, image.pixels().data());
    const float c[4] = {colour.r, colour.g, colour.b, colour.a};
    return OIIO::ImageBufAlgo::render_text(buffer, x, y, text, size, kFont, c);
}

std::pair<int, int> textExtent(const std::string& text, int size) {
    const OIIO::ROI roi = OIIO::ImageBufAlgo::text_size(text, size, kFont);
    if (!roi.defined()) return {0, 0};
    return {roi.width(), roi.height()};
}

}  // namespace refray
