// Effects a shader library can be built without (issue 8): what a scene file's "effects" block switches off
// (docs/scene-format.md). The default is the HLSL as written, so a library built with Effects{} renders
// bit-identical to one built without this argument.
//
// PORT: a switch removes a call site's work and returns what the HLSL itself returns when that call site is skipped
// (e.g. at MAX_RAY_RECURSION_DEPTH); it never changes the math of the shaders that still run. The other effect a
// scene can limit, the reflection depth, is the shaders' MAX_RAY_RECURSION_DEPTH: Accuracy::maxRecursionDepth.
#pragma once

#include <compare>

namespace refray::procedural {

// Whether the shadow call sites exist at all. The CMake option REFRAY_WITHOUT_SHADOW_MACHINERY compiles them out,
// as if the HLSL traced no shadow rays; it exists only for docs/performance.md's check that a scene with shadows
// switched off costs no more than a build without them.
#ifdef REFRAY_WITHOUT_SHADOW_MACHINERY
inline constexpr bool kShadowMachinery = false;
#else
inline constexpr bool kShadowMachinery = true;
#endif

struct Effects {
    // The closest hits' shadow rays. false: TraceShadowRayAndReportIfHit returns false ("not in shadow") without
    // tracing, exactly what it returns for a call at MAX_RAY_RECURSION_DEPTH, so every point counts as lit.
    bool traceShadowRays = true;

    friend auto operator<=>(const Effects&, const Effects&) = default;
    friend bool operator==(const Effects&, const Effects&) = default;
    bool isDefault() const { return *this == Effects{}; }
};

}  // namespace refray::procedural
