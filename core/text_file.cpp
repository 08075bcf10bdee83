#include "core/text_file.h"

#include <filesystem>
#include <fstream>

#include "core/error.h"

namespace refray {

void writeTextFile(const std::string& path, const std::string& text) {
    const auto parent = std::filesystem::path(path).parent_path();
    if (!parent.empty()) std::filesystem::create_directories(parent);
    std::ofstream out(path, std::ios::binary);
    out << text;
    out.close();
    REFRAY_CHECK(out.good(), "cannot write '" << path << "'");
}

}  // namespace refray
