// LDR-FLIP: the perceptual difference of two display-encoded images (Andersson et al.,
// "FLIP: A Difference Evaluator for Alternating Images", HPG 2020). docs/compare.md
// describes the pipeline and how this implementation was checked.
#pragma once

#include <cstdint>
#include <vector>

#include "core/image.h"

namespace refray {

// The paper's default observer: a 0.7 m wide 4K monitor seen from 0.7 m, about 67
// pixels per degree of visual angle.
inline constexpr double kFlipDefaultPixelsPerDegree = 67.0;

// One FLIP value per pixel, row-major, each in [0, 1] (0: no perceived difference).
struct FlipMap {
    uint32_t width = 0, height = 0;
    std::vector<float> error;

    float at(uint32_t x, uint32_t y) const { return error[size_t(y) * width + x]; }
};

// LDR-FLIP of `test` against `reference`. Both images' RGB values are taken as
// display-encoded sRGB in [0, 1], as an R8G8B8A8_UNORM target holds them: NaN reads as 0
// and values are clamped to [0, 1] first; alpha is ignored. Deterministic and
// single-threaded. Throws refray::Error when the sizes differ, an image is empty or
// pixelsPerDegree is not positive.
FlipMap computeFlip(const Image& reference, const Image& test,
                    double pixelsPerDegree = kFlipDefaultPixelsPerDegree);

// Summary of a FLIP map over the pixels it covers. Quartiles interpolate linearly
// between the two nearest ranks (rank p * (n - 1)); all zero when no pixel is covered.
struct FlipStats {
    double mean = 0, median = 0, firstQuartile = 0, thirdQuartile = 0, max = 0;
    uint64_t pixels = 0;  // pixels the statistics cover
};

// Statistics of `map` over every pixel, or over the pixels whose `include` entry is
// non-zero (`include` is row-major, one entry per pixel, or empty for all).
FlipStats flipStatistics(const FlipMap& map, const std::vector<uint8_t>& include = {});

// The "magma" colour ramp FLIP uses for its error maps: 0 black, through purple and
// orange, 1 pale yellow. t is clamped to [0, 1]; the result is display-encoded RGB.
vec3 magma(float t);

// The map as an opaque image through magma(), ready to write as PNG.
Image flipHeatMap(const FlipMap& map);

}  // namespace refray
