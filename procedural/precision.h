// The scalar type a procedural shader library runs its internal math in (issue 3): Float is faithful to the
// GPU (float32, denormals flushed); Double is the accuracy oracle. Shader-visible structs stay float either way.
#pragma once

#include <optional>
#include <string_view>

#include "procedural/math/hlsl.h"

namespace refray::procedural {

enum class Precision { Float, Double };

constexpr std::string_view toString(Precision precision) {
    return precision == Precision::Double ? "double" : "float";
}

// "float" or "double" (the render-time option's spelling); anything else is empty.
constexpr std::optional<Precision> parsePrecision(std::string_view text) {
    if (text == "float") return Precision::Float;
    if (text == "double") return Precision::Double;
    return std::nullopt;
}

// Held for the duration of a shader entry point: float mode runs with denormals flushed, as D3D
// float32 arithmetic does (H18); the double oracle keeps them.
template <typename T>
struct PrecisionScope {};
template <>
struct PrecisionScope<float> {
    hlsl::ScopedFlushDenormals ftz;
};
// A wave's float lanes (procedural/math/lanes.h) flush as float does.
template <int N>
struct PrecisionScope<math::Lanes<float, N>> {
    hlsl::ScopedFlushDenormals ftz;
};

}  // namespace refray::procedural
