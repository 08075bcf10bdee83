// Writing a text file whole (reports, JSON documents, job lists).
#pragma once

#include <string>

namespace refray {

// Writes `text` to `path`, creating the parent directory, whole or not at all (core/file_output.h); throws
// refray::Error naming the file and the reason.
void writeTextFile(const std::string& path, const std::string& text);

}  // namespace refray
