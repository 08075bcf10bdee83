// Wave calls (docs/emulator.md, "Waves"): a function of a shader that runs once over the lanes of a wave that call
// it together, as a GPU runs one function's instructions for every thread of a wave that reaches it. The lanes'
// shaders call it one lane at a time, each with its own state (inputs and outputs); the wave executor parks each
// calling lane and, when every lane of the wave is parked or done, runs the function once per group of lanes that
// called it with the same key, in calls of at most `lanesPerCall` lanes. It is for shader math that has no
// intrinsic inside, such as inline ray tracing's procedural intersection tests (RayQuery's candidates are the
// shader's own code, so no record groups them: the shader's key does).
#pragma once

#include <cstdint>
#include <span>

namespace refray::dxr {

// A function of one lane's state that also runs over several lanes' states at once: `run` gets the states of the
// lanes of one call (1 to lanesPerCall, in lane order) and writes each lane's outputs into its state. Each lane's
// outputs must be bit for bit what a call of that lane alone gives, so that no image depends on which lanes met:
// wave width, threads and tile order change nothing. It must not call intrinsics (it runs outside the lanes'
// shaders) or depend on anything but the states and the key.
struct WaveFunction {
    void (*run)(std::span<void* const> lanes) = nullptr;
    int lanesPerCall = 8;
};

// A wave call's grouping: lanes whose calls have the same function, context and value run together. The context
// is typically what the function reads beside the states (a library's constants); the value, what must be uniform
// over a call (a primitive type).
struct WaveCallKey {
    const void* context = nullptr;
    uint64_t value = 0;
    bool operator==(const WaveCallKey&) const = default;
};

// One lane's wave call, as a shader written for waves makes it for its lanes together (ShaderWave::CallInWave): what
// ShaderContext::callInWave takes.
struct WaveCall {
    const WaveFunction* function = nullptr;
    WaveCallKey key;
    void* state = nullptr;
};

}  // namespace refray::dxr
