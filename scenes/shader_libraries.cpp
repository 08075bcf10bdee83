#include "scenes/shader_libraries.h"

#include <array>
#include <cstring>

#include "core/error.h"
#include "core/strings.h"
#include "procedural/d3d12/d3d12_shaders.h"
#include "procedural/proceduray/proceduray_shaders.h"

namespace refray::scenes {

namespace {

template <class T>
std::vector<uint8_t> bytesOf(const T& value) {
    std::vector<uint8_t> bytes(sizeof(T));
    std::memcpy(bytes.data(), &value, sizeof(T));
    return bytes;
}

std::vector<uint8_t> procedurayConstants(const SceneConstantsInput& in) {
    procedural::proceduray::SceneConstantBuffer cb{};
    cb.projectionToWorld = in.projectionToWorld;
    cb.cameraPosition = in.cameraPosition;
    cb.lightPosition = in.light.position;
    cb.lightAmbientColor = in.light.ambientColor;
    cb.lightDiffuseColor = in.light.diffuseColor;
    cb.reflectance = 0.0f;  // never written by the sample, never read (§1.7)
    cb.elapsedTime = in.elapsedTime;
    cb.debugFlag = in.debugFlag;
    return bytesOf(cb);
}

// The per-ray-type list of a scene as a library's TraceRayArgumentSet.
procedural::TraceRayArgumentSet argumentSet(const std::vector<procedural::TraceRayArguments>& perRayType,
                                            const char* library) {
    REFRAY_CHECK(perRayType.size() == procedural::kTraceRayTypeCount,
                 "the " << library << " shaders trace " << procedural::kTraceRayTypeCount
                        << " ray types; got TraceRay arguments for " << perRayType.size());
    procedural::TraceRayArgumentSet set;
    for (uint32_t r = 0; r < procedural::kTraceRayTypeCount; ++r) set[r] = perRayType[r];
    return set;
}

// A library's per-ray-type constants (an array in its header) as the binding stores them.
template <class T, size_t N>
std::vector<T> perRayType(const std::array<T, N>& rayTypes) {
    return {rayTypes.begin(), rayTypes.end()};
}

std::vector<uint8_t> d3d12Constants(const SceneConstantsInput& in) {
    procedural::d3d12::SceneConstantBuffer cb{};
    cb.projectionToWorld = in.projectionToWorld;
    cb.cameraPosition = in.cameraPosition;
    cb.lightPosition = in.light.position;
    cb.lightAmbientColor = in.light.ambientColor;
    cb.lightDiffuseColor = in.light.diffuseColor;
    cb.reflectance = 0.0f;  // never read (I10)
    cb.elapsedTime = in.elapsedTime;
    return bytesOf(cb);
}

// reference-scene-d3d12-procedural.md §1.7 (ray types), §2.5 (metaballs), §2.9-2.11 (closest hits).
ShaderLibraryFacts d3d12Facts() {
    namespace d = procedural::d3d12;
    using E = ShaderEffect;
    ShaderLibraryFacts f;
    f.maxRayRecursionDepth = d::MAX_RAY_RECURSION_DEPTH;
    f.shadowRayType = d::RayType::Shadow;
    f.rayFlags = perRayType(d::kTraceRayFlags);
    f.uses = {
        {E::ShadowRays, "MyClosestHitShader_Triangle", "", "", 0.0f},
        {E::ShadowRays, "MyClosestHitShader_AABB", "", "", 0.0f},
        {E::Reflections, "MyClosestHitShader_Triangle", "", "reflectanceCoef", 0.001f},
        {E::Reflections, "MyClosestHitShader_AABB", "", "reflectanceCoef", 0.001f},
        {E::Animation, "MyIntersectionShader_VolumetricPrimitive", "the metaballs' centres", "", 0.0f},
        {E::DistanceFog, "MyClosestHitShader_Triangle", "", "", 0.0f},
        {E::DistanceFog, "MyClosestHitShader_AABB", "", "", 0.0f},
        {E::RayDifferentials, "MyClosestHitShader_Triangle", "the grid lines", "", 0.0f},
    };
    return f;
}

// reference-scene-proceduray.md §1.4 (ray types), §1.9 (time), §3 (closest hits: the Julia and the Mandelbulb trace
// no shadow ray; the Julia always reflects with 0.1).
ShaderLibraryFacts procedurayFacts() {
    namespace p = procedural::proceduray;
    using E = ShaderEffect;
    ShaderLibraryFacts f;
    f.maxRayRecursionDepth = p::MAX_RAY_RECURSION_DEPTH;
    f.shadowRayType = p::Shadow;
    f.rayFlags = perRayType(p::kTraceRayFlags);
    f.uses = {
        {E::ShadowRays, "ClosestHit_Triangle", "", "", 0.0f},
        {E::ShadowRays, "ClosestHit_Pacman", "", "", 0.0f},
        {E::Reflections, "ClosestHit_Triangle", "", "reflectanceCoef", 0.001f},
        {E::Reflections, "ClosestHit_Pacman", "", "reflectanceCoef", 0.001f},
        {E::Reflections, "ClosestHit_Mandelbulb", "", "reflectanceCoef", 0.001f},
        {E::Reflections, "ClosestHit_Julia", "", "", 0.0f},
        {E::Animation, "Intersection_Mandelbulb", "the Mandelbulb's step count", "", 0.0f},
        {E::Animation, "Intersection_Pacman", "the Pac-man's mouth", "", 0.0f},
    };
    return f;
}

}  // namespace

const std::vector<ShaderLibraryBinding>& shaderLibraries() {
    static const std::vector<ShaderLibraryBinding> libraries = {
        {"d3d12-procedural-geometry",
         "Microsoft D3D12RaytracingProceduralGeometry Raytracing.hlsl (procedural/d3d12/)",
         [](procedural::Precision p, const std::vector<procedural::TraceRayArguments>& traceRay,
            const procedural::Accuracy& accuracy, const procedural::Effects& effects) {
             return procedural::d3d12::makeD3D12ShaderLibrary(p, argumentSet(traceRay, "d3d12-procedural-geometry"),
                                                              accuracy, effects);
         },
         d3d12Constants, false, procedural::d3d12::RayType::Count,
         perRayType(procedural::d3d12::defaultTraceRayArguments().rayTypes), d3d12Facts()},
        {"proceduray", "Proceduray MandelJuliaPac Raytracing.hlsl (procedural/proceduray/)",
         [](procedural::Precision p, const std::vector<procedural::TraceRayArguments>& traceRay,
            const procedural::Accuracy& accuracy, const procedural::Effects& effects) {
             return procedural::proceduray::makeProcedurayShaderLibrary(p, argumentSet(traceRay, "proceduray"), accuracy,
                                                                        effects);
         },
         procedurayConstants, true, procedural::proceduray::RayTypeCount,
         perRayType(procedural::proceduray::defaultTraceRayArguments().rayTypes), procedurayFacts()},
    };
    return libraries;
}

const ShaderLibraryBinding& findShaderLibrary(const std::string& name) {
    std::vector<std::string> names;
    for (const ShaderLibraryBinding& b : shaderLibraries()) {
        if (b.name == name) return b;
        names.push_back(b.name);
    }
    std::string known;
    for (const std::string& n : names) known += (known.empty() ? "" : ", ") + n;
    throw Error("unknown shader library '" + name + "'" + didYouMean(name, names) + "; known libraries: " + known);
}

}  // namespace refray::scenes
