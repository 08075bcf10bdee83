// The shader libraries a scene file can name, with the host-side knowledge each one needs: how to make it
// (in float or double), the layout of its scene constant buffer, and the TraceRay parameters its shaders use.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "core/math.h"
#include "emulator/state_object.h"
#include "procedural/accuracy.h"
#include "procedural/effects.h"
#include "procedural/perturbation.h"
#include "procedural/precision.h"
#include "procedural/sample_layout.h"
#include "procedural/trace_ray_parameters.h"

namespace refray::scenes {

struct LightDesc {
    vec4 position{0.0f};
    vec4 ambientColor{0.0f};
    vec4 diffuseColor{0.0f};
};

// What the host writes into the library's scene constant buffer for one frame. Each library takes the fields its
// constant buffer has.
struct SceneConstantsInput {
    procedural::Float4x4 projectionToWorld;
    vec4 cameraPosition{0.0f};
    LightDesc light;
    float elapsedTime = 0.0f;
    int32_t debugFlag = 0;   // debugFlag, or the path tracer's debugMode
    uint32_t seed = 0;       // RenderSettings::seed
    // The path tracer's (PathTracerConstants): the radiance of rays that leave the scene, scattering events per
    // path, the number of light triangles, and the paths per pixel of the dispatch (RenderSettings::spp).
    vec3 backgroundColor{0.0f};
    uint32_t maxBounces = 8;
    uint32_t lightCount = 0;
    uint32_t samplesPerPixel = 1;
};

// What a library's shaders do that the scene's DXR objects do not show, from its fact sheet: the exports that trace
// shadow or reflection rays, read the time, or shade with an effect of their own. scenes/effects.h decides from these
// (and from the scene) which effects a scene calls for.
enum class ShaderEffect {
    ShadowRays,        // traces the shadow ray type towards the light
    Reflections,       // traces a reflection (radiance) ray
    Animation,         // reads elapsedTime
    DistanceFog,       // blends towards the background with the hit distance
    RayDifferentials,  // filters a texture over the footprint of the neighbouring pixels' camera rays
    Textures,          // samples the models' diffuse textures
    NormalMaps,        // perturbs the shading normal with the models' normal maps
};
struct ShaderEffectUse {
    ShaderEffect effect;
    std::string exportName;  // the export that does it
    std::string what;        // a few words for the effect's reason, e.g. "the mouth"
    // A material field that gates it per record (e.g. reflections only where "reflectanceCoef" > 0.001); empty:
    // always. Read from a record's root constants when their struct has a field of this name.
    std::string gateField;
    float gateAbove = 0.0f;
};
struct ShaderLibraryFacts {
    uint32_t maxRayRecursionDepth = 0;  // the HLSL's MAX_RAY_RECURSION_DEPTH
    uint32_t shadowRayType = 0;         // the ray type TraceShadowRayAndReportIfHit traces
    std::vector<uint32_t> rayFlags;     // per ray type, the RAY_FLAGs its TraceRay call passes
    std::vector<ShaderEffectUse> uses;
};

// ShaderLibraryBinding::make: a library's maker, called with or without a perturbation (without: the nominal
// arithmetic, as the callers that only build the shaders as written ask for it).
class ShaderLibraryMaker {
public:
    using Function = std::function<std::shared_ptr<dxr::ShaderLibrary>(
        procedural::Precision, const std::vector<procedural::TraceRayArguments>&, const procedural::Accuracy&,
        const procedural::Effects&, const std::optional<procedural::Perturbation>&)>;

    ShaderLibraryMaker() = default;
    template <class F>
        requires std::is_constructible_v<Function, F>
    ShaderLibraryMaker(F function) : function_(std::move(function)) {}

    std::shared_ptr<dxr::ShaderLibrary> operator()(
        procedural::Precision precision, const std::vector<procedural::TraceRayArguments>& traceRay,
        const procedural::Accuracy& accuracy, const procedural::Effects& effects,
        const std::optional<procedural::Perturbation>& perturbation = std::nullopt) const {
        return function_(precision, traceRay, accuracy, effects, perturbation);
    }

private:
    Function function_;
};

struct ShaderLibraryBinding {
    std::string name;         // what scene files write in "shaderLibrary"
    std::string description;  // which HLSL it ports
    // Makes the library with its shaders' TraceRay arguments, one entry per ray type (exactly rayTypeCount; other
    // counts throw refray::Error), its accuracy knobs, the effects switched off and its perturbation (unset: the
    // nominal arithmetic). `traceRayDefaults` gives the library's own TraceRay arguments; Accuracy{} and Effects{}
    // give the HLSL's.
    ShaderLibraryMaker make;
    // The bytes of the library's SceneConstantBuffer (its C++ struct, padding zeroed).
    std::function<std::vector<uint8_t>(const SceneConstantsInput&)> sceneConstants;
    bool hasDebugFlag = false;
    // The number of ray types the shaders trace.
    uint32_t rayTypeCount = 0;
    // What the HLSL passes to TraceRay for ray type r: RayContributionToHitGroupIndex r, multiplier rayTypeCount,
    // miss index r and its instance inclusion mask (~0 for both libraries), rayTypeCount entries.
    std::vector<procedural::TraceRayArguments> traceRayDefaults;
    // What the shaders do besides (for scenes/effects.h).
    ShaderLibraryFacts facts;
    // The shaders draw `spp` random samples per pixel themselves (samplesPerPixel in the constants, keyed by the
    // render's seed): --spp is any count from 1 to maxSamplesPerPixel and the dispatch is the image size. Otherwise
    // --spp is a square k·k and the dispatch k times larger (a k x k grid of pixel centres, averaged).
    bool samplesInShader = false;
    uint32_t maxSamplesPerPixel = 256;
    // The name of the debug switch on its sceneConstants buffer (with hasDebugFlag).
    std::string debugFlagName = "debugFlag";
    // Further keys its sceneConstants buffer takes: "backgroundColor", "maxBounces".
    std::vector<std::string> constantsKeys;
    // Its constants hold the scene's "light" (required then; refused otherwise).
    bool usesLight = true;
    // Its make() builds the shaders with other TraceRay arguments (a ray type's "traceRay"), the scene's "effects"
    // block, the accuracy knobs and double precision. false: only the shaders as written (make() throws
    // refray::Error for anything else, and the loader refuses "traceRay" and "effects").
    bool configurable = true;
};

// The registered libraries, in name order.
const std::vector<ShaderLibraryBinding>& shaderLibraries();
// Throws refray::Error with a "did you mean" and the list of known names when `name` is unknown.
const ShaderLibraryBinding& findShaderLibrary(const std::string& name);

}  // namespace refray::scenes
