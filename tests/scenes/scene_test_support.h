// What the scene-file tests share: reading a file, editing one occurrence, and catching the loader's message.
#pragma once

#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <string>

#include "core/error.h"
#include "scenes/scene_loader.h"

namespace refray::scenes::testing {

inline std::string readText(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    EXPECT_TRUE(in.good()) << "cannot read " << path;
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// `text` with `from` replaced by `to` (which must occur exactly once).
inline std::string edited(std::string text, const std::string& from, const std::string& to) {
    const size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    EXPECT_EQ(text.find(from, at + 1), std::string::npos) << "not unique: " << from;
    if (at != std::string::npos) text.replace(at, from.size(), to);
    return text;
}

// The loader's error for `text` (named broken.json), or "" if it loads.
inline std::string loadError(const std::string& text) {
    try {
        parseScene(text, "broken.json");
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

}  // namespace refray::scenes::testing

#define EXPECT_CONTAINS(haystack, needle) \
    EXPECT_NE(std::string(haystack).find(needle), std::string::npos) << "message: " << (haystack)
