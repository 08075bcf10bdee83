#include "emulator/types.h"

#include <cstdio>
#include <string>
#include <utility>

namespace refray::dxr {

std::string_view toString(ShaderStage stage) {
    switch (stage) {
        case ShaderStage::RayGeneration: return "raygeneration";
        case ShaderStage::Intersection: return "intersection";
        case ShaderStage::AnyHit: return "anyhit";
        case ShaderStage::ClosestHit: return "closesthit";
        case ShaderStage::Miss: return "miss";
        case ShaderStage::Callable: return "callable";
        case ShaderStage::Compute: return "compute";
    }
    return "unknown";
}

namespace {

template <size_t N>
std::string flagsToString(uint32_t flags, const std::pair<uint32_t, const char*> (&names)[N], const char* none) {
    if (flags == 0) return none;
    std::string out;
    for (const auto& [bit, name] : names) {
        if (flags & bit) {
            if (!out.empty()) out += '|';
            out += name;
            flags &= ~bit;
        }
    }
    if (flags) {
        char hex[24];
        std::snprintf(hex, sizeof hex, "0x%X", flags);
        if (!out.empty()) out += '|';
        out += hex;
    }
    return out;
}

}  // namespace

std::string rayFlagsToString(uint32_t flags) {
    static const std::pair<uint32_t, const char*> names[] = {
        {RAY_FLAG_FORCE_OPAQUE, "FORCE_OPAQUE"},
        {RAY_FLAG_FORCE_NON_OPAQUE, "FORCE_NON_OPAQUE"},
        {RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH, "ACCEPT_FIRST_HIT_AND_END_SEARCH"},
        {RAY_FLAG_SKIP_CLOSEST_HIT_SHADER, "SKIP_CLOSEST_HIT_SHADER"},
        {RAY_FLAG_CULL_BACK_FACING_TRIANGLES, "CULL_BACK_FACING_TRIANGLES"},
        {RAY_FLAG_CULL_FRONT_FACING_TRIANGLES, "CULL_FRONT_FACING_TRIANGLES"},
        {RAY_FLAG_CULL_OPAQUE, "CULL_OPAQUE"},
        {RAY_FLAG_CULL_NON_OPAQUE, "CULL_NON_OPAQUE"},
        {RAY_FLAG_SKIP_TRIANGLES, "SKIP_TRIANGLES"},
        {RAY_FLAG_SKIP_PROCEDURAL_PRIMITIVES, "SKIP_PROCEDURAL_PRIMITIVES"},
    };
    return flagsToString(flags, names, "NONE");
}

std::string instanceFlagsToString(uint32_t flags) {
    static const std::pair<uint32_t, const char*> names[] = {
        {INSTANCE_FLAG_TRIANGLE_CULL_DISABLE, "TRIANGLE_CULL_DISABLE"},
        {INSTANCE_FLAG_TRIANGLE_FRONT_COUNTERCLOCKWISE, "TRIANGLE_FRONT_COUNTERCLOCKWISE"},
        {INSTANCE_FLAG_FORCE_OPAQUE, "FORCE_OPAQUE"},
        {INSTANCE_FLAG_FORCE_NON_OPAQUE, "FORCE_NON_OPAQUE"},
    };
    return flagsToString(flags, names, "NONE");
}

std::string geometryFlagsToString(uint32_t flags) {
    static const std::pair<uint32_t, const char*> names[] = {
        {GEOMETRY_FLAG_OPAQUE, "OPAQUE"},
        {GEOMETRY_FLAG_NO_DUPLICATE_ANYHIT_INVOCATION, "NO_DUPLICATE_ANYHIT_INVOCATION"},
    };
    return flagsToString(flags, names, "NONE");
}

std::string pipelineFlagsToString(uint32_t flags) {
    static const std::pair<uint32_t, const char*> names[] = {
        {PIPELINE_FLAG_SKIP_TRIANGLES, "SKIP_TRIANGLES"},
        {PIPELINE_FLAG_SKIP_PROCEDURAL_PRIMITIVES, "SKIP_PROCEDURAL_PRIMITIVES"},
    };
    return flagsToString(flags, names, "NONE");
}

}  // namespace refray::dxr
