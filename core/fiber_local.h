// Thread-local values that belong to the code running on a fiber rather than to the thread: the wave executor
// (emulator/wave.h) runs several rays' shaders on one worker thread, each on its own fiber, and switches between
// them at every TraceRay. A value that a shader call installs for its duration (the perturbed arithmetic's
// context, procedural/math/perturbed.h) must follow the fiber, or one ray's scope would end another's. Such a value
// registers a getter and a setter once; the fiber switch saves the registered values of the fiber it leaves and
// puts back those of the fiber it enters. MXCSR (denormal flushing) is saved by the switch itself.
#pragma once

#include <cstddef>

namespace refray {

struct FiberLocal {
    void* (*get)();
    void (*set)(void*);
};

inline constexpr size_t kMaxFiberLocals = 4;

// Registers a fiber-local value (at static initialisation); returns true, for use as an initialiser.
bool registerFiberLocal(FiberLocal local);
// The registered values, and their number.
const FiberLocal* fiberLocals();
size_t fiberLocalCount();

}  // namespace refray
