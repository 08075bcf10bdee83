// Deterministic random numbers keyed by (pixel, sample, bounce): never by thread or time.
#pragma once

#include <cstdint>

namespace refray {

// A stateless 32-bit hash (PCG output permutation); good avalanche, cheap.
inline uint32_t pcgHash(uint32_t v) {
    const uint32_t state = v * 747796405u + 2891336453u;
    const uint32_t word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// A small PCG32 stream seeded from a key; next() gives uniform floats in [0, 1).
class Random {
public:
    Random(uint32_t pixelLinear, uint32_t sample, uint32_t bounce, uint32_t seed = 0)
        : state_(pcgHash(pixelLinear ^ pcgHash(sample ^ pcgHash(bounce ^ pcgHash(seed))))) {}

    uint32_t nextUint() {
        state_ = state_ * 747796405u + 2891336453u;
        const uint32_t word = ((state_ >> ((state_ >> 28u) + 4u)) ^ state_) * 277803737u;
        return (word >> 22u) ^ word;
    }
    float nextFloat() { return float(nextUint() >> 8) * (1.0f / 16777216.0f); }

private:
    uint32_t state_;
};

}  // namespace refray
