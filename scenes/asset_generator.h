// The generated assets of the path-tracer model scenes: scenes/cornell-box (the Cornell University measurements as
// OBJ + MTL) and scenes/textured-room (procedural meshes and textures). This file is their source: the files in the
// repository are its output (tools/make_assets.cpp writes them), and tests/scenes/model_test.cpp checks that
// regenerating them gives the same bytes.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace refray::scenes {

// Writes cornell-box/ and textured-room/ under `scenesDir` (creating the folders) and returns the paths written,
// relative to `scenesDir` with '/' separators, in the order written. Deterministic: the same bytes on every run
// (text with fixed decimals; PNGs through core/image.h, whose bytes depend only on the pixels and the zlib in use).
// Throws refray::Error naming a file that cannot be written.
std::vector<std::string> writeModelAssets(const std::filesystem::path& scenesDir);

}  // namespace refray::scenes
