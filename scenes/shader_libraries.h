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
#include "procedural/precision.h"
#include "procedural/sample_layout.h"

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
    std::function<std::shared_ptr<dxr::ShaderLibrary>(procedural::Precision)> make;
    // The bytes of the library's SceneConstantBuffer (its C++ struct, padding zeroed).
    std::function<std::vector<uint8_t>(const SceneConstantsInput&)> sceneConstants;
    bool hasDebugFlag = false;
    // The shaders trace ray type r with RayContributionToHitGroupIndex r, multiplier rayTypeCount and miss index r.
    uint32_t rayTypeCount = 0;
};

// The registered libraries, in name order.
const std::vector<ShaderLibraryBinding>& shaderLibraries();
// Throws refray::Error with a "did you mean" and the list of known names when `name` is unknown.
const ShaderLibraryBinding& findShaderLibrary(const std::string& name);

}  // namespace refray::scenes
