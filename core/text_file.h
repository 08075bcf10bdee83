// Writing a text file whole (reports, JSON documents, job lists).
#pragma once

#include <string>

namespace refray {

// Writes `text` to `path`, creating the parent directory; throws refray::Error naming the file.
void writeTextFile(const std::string& path, const std::string& text);

}  // namespace refray
