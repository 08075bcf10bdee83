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

template <size_t N>
std::vector<procedural::TraceRayArguments> perRayType(const std::array<procedural::TraceRayArguments, N>& rayTypes) {
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

}  // namespace

const std::vector<ShaderLibraryBinding>& shaderLibraries() {
    static const std::vector<ShaderLibraryBinding> libraries = {
        {"d3d12-procedural-geometry",
         "Microsoft D3D12RaytracingProceduralGeometry Raytracing.hlsl (procedural/d3d12/)",
         [](procedural::Precision p, const std::vector<procedural::TraceRayArguments>& traceRay,
            const procedural::Accuracy& accuracy) {
             return procedural::d3d12::makeD3D12ShaderLibrary(p, argumentSet(traceRay, "d3d12-procedural-geometry"),
                                                              accuracy);
         },
         d3d12Constants, false, procedural::d3d12::RayType::Count,
         perRayType(procedural::d3d12::defaultTraceRayArguments().rayTypes)},
        {"proceduray", "Proceduray MandelJuliaPac Raytracing.hlsl (procedural/proceduray/)",
         [](procedural::Precision p, const std::vector<procedural::TraceRayArguments>& traceRay,
            const procedural::Accuracy& accuracy) {
             return procedural::proceduray::makeProcedurayShaderLibrary(p, argumentSet(traceRay, "proceduray"), accuracy);
         },
         procedurayConstants, true, procedural::proceduray::RayTypeCount,
         perRayType(procedural::proceduray::defaultTraceRayArguments().rayTypes)},
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
