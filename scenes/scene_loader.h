// Reads a scene file (docs/scene-format.md) into a validated SceneDesc. Every error names the file, line and
// column and says what was expected; unknown keys and unknown names get a "did you mean".
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "scenes/scene_desc.h"

namespace refray::scenes {

// The format string a scene file declares in "format".
inline constexpr std::string_view kSceneFormat = "refray-scene/1";
// A lesson (docs/tutorial-indexing.md): {"format": "refray-lesson/1", "name", "base": a scene or lesson file
// relative to this one, "title", "teaches", "patch": a JSON Patch (RFC 6902) applied to the base, "expect":
// {"table": the first finding of `refray table --check`, "render": {"camera", "size", "diagnostic": what a
// render stops with}}} (LessonDesc).
inline constexpr std::string_view kLessonFormat = "refray-lesson/1";

// Scene and lesson files alike.
SceneDesc loadSceneFile(const std::filesystem::path& path);
// The same from text; `fileName` is used in messages and as SceneDesc::file.
SceneDesc parseScene(std::string_view text, const std::string& fileName);

}  // namespace refray::scenes
