// The operating system's reason for an errno value, as a phrase that reads inside a sentence ("no space left on
// device"): the one wording of OS errors in refray's messages (core/file_input.*, core/file_output.*).
#pragma once

#include <cctype>
#include <cstring>
#include <string>

namespace refray {

inline std::string osReason(int error) {
    std::string text = std::strerror(error);
    if (!text.empty()) text[0] = char(std::tolower((unsigned char)text[0]));
    return text;
}

}  // namespace refray
