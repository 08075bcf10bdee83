// LaneSlots: one T per lane of a wave, made only for the lanes that use it. A wave's per-lane scratch (a TraceRay's
// ray states and payload copies, its closest hits' records and invocations) then costs what its lanes use, not
// kMaxWaveWidth value-initialisations each time (docs/performance.md, "Per-lane scratch"). Internal to the emulator.
#pragma once

#include <array>
#include <cstddef>
#include <new>
#include <utility>

#include "core/error.h"
#include "emulator/lane_mask.h"

namespace refray::dxr::detail {

template <class T>
class LaneSlots {
public:
    LaneSlots() = default;
    LaneSlots(const LaneSlots&) = delete;
    LaneSlots& operator=(const LaneSlots&) = delete;
    ~LaneSlots() {
        for (int lane : made_) (*this)[lane].~T();
    }

    // Lane `lane`'s T, made from `args`; once per lane.
    template <class... Args>
    T& emplace(int lane, Args&&... args) {
        REFRAY_ASSERT(!made_.test(lane), "lane " << lane << "'s slot is made twice");
        T* made = ::new (static_cast<void*>(slots_[size_t(lane)].bytes)) T(std::forward<Args>(args)...);
        made_.set(lane);
        return *made;
    }
    // Lane `lane`'s T, which emplace made.
    T& operator[](int lane) { return *std::launder(reinterpret_cast<T*>(slots_[size_t(lane)].bytes)); }
    const T& operator[](int lane) const {
        return *std::launder(reinterpret_cast<const T*>(slots_[size_t(lane)].bytes));
    }

private:
    struct Slot {
        alignas(T) std::byte bytes[sizeof(T)];
    };
    std::array<Slot, kMaxWaveWidth> slots_;
    LaneMask made_;
};

}  // namespace refray::dxr::detail
