// The shader libraries a scene file can name, with the host-side knowledge each one needs: how to make it
// (in float or double), the layout of its scene constant buffer, and the TraceRay parameters its shaders use.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/math.h"
#include "emulator/state_object.h"
#include "procedural/accuracy.h"
#include "procedural/precision.h"
#include "procedural/sample_layout.h"
#include "procedural/trace_ray_parameters.h"

namespace refray::scenes {

struct LightDesc {
    vec4 position{0.0f};
    vec4 ambientColor{0.0f};
    vec4 diffuseColor{0.0f};
};

// What the host writes into the library's scene constant buffer for one frame.
struct SceneConstantsInput {
    procedural::Float4x4 projectionToWorld;
    vec4 cameraPosition{0.0f};
    LightDesc light;
    float elapsedTime = 0.0f;
    int32_t debugFlag = 0;
};

struct ShaderLibraryBinding {
    std::string name;         // what scene files write in "shaderLibrary"
    std::string description;  // which HLSL it ports
    // Makes the library with its shaders' TraceRay arguments, one entry per ray type (exactly rayTypeCount; other
    // counts throw refray::Error), and its accuracy knobs. `traceRayDefaults` gives the library's own.
    std::function<std::shared_ptr<dxr::ShaderLibrary>(
        procedural::Precision, const std::vector<procedural::TraceRayArguments>&, const procedural::Accuracy&)>
        make;
    // The bytes of the library's SceneConstantBuffer (its C++ struct, padding zeroed).
    std::function<std::vector<uint8_t>(const SceneConstantsInput&)> sceneConstants;
    bool hasDebugFlag = false;
    // The number of ray types the shaders trace.
    uint32_t rayTypeCount = 0;
    // What the HLSL passes to TraceRay for ray type r: RayContributionToHitGroupIndex r, multiplier rayTypeCount,
    // miss index r and its instance inclusion mask (~0 for both libraries), rayTypeCount entries.
    std::vector<procedural::TraceRayArguments> traceRayDefaults;
};

// The registered libraries, in name order.
const std::vector<ShaderLibraryBinding>& shaderLibraries();
// Throws refray::Error with a "did you mean" and the list of known names when `name` is unknown.
const ShaderLibraryBinding& findShaderLibrary(const std::string& name);

}  // namespace refray::scenes
