#include "tools/cli_common.h"

#include <atomic>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string_view>
#include <unistd.h>

#include "core/error.h"

namespace refray::tools {

namespace {

// "<digits><separator><digits>", each number 1 to 9 digits: the two numbers, or false.
bool parseNumberPair(const std::string& text, char separator, unsigned long& a, unsigned long& b) {
    const size_t at = text.find(separator);
    if (at == std::string::npos) return false;
    const auto number = [](std::string_view digits, unsigned long& value) {
        if (digits.empty() || digits.size() > 9) return false;
        value = 0;
        for (char c : digits) {
            if (c < '0' || c > '9') return false;
            value = value * 10 + unsigned(c - '0');
        }
        return true;
    };
    const std::string_view view(text);
    return number(view.substr(0, at), a) && number(view.substr(at + 1), b);
}

}  // namespace

Size parseSize(const std::string& text, const char* option) {
    unsigned long w = 0, h = 0;
    REFRAY_CHECK(parseNumberPair(text, 'x', w, h), option << " expects WIDTHxHEIGHT (e.g. 640x360), got '" << text << "'");
    REFRAY_CHECK(w > 0 && h > 0 && w <= 16384 && h <= 16384, option << " " << text << " is outside 1x1 .. 16384x16384");
    return {uint32_t(w), uint32_t(h)};
}

void parsePixel(const std::string& text, uint32_t& x, uint32_t& y, const char* option) {
    unsigned long a = 0, b = 0;
    REFRAY_CHECK(parseNumberPair(text, ',', a, b), option << " expects X,Y (e.g. 640,360), got '" << text << "'");
    x = uint32_t(a);
    y = uint32_t(b);
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
