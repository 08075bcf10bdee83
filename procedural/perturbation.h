// The perturbed arithmetic a procedural shader library can run in (issue 17): float32 computed as one GPU that the
// specs allow, picked by a seed. docs/numerical-variation.md states the variation model, with its sources;
// procedural/math/perturbed.h implements it. Shader-visible structs stay float.
#pragma once

#include <compare>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace refray::procedural {

// The model the perturbed arithmetic draws from (docs/numerical-variation.md); renders and goldens record it.
inline constexpr std::string_view kVariationModel = "variation model v1";

// Whether a*b + c, written as a multiply and an add, is computed with one rounding (D3D11.3 §3.1.3.2 on fused
// operations, §22.19.2 precise): never, always, or per operation as the seed decides.
enum class Contraction : uint8_t { Split, Fuse, Mixed };

// Denormal float32 inputs and results: flushed to zero (D3D11.3 §3.1.3.2), or kept (DXIL's default fp32-denorm-mode
// "any", shader model 6.2 and later).
enum class Denormals : uint8_t { Flush, Preserve };

struct Perturbation {
    // Picks the GPU: every inexact operation's error is a pure function of this seed and the operation's operands.
    uint64_t seed = 0;
    Contraction contraction = Contraction::Mixed;
    Denormals denormals = Denormals::Flush;

    friend auto operator<=>(const Perturbation&, const Perturbation&) = default;
    friend bool operator==(const Perturbation&, const Perturbation&) = default;
};

constexpr std::string_view toString(Contraction contraction) {
    switch (contraction) {
        case Contraction::Split: return "split";
        case Contraction::Fuse: return "fuse";
        case Contraction::Mixed: return "mixed";
    }
    return "mixed";
}

constexpr std::string_view toString(Denormals denormals) {
    return denormals == Denormals::Preserve ? "preserve" : "flush";
}

// "seed 7, contraction mixed, denormals flush (variation model v1)": what a render's metadata records.
inline std::string describe(const Perturbation& p) {
    return "seed " + std::to_string(p.seed) + ", contraction " + std::string(toString(p.contraction)) +
           ", denormals " + std::string(toString(p.denormals)) + " (" + std::string(kVariationModel) + ")";
}

// "split", "fuse" or "mixed"; anything else is empty.
constexpr std::optional<Contraction> parseContraction(std::string_view text) {
    for (const Contraction c : {Contraction::Split, Contraction::Fuse, Contraction::Mixed})
        if (text == toString(c)) return c;
    return std::nullopt;
}

// "flush" or "preserve"; anything else is empty.
constexpr std::optional<Denormals> parseDenormals(std::string_view text) {
    if (text == "flush") return Denormals::Flush;
    if (text == "preserve") return Denormals::Preserve;
    return std::nullopt;
}

}  // namespace refray::procedural
