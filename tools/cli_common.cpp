#include "tools/cli_common.h"

#include <atomic>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <unistd.h>

#include "core/error.h"

namespace refray::tools {

Size parseSize(const std::string& text, const char* option) {
    static const std::regex pattern(R"((\d{1,9})x(\d{1,9}))");
    std::smatch m;
    REFRAY_CHECK(std::regex_match(text, m, pattern), option << " expects WIDTHxHEIGHT (e.g. 640x360), got '" << text << "'");
    const unsigned long w = std::stoul(m[1]), h = std::stoul(m[2]);
    REFRAY_CHECK(w > 0 && h > 0 && w <= 16384 && h <= 16384, option << " " << text << " is outside 1x1 .. 16384x16384");
    return {uint32_t(w), uint32_t(h)};
}

void parsePixel(const std::string& text, uint32_t& x, uint32_t& y, const char* option) {
    static const std::regex pattern(R"((\d{1,9}),(\d{1,9}))");
    std::smatch m;
    REFRAY_CHECK(std::regex_match(text, m, pattern), option << " expects X,Y (e.g. 640,360), got '" << text << "'");
    x = uint32_t(std::stoul(m[1]));
    y = uint32_t(std::stoul(m[2]));
}

Progress::Sink terminalProgress() {
    if (!isatty(STDERR_FILENO)) return {};
    return [](const ProgressState& s) {
        std::fprintf(stderr, "\r%s", formatProgressBar(s).c_str());
        if (s.finished) std::fputc('\n', stderr);
        std::fflush(stderr);
    };
}

void writeOutput(const std::string& path, const Image& image) {
    const auto parent = std::filesystem::path(path).parent_path();
    if (!parent.empty()) std::filesystem::create_directories(parent);
    writeImage(path, image);
}

namespace {

std::string base64(const std::string& bytes) {
    static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    out.reserve((bytes.size() + 2) / 3 * 4);
    size_t i = 0;
    for (; i + 2 < bytes.size(); i += 3) {
        const uint32_t v = uint32_t(uint8_t(bytes[i])) << 16 | uint32_t(uint8_t(bytes[i + 1])) << 8 | uint8_t(bytes[i + 2]);
        out += kAlphabet[v >> 18];
        out += kAlphabet[(v >> 12) & 63];
        out += kAlphabet[(v >> 6) & 63];
        out += kAlphabet[v & 63];
    }
    if (i + 1 == bytes.size()) {
        const uint32_t v = uint32_t(uint8_t(bytes[i])) << 16;
        out += kAlphabet[v >> 18];
        out += kAlphabet[(v >> 12) & 63];
        out += "==";
    } else if (i + 2 == bytes.size()) {
        const uint32_t v = uint32_t(uint8_t(bytes[i])) << 16 | uint32_t(uint8_t(bytes[i + 1])) << 8;
        out += kAlphabet[v >> 18];
        out += kAlphabet[(v >> 12) & 63];
        out += kAlphabet[(v >> 6) & 63];
        out += '=';
    }
    return out;
}

}  // namespace

// Through a temporary file because core/image writes files only.
std::string pngDataURI(const Image& image) {
    static std::atomic<unsigned> counter{0};
    const auto path = std::filesystem::temp_directory_path() /
                      ("refray-page-" + std::to_string(getpid()) + "-" + std::to_string(counter++) + ".png");
    Image bare(image.width(), image.height());
    bare.pixels() = image.pixels();
    writeImage(path.string(), bare);
    std::ifstream in(path, std::ios::binary);
    std::ostringstream bytes;
    bytes << in.rdbuf();
    in.close();
    std::error_code ignored;
    std::filesystem::remove(path, ignored);
    return "data:image/png;base64," + base64(bytes.str());
}

}  // namespace refray::tools
