// Fiber: a call stack of its own that a worker thread can leave and come back to. The wave executor
// (emulator/wave.h) runs each lane of a wave (one launch's ray generation shader and everything it calls) on a
// fiber, so that a lane that calls TraceRay can wait while the other lanes reach theirs; the wave then traverses
// their rays together. Switching is a handful of instructions (callee-saved registers, MXCSR and the x87 control
// word, the stack pointer) plus the registered fiber-local values (core/fiber_local.h); AddressSanitizer is told
// about every switch. What a switch's perf samples show is mostly the stall of the first touches of the other
// stack, not its instructions: a wave prefetches the stack of the lane it resumes next, and gives its lanes' stacks
// different colours (cache-set offsets).
#pragma once

#include <cstddef>
#include <exception>
#include <functional>

#include "core/fiber_local.h"

namespace refray::dxr {

class Fiber {
public:
    // A fiber whose stack holds `stackBytes` (reserved, not committed until used) plus a guard page. Its frames start
    // `colour` cache lines (at most 63) below the top of the stack: fibers whose stacks lie a multiple of the page
    // size apart would otherwise put their hottest frames in the same sets of the L1 cache (a wave gives each lane's
    // fiber a colour of its own).
    explicit Fiber(size_t stackBytes, unsigned colour = 0);
    static constexpr unsigned kColours = 64;  // the 64-byte lines of a 4 KiB page
    ~Fiber();
    Fiber(const Fiber&) = delete;
    Fiber& operator=(const Fiber&) = delete;

    // Makes `body` the fiber's work; it starts at the next resume(). The fiber must be idle (finished or new).
    void start(std::function<void()> body);
    // Runs the fiber until it yields or its body returns. An exception that leaves the body is rethrown here.
    void resume();
    // Asks the cache for the top of the fiber's saved stack, the frames resume() pops and returns into first. A wave
    // calls it for the lane it resumes next while the current one runs (no effect on what runs).
    void prefetch() const;
    // Called on a fiber: goes back to the resume() that entered it; returns when it is resumed again.
    static void yield();
    // Whether a started body has not returned yet.
    bool running() const { return running_; }
    // The fiber running on this thread, or null on the thread's own stack.
    static Fiber* current();

    // The default stack: deep enough for MaxTraceRecursionDepth 31 of nested shaders (more under AddressSanitizer,
    // whose redzones and fake frames grow every frame).
    static size_t defaultStackBytes();

private:
    static void entry(Fiber* self);
    void switchIn();
    void switchOut();

    void* stack_ = nullptr;  // the mapping, guard page first
    size_t mapped_ = 0;
    size_t colourBytes_ = 0;  // left free at the top of the stack
    void* fiberSp_ = nullptr;   // the fiber's saved stack pointer while it is not running
    void* callerSp_ = nullptr;  // the resumer's saved stack pointer while the fiber runs
    Fiber* previous_ = nullptr;  // the fiber (or null: the thread) that resumed this one
    std::function<void()> body_;
    std::exception_ptr failure_;
    bool running_ = false;
    void* locals_[kMaxFiberLocals] = {};        // the fiber's fiber-local values while it is not running
    void* callerLocals_[kMaxFiberLocals] = {};  // the resumer's, while the fiber runs
    // AddressSanitizer's view of the two stacks (unused without it).
    void* asanFakeStack_ = nullptr;
    const void* callerStackBottom_ = nullptr;
    size_t callerStackSize_ = 0;
};

}  // namespace refray::dxr
