// The constant arguments a shader library passes to TraceRay, per ray type. In the HLSL they are compile-time
// constants (ShaderCompat.h / RayTracingHlslCompat.h); here a library is built with them, so a scene file can
// reproduce a shader compiled with other constants (e.g. a multiplier of 1 with two ray types) without editing code.
#pragma once

#include <array>
#include <cstdint>

namespace refray::procedural {

// The arguments of one TraceRay call site besides the flags, the ray and the payload. The shaders pass them as
// given; DXR then uses the low 4 bits of R and M (IDX-2, the emulator warns about the rest), the low 16 bits of
// MissShaderIndex (IDX-7) and the low 8 bits of InstanceInclusionMask (INST-4).
struct TraceRayArguments {
    uint32_t rayContribution = 0;          // RayContributionToHitGroupIndex (R of I = R + M*G + C, IDX-1)
    uint32_t multiplier = 0;               // MultiplierForGeometryContributionToHitGroupIndex (M)
    uint32_t missShaderIndex = 0;          // MissShaderIndex (IDX-7)
    uint32_t instanceInclusionMask = ~0u;  // InstanceInclusionMask (INST-4)

    friend bool operator==(const TraceRayArguments&, const TraceRayArguments&) = default;
};

// A library's TraceRay arguments, indexed by ray type: radiance (0) and shadow (1), the two ray types both reference
// libraries trace. Each library's defaultTraceRayArguments() gives exactly what its HLSL passes.
inline constexpr uint32_t kTraceRayTypeCount = 2;
struct TraceRayArgumentSet {
    std::array<TraceRayArguments, kTraceRayTypeCount> rayTypes{};

    constexpr const TraceRayArguments& operator[](uint32_t rayType) const { return rayTypes[rayType]; }
    constexpr TraceRayArguments& operator[](uint32_t rayType) { return rayTypes[rayType]; }
    friend bool operator==(const TraceRayArgumentSet&, const TraceRayArgumentSet&) = default;
};

}  // namespace refray::procedural
