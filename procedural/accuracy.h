// Accuracy knobs of the procedural shader libraries (issue 7): the constants of the HLSL marches that trade error
// for time, made settable so `refray sweep` can show what each one buys. The defaults are exactly the HLSL's
// constants, so a library built with Accuracy{} renders bit-identical to the port without knobs.
//
// PORT: every knob replaces a compile-time constant of the HLSL; a library built with other values is the shader
// recompiled with other constants, not a different algorithm.
#pragma once

#include <compare>
#include <cstdint>
#include <optional>

namespace refray::procedural {

struct Accuracy {
    // Multiplies every march's step limit: the SDF sphere tracing (512 in both libraries), Julia's 1024 march steps
    // and the Mandelbulb's animated step count iMax. The product is rounded to the nearest integer, at least 1.
    double stepsFactor = 1.0;
    // Multiplies every hit threshold: the SDF `distance <= 1e-4 * t`, the Mandelbulb's `h < 1e-4 * t` and Julia's
    // precis 0.00025 (its march stop; tmin and the secant-step gate stay as they are).
    double thresholdFactor = 1.0;
    // Iterations of the fractal formulas: the Mandelbulb DE's power-8 loop (4) and Julia's jdist loop (200,
    // also used by its normal). Unset: the HLSL's.
    std::optional<uint32_t> mandelbulbIterations;
    std::optional<uint32_t> juliaIterations;
    // Multiplies every normal-estimation offset: the tetrahedral offsets (SDF, Mandelbulb, Julia) and the
    // metaballs' central-difference step.
    double normalEpsilonFactor = 1.0;
    // Samples of the metaballs' fixed-step march (128). Unset: the HLSL's.
    std::optional<uint32_t> metaballSteps;
    // MAX_RAY_RECURSION_DEPTH of the shaders (3 in both libraries): how deep reflection rays recurse. The scene
    // raises the pipeline's MaxTraceRecursionDepth to match. Unset: the HLSL's.
    std::optional<uint32_t> maxRecursionDepth;

    friend auto operator<=>(const Accuracy&, const Accuracy&) = default;
    friend bool operator==(const Accuracy&, const Accuracy&) = default;
    bool isDefault() const { return *this == Accuracy{}; }
};

// A step limit times stepsFactor: rounded to nearest, at least 1, at most 2^31 - 1 (the HLSL loops count in int).
inline uint32_t scaledSteps(uint32_t hlslSteps, double stepsFactor) {
    const double steps = double(hlslSteps) * stepsFactor + 0.5;
    if (!(steps >= 1.0)) return 1;
    return steps >= 2147483647.0 ? 2147483647u : uint32_t(steps);
}

// A constant of the HLSL, already in the shader's scalar type T, times a factor rounded to T: the constant itself,
// bit for bit, when the factor is 1 (the shader libraries scale thresholds and normal offsets with it).
template <typename T>
T scaledConstant(T hlslValue, double factor) {
    return factor == 1.0 ? hlslValue : hlslValue * static_cast<T>(factor);
}

// A count for one of the HLSL's int loop counters: at most 2^31 - 1.
inline int hlslLoopCount(uint32_t count) { return count >= 2147483647u ? 2147483647 : int(count); }

}  // namespace refray::procedural
