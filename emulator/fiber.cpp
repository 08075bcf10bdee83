// Fiber switching: x86-64 System V by hand (the callee-saved registers, MXCSR and the x87 control word are saved on
// the stack being left; its stack pointer is stored; the other stack's is loaded and the same values popped), the
// portable ucontext calls elsewhere.
#include "emulator/fiber.h"

#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstring>

#include "core/error.h"

// GCC says -fsanitize=address with __SANITIZE_ADDRESS__, clang (the fuzz preset) with __has_feature.
#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define REFRAY_FIBER_UNDER_ASAN 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__) || defined(REFRAY_FIBER_UNDER_ASAN)
#include <sanitizer/asan_interface.h>
#include <sanitizer/common_interface_defs.h>
#define REFRAY_FIBER_ASAN 1
#else
#define REFRAY_FIBER_ASAN 0
#endif

#if defined(__x86_64__) && defined(__linux__)
#define REFRAY_FIBER_X86_64 1
extern "C" void refray_fiber_switch(void** saveSp, void* loadSp);
extern "C" void refray_fiber_trampoline();
asm(R"(
    .text
    .globl refray_fiber_switch
    .type refray_fiber_switch, @function
    .p2align 4
refray_fiber_switch:
    pushq %rbp
    pushq %rbx
    pushq %r12
    pushq %r13
    pushq %r14
    pushq %r15
    subq $16, %rsp
    stmxcsr 8(%rsp)
    fnstcw (%rsp)
    movl 8(%rsp), %eax
    movzwl (%rsp), %ecx
    movq %rsp, (%rdi)
    movq %rsi, %rsp
    cmpl 8(%rsp), %eax
    je 1f
    ldmxcsr 8(%rsp)
1:
    cmpw (%rsp), %cx
    je 2f
    fldcw (%rsp)
2:
    addq $16, %rsp
    popq %r15
    popq %r14
    popq %r13
    popq %r12
    popq %rbx
    popq %rbp
    ret
    .size refray_fiber_switch, .-refray_fiber_switch

    .globl refray_fiber_trampoline
    .type refray_fiber_trampoline, @function
    .p2align 4
refray_fiber_trampoline:
    .cfi_startproc
    .cfi_undefined rip
    movq %r12, %rdi
    callq *%r13
    ud2
    .cfi_endproc
    .size refray_fiber_trampoline, .-refray_fiber_trampoline
)");
#else
#define REFRAY_FIBER_X86_64 0
#error "refray's fibers switch stacks by hand on x86-64 Linux only"
#endif

namespace refray::dxr {

namespace {

thread_local Fiber* tCurrentFiber = nullptr;

size_t pageSize() { return size_t(sysconf(_SC_PAGESIZE)); }

constexpr size_t kCacheLine = 64;
// How much of a fiber's stack prefetch() asks for: the frames a lane's resume returns through (the fiber switch,
// TraceRay's wait and TraceRay, about 2 KB); 4 KB measured the same or a little worse (docs/performance.md).
constexpr size_t kPrefetchBytes = 2048;

void saveLocals(void** into) {
    const FiberLocal* locals = fiberLocals();
    for (size_t i = 0, n = fiberLocalCount(); i < n; ++i) into[i] = locals[i].get();
}
// Saves the values now in place into `saveInto` and puts those of `loadFrom` in their place; a value that is already
// in place (a float render's perturbation context: none on every fiber) is not set again.
void swapLocals(void** saveInto, void* const* loadFrom) {
    const FiberLocal* locals = fiberLocals();
    for (size_t i = 0, n = fiberLocalCount(); i < n; ++i) {
        void* const now = locals[i].get();
        if (now != loadFrom[i]) locals[i].set(loadFrom[i]);
        saveInto[i] = now;
    }
}

}  // namespace

size_t Fiber::defaultStackBytes() { return REFRAY_FIBER_ASAN ? size_t(16) << 20 : size_t(2) << 20; }

Fiber::Fiber(size_t stackBytes, unsigned colour) {
    const size_t page = pageSize();
    REFRAY_CHECK(colour < kColours, "fiber stack colour " << colour << " is outside 0.." << kColours - 1);
    colourBytes_ = size_t(colour) * kCacheLine;
    mapped_ = (stackBytes + page - 1) / page * page + page;
    stack_ = mmap(nullptr, mapped_, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
    REFRAY_CHECK(stack_ != MAP_FAILED, "cannot map a fiber stack of " << mapped_ << " bytes: " << std::strerror(errno));
    mprotect(stack_, page, PROT_NONE);  // the guard page: an overflow faults instead of writing past the stack
}

Fiber::~Fiber() {
    if (stack_ && stack_ != MAP_FAILED) munmap(stack_, mapped_);
}

Fiber* Fiber::current() { return tCurrentFiber; }

void Fiber::start(std::function<void()> body) {
    REFRAY_CHECK(!running_, "a fiber was started while its previous body was still running");
    body_ = std::move(body);
    failure_ = nullptr;
    running_ = true;
    const size_t page = pageSize();
    char* const bottom = static_cast<char*>(stack_) + page;
    const size_t usable = mapped_ - page;
#if REFRAY_FIBER_ASAN
    // A body that ended its previous run left the shadow of the frames that never returned: entry() and the switch
    // out of it, at the top of the stack (every frame below them returned, or was unwound by an exception, which
    // AddressSanitizer cleans). Unpoisoning just the top keeps a launch from paying for the whole stack's shadow
    // (2 MiB for a 16 MiB stack).
    const size_t leftPoisoned = std::min(usable, size_t(64) << 10);
    __asan_unpoison_memory_region(bottom + usable - leftPoisoned, leftPoisoned);
#endif
    // The first switch into the fiber pops this frame and "returns" into the trampoline, which calls entry(this)
    // with the stack 16-byte aligned at the call.
    const uintptr_t afterReturn = (reinterpret_cast<uintptr_t>(bottom + usable) - 64 - colourBytes_) & ~uintptr_t(15);
    auto* frame = reinterpret_cast<uint64_t*>(afterReturn - 9 * sizeof(uint64_t));
    uint32_t mxcsr = 0;
    uint16_t fpuControl = 0;
    asm volatile("stmxcsr %0" : "=m"(mxcsr));
    asm volatile("fnstcw %0" : "=m"(fpuControl));
    frame[0] = fpuControl;
    frame[1] = mxcsr;
    frame[2] = 0;                                                      // r15
    frame[3] = 0;                                                      // r14
    frame[4] = reinterpret_cast<uint64_t>(&Fiber::entry);              // r13: what the trampoline calls
    frame[5] = reinterpret_cast<uint64_t>(this);                       // r12: its argument
    frame[6] = 0;                                                      // rbx
    frame[7] = 0;                                                      // rbp
    frame[8] = reinterpret_cast<uint64_t>(&refray_fiber_trampoline);  // the return address
    fiberSp_ = frame;
    // The fiber starts with the fiber-local values its starter has now.
    saveLocals(locals_);
}

void Fiber::prefetch() const {
    // The frames above the saved stack pointer, up to the top of the stack: what the fiber pops and returns into.
    const char* from = static_cast<const char*>(fiberSp_);
    const char* top = static_cast<const char*>(stack_) + mapped_;
    const char* to = std::min(top, from + kPrefetchBytes);
    for (const char* line = from; line < to; line += kCacheLine) __builtin_prefetch(line, 1, 3);
}

void Fiber::resume() {
    REFRAY_CHECK(running_, "a fiber was resumed with no body to run");
    previous_ = tCurrentFiber;
    tCurrentFiber = this;
    swapLocals(callerLocals_, locals_);
#if REFRAY_FIBER_ASAN
    void* callerFakeStack = nullptr;
    const size_t page = pageSize();
    __sanitizer_start_switch_fiber(&callerFakeStack, static_cast<char*>(stack_) + page, mapped_ - page);
#endif
    refray_fiber_switch(&callerSp_, fiberSp_);
#if REFRAY_FIBER_ASAN
    __sanitizer_finish_switch_fiber(callerFakeStack, nullptr, nullptr);
#endif
    swapLocals(locals_, callerLocals_);
    tCurrentFiber = previous_;
    if (!running_ && failure_) {
        std::exception_ptr failure = std::move(failure_);
        failure_ = nullptr;
        std::rethrow_exception(failure);
    }
}

void Fiber::yield() {
    Fiber* self = tCurrentFiber;
    REFRAY_CHECK(self, "Fiber::yield outside a fiber");
    self->switchOut();
}

void Fiber::switchOut() {
#if REFRAY_FIBER_ASAN
    __sanitizer_start_switch_fiber(running_ ? &asanFakeStack_ : nullptr, callerStackBottom_, callerStackSize_);
#endif
    refray_fiber_switch(&fiberSp_, callerSp_);
    switchIn();
}

void Fiber::switchIn() {
#if REFRAY_FIBER_ASAN
    __sanitizer_finish_switch_fiber(asanFakeStack_, &callerStackBottom_, &callerStackSize_);
#endif
}

void Fiber::entry(Fiber* self) {
    self->asanFakeStack_ = nullptr;
    self->switchIn();
    try {
        self->body_();
    } catch (...) {
        self->failure_ = std::current_exception();
    }
    self->body_ = nullptr;
    self->running_ = false;
    // Back to the resumer for good: start() builds a new first frame before the fiber runs again.
    self->switchOut();
    __builtin_trap();
}

}  // namespace refray::dxr
