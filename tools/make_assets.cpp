// refray_make_assets: writes the generated model assets (scenes/cornell-box, scenes/textured-room) from
// scenes/asset_generator.cpp, by default into this source tree's scenes/ folder.
#include <cstdio>
#include <string>

#include <CLI/CLI.hpp>

#include "core/error.h"
#include "scenes/asset_generator.h"

int main(int argc, char** argv) {
    CLI::App app{"Writes the generated OBJ, MTL and PNG files of scenes/cornell-box and scenes/textured-room."};
    std::string output = std::string(REFRAY_SOURCE_DIR) + "/scenes";
    app.add_option("--output", output, "the scenes folder to write into")->capture_default_str();
    CLI11_PARSE(app, argc, argv);
    try {
        for (const std::string& file : refray::scenes::writeModelAssets(output))
            std::printf("wrote %s/%s\n", output.c_str(), file.c_str());
    } catch (const refray::Error& e) {
        std::fprintf(stderr, "refray_make_assets: %s\n", e.what());
        return 1;
    }
    return 0;
}
