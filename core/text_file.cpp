#include "core/text_file.h"

#include "core/file_output.h"

namespace refray {

void writeTextFile(const std::string& path, const std::string& text) { writeFileAtomically(path, text); }

}  // namespace refray
