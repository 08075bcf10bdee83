#include "core/fiber_local.h"

#include <atomic>

#include "core/error.h"

namespace refray {

namespace {
FiberLocal gLocals[kMaxFiberLocals];
std::atomic<size_t> gCount{0};
}  // namespace

bool registerFiberLocal(FiberLocal local) {
    const size_t slot = gCount.fetch_add(1);
    REFRAY_CHECK(slot < kMaxFiberLocals, "more than " << kMaxFiberLocals << " fiber-local values registered");
    gLocals[slot] = local;
    return true;
}

const FiberLocal* fiberLocals() { return gLocals; }
size_t fiberLocalCount() { return gCount.load(std::memory_order_relaxed); }

}  // namespace refray
