// libFuzzer: the scene loader (scene and lesson files) on arbitrary bytes. Bad input must end in refray::Error, a
// message naming the file, line and column; a crash, a sanitizer report or a hang is a finding.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "core/error.h"
#include "scenes/scene_loader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    try {
        refray::scenes::parseScene(text, "fuzz.json");
    } catch (const refray::Error&) {
        // The expected outcome for almost every input.
    }
    return 0;
}
