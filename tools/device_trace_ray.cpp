#include "tools/device_trace_ray.h"

#include "core/error.h"
#include "procedural/builtin/builtin_shaders.h"
#include "scenes/shader_libraries.h"

namespace refray::tools {

std::vector<gpu::TraceRayConstants> deviceTraceRayConstants(const std::string& library, const scenes::SceneDesc* scene) {
    std::vector<gpu::TraceRayConstants> out;
    if (!scene) {
        REFRAY_CHECK(library == "builtin", "--device vulkan: the TraceRay arguments of the " << library
                                               << " shaders come from a scene file, and none was given");
        // procedural/builtin/builtin_shaders.cpp, traceRadiance and inShadow.
        for (uint32_t r = 0; r < procedural::builtin::kRayTypeCount; ++r)
            out.push_back({r, procedural::builtin::kRayTypeCount, r, 0xFFu});
        return out;
    }
    REFRAY_CHECK(scene->shaderLibrary == library, "--device vulkan: scene '" << scene->name << "' uses the "
                                                      << scene->shaderLibrary << " shaders, not " << library
                                                      << "; their TraceRay arguments are unknown");
    const scenes::ShaderLibraryBinding& binding = scenes::findShaderLibrary(library);  // throws for an unknown one
    REFRAY_CHECK(scene->rayTypes.size() == binding.rayTypeCount,
                 "--device vulkan: scene '" << scene->name << "' declares " << scene->rayTypes.size()
                                            << " ray types, but the " << library << " shaders trace "
                                            << binding.rayTypeCount
                                            << "; the GLSL port's TraceRay arguments cannot be determined");
    for (const scenes::RayTypeDesc& t : scene->rayTypes)
        out.push_back({t.rayContribution, t.multiplier, t.missShaderIndex, t.instanceInclusionMask});
    return out;
}

}  // namespace refray::tools
