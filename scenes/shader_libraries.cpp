#include "scenes/shader_libraries.h"

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
         [](procedural::Precision p) { return procedural::d3d12::makeD3D12ShaderLibrary(p); }, d3d12Constants, false,
         procedural::d3d12::RayType::Count},
        {"proceduray", "Proceduray MandelJuliaPac Raytracing.hlsl (procedural/proceduray/)",
         [](procedural::Precision p) { return procedural::proceduray::makeProcedurayShaderLibrary(p); },
         procedurayConstants, true, procedural::proceduray::RayTypeCount},
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
