// Small pieces the refray subcommands share: option parsing and the terminal progress bar.
#pragma once

#include <cstdint>
#include <string>

#include "core/image.h"
#include "core/progress.h"
#include "core/text_file.h"  // writeTextFile, which the commands use

namespace refray::tools {

struct Size {
    uint32_t width = 640, height = 360;
};

// "WIDTHxHEIGHT" within 1x1 .. 16384x16384; throws refray::Error naming the option otherwise.
Size parseSize(const std::string& text, const char* option = "--size");
// "X,Y": two non-negative integers; throws refray::Error naming the option otherwise.
void parsePixel(const std::string& text, uint32_t& x, uint32_t& y, const char* option = "--pixel");
// A progress bar on stderr when it is a terminal; an empty sink otherwise.
Progress::Sink terminalProgress();
// Writes `image`, creating the parent directory.
void writeOutput(const std::string& path, const Image& image);

// The image as a PNG data URI (the bytes an R8G8B8A8_UNORM target holds), for self-contained HTML pages.
std::string pngDataURI(const Image& image);

}  // namespace refray::tools
