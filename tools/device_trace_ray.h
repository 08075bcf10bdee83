// The TraceRay arguments a GLSL port passes on the Vulkan device, per ray type: what refray's C++ shader library
// passes for the same scene (docs/vulkan-backend.md, "TraceRay arguments a scene overrides become specialization
// constants"). Built with the Vulkan back end only.
#pragma once

#include <string>
#include <vector>

#include "gpu/vulkan_pipeline.h"
#include "scenes/scene_desc.h"

namespace refray::tools {

// `scene`: the scene file's description, whose ray types hold the effective arguments (the library's defaults with
// each ray type's "traceRay" applied, scenes/loader/pipeline.cpp); nullptr for the built-in scene (library
// "builtin", whose C++ shaders pass fixed arguments: R = r, M = 2, miss index r, mask 0xFF). Throws refray::Error
// when the arguments cannot be determined: a library other than the scene's, an unknown library, or a scene whose
// ray types are not the ones its library's shaders trace.
std::vector<gpu::TraceRayConstants> deviceTraceRayConstants(const std::string& library, const scenes::SceneDesc* scene);

}  // namespace refray::tools
