#include "scenes/shader_libraries.h"

#include <array>
#include <cstring>

#include "core/error.h"
#include "core/strings.h"
#include "procedural/d3d12/d3d12_shaders.h"
#include "procedural/pathtracer/pathtracer_shaders.h"
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
        // The inline-shadow closest hits (scenes/inline/InlineShadows.hlsl): the same effects, shadows traced inline.
        {E::ShadowRays, "MyClosestHitShader_Triangle_InlineShadow", "a RayQuery", "", 0.0f},
        {E::ShadowRays, "MyClosestHitShader_AABB_InlineShadow", "a RayQuery", "", 0.0f},
        {E::Reflections, "MyClosestHitShader_Triangle_InlineShadow", "", "reflectanceCoef", 0.001f},
        {E::Reflections, "MyClosestHitShader_AABB_InlineShadow", "", "reflectanceCoef", 0.001f},
        {E::DistanceFog, "MyClosestHitShader_Triangle_InlineShadow", "", "", 0.0f},
        {E::DistanceFog, "MyClosestHitShader_AABB_InlineShadow", "", "", 0.0f},
        {E::RayDifferentials, "MyClosestHitShader_Triangle_InlineShadow", "the grid lines", "", 0.0f},
    };
    // The variants of the inline-shadow closest hits (the RayQuery lessons and mutants) have the same effects.
    const size_t inlineUses = f.uses.size();
    for (const std::string& suffix : d::inlineVariantSuffixes())
        for (size_t i = 0; i < inlineUses; ++i)
            if (f.uses[i].exportName.ends_with("_InlineShadow")) {
                ShaderEffectUse use = f.uses[i];
                use.exportName += suffix;
                f.uses.push_back(use);
            }
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

std::vector<uint8_t> pathTracerConstants(const SceneConstantsInput& in) {
    procedural::pathtracer::PathTracerConstants cb{};
    cb.projectionToWorld = in.projectionToWorld;
    cb.cameraPosition = in.cameraPosition;
    cb.backgroundColor = vec4(in.backgroundColor, 1.0f);
    cb.samplesPerPixel = in.samplesPerPixel;
    cb.maxBounces = in.maxBounces;
    cb.seed = in.seed;
    cb.lightCount = in.lightCount;
    cb.debugMode = uint32_t(in.debugFlag);
    return bytesOf(cb);
}

// procedural/pathtracer/pathtracer_shaders.h: PT_RayGen traces every ray itself (an iterative path), radiance rays
// with no flags and shadow rays that accept the first hit and skip the closest hit; PT_ClosestHit samples the
// diffuse textures and the normal maps.
ShaderLibraryFacts pathTracerFacts() {
    namespace pt = procedural::pathtracer;
    using E = ShaderEffect;
    ShaderLibraryFacts f;
    f.maxRayRecursionDepth = 1;  // no shader but the ray generation shader traces
    f.shadowRayType = pt::RayType::Shadow;
    f.rayFlags = {pt::kRadianceRayFlags, pt::kShadowRayFlags};
    f.uses = {
        {E::ShadowRays, "PT_RayGen", "next-event estimation", "", 0.0f},
        {E::Reflections, "PT_RayGen", "the path's bounces", "", 0.0f},
        {E::Textures, "PT_ClosestHit", "", "", 0.0f},
        {E::NormalMaps, "PT_ClosestHit", "", "", 0.0f},
    };
    return f;
}

std::shared_ptr<dxr::ShaderLibrary> makePathTracer(procedural::Precision precision,
                                                   const std::vector<procedural::TraceRayArguments>& traceRay,
                                                   const procedural::Accuracy& accuracy,
                                                   const procedural::Effects& effects,
                                                   const std::optional<procedural::Perturbation>& perturbation,
                                                   const std::vector<procedural::TraceRayArguments>& defaults) {
    REFRAY_CHECK(precision == procedural::Precision::Float,
                 "the dxr-path-tracer shaders exist in float only (the GPU's precision); --precision double is for "
                 "the procedural libraries");
    REFRAY_CHECK(!perturbation, "the dxr-path-tracer shaders exist in nominal float only; --perturb is for the "
                                "procedural libraries");
    REFRAY_CHECK(traceRay == defaults, "the dxr-path-tracer shaders pass fixed TraceRay arguments (R = ray type, "
                                       "M = 2, miss index = ray type, mask 0xFF)");
    REFRAY_CHECK(accuracy.isDefault(), "the dxr-path-tracer shaders have no accuracy knobs (steps, thresholds, "
                                       "iterations, recursion-depth); its spp is --spp");
    REFRAY_CHECK(effects.isDefault(), "the dxr-path-tracer shaders have no effect switches");
    return procedural::pathtracer::makePathTracerShaderLibrary();
}

ShaderLibraryBinding pathTracerBinding() {
    namespace pt = procedural::pathtracer;
    ShaderLibraryBinding b;
    b.name = "dxr-path-tracer";
    b.description = "refray's DXR path tracer over OBJ models in global buffers (procedural/pathtracer/)";
    b.traceRayDefaults = {{pt::RayType::Radiance, pt::kGeometryStride, pt::RayType::Radiance, 0xFF},
                          {pt::RayType::Shadow, pt::kGeometryStride, pt::RayType::Shadow, 0xFF}};
    b.make = [defaults = b.traceRayDefaults](procedural::Precision p,
                                             const std::vector<procedural::TraceRayArguments>& traceRay,
                                             const procedural::Accuracy& accuracy, const procedural::Effects& effects,
                                             const std::optional<procedural::Perturbation>& perturbation) {
        return makePathTracer(p, traceRay, accuracy, effects, perturbation, defaults);
    };
    b.sceneConstants = pathTracerConstants;
    b.hasDebugFlag = true;
    b.debugFlagName = "debugMode";
    b.rayTypeCount = pt::RayType::Count;
    b.facts = pathTracerFacts();
    b.samplesInShader = true;
    b.maxSamplesPerPixel = 1u << 20;
    b.constantsKeys = {"backgroundColor", "maxBounces"};
    b.usesLight = false;
    b.configurable = false;
    return b;
}

ShaderLibraryBinding d3d12Binding() {
    ShaderLibraryBinding b;
    b.name = "d3d12-procedural-geometry";
    b.description = "Microsoft D3D12RaytracingProceduralGeometry Raytracing.hlsl (procedural/d3d12/)";
    b.make = [](procedural::Precision p, const std::vector<procedural::TraceRayArguments>& traceRay,
                const procedural::Accuracy& accuracy, const procedural::Effects& effects,
                const std::optional<procedural::Perturbation>& perturbation) {
        return procedural::d3d12::makeD3D12ShaderLibrary(p, argumentSet(traceRay, "d3d12-procedural-geometry"),
                                                         accuracy, effects, perturbation);
    };
    b.sceneConstants = d3d12Constants;
    b.hasDebugFlag = false;
    b.rayTypeCount = procedural::d3d12::RayType::Count;
    b.traceRayDefaults = perRayType(procedural::d3d12::defaultTraceRayArguments().rayTypes);
    b.facts = d3d12Facts();
    return b;
}

ShaderLibraryBinding procedurayBinding() {
    ShaderLibraryBinding b;
    b.name = "proceduray";
    b.description = "Proceduray MandelJuliaPac Raytracing.hlsl (procedural/proceduray/)";
    b.make = [](procedural::Precision p, const std::vector<procedural::TraceRayArguments>& traceRay,
                const procedural::Accuracy& accuracy, const procedural::Effects& effects,
                const std::optional<procedural::Perturbation>& perturbation) {
        return procedural::proceduray::makeProcedurayShaderLibrary(p, argumentSet(traceRay, "proceduray"), accuracy,
                                                                   effects, perturbation);
    };
    b.sceneConstants = procedurayConstants;
    b.hasDebugFlag = true;
    b.rayTypeCount = procedural::proceduray::RayTypeCount;
    b.traceRayDefaults = perRayType(procedural::proceduray::defaultTraceRayArguments().rayTypes);
    b.facts = procedurayFacts();
    return b;
}

}  // namespace

const std::vector<ShaderLibraryBinding>& shaderLibraries() {
    static const std::vector<ShaderLibraryBinding> libraries = {d3d12Binding(), pathTracerBinding(),
                                                                procedurayBinding()};
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
