// Drawing into an Image: filled rectangles and text (OpenImageIO's text renderer with a system TrueType
// font, DejaVu Sans from Debian's fonts-dejavu-core). Used for legends and plots.
#pragma once

#include <string>

#include "core/image.h"

namespace refray {

// Fills the rectangle [x, x+w) x [y, y+h), clipped to the image.
void fillRect(Image& image, int x, int y, int w, int h, vec4 colour);

// Draws `text` with its baseline at (x, y), `size` pixels tall. Returns false (and draws nothing) when no
// usable font is installed; callers then fall back to a text legend.
bool drawText(Image& image, int x, int y, const std::string& text, int size, vec4 colour);

// The width and height in pixels `text` takes at `size` (0, 0 without a font).
std::pair<int, int> textExtent(const std::string& text, int size);

}  // namespace refray
