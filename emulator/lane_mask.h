// LaneMask: which lanes of a wave (emulator/wave.h) take part in a step: the lanes whose rays wait for traversal, the
// lanes of one record group, the lanes an intersection shader still runs for. One bit per lane, lane 0 lowest.
#pragma once

#include <bit>
#include <cstdint>

namespace refray::dxr {

// The widest wave, and the default: 32 lanes (docs/emulator.md, "Waves": the width a wave's record groups and march
// queues batch over; the SIMD math runs in 8-float lanes whatever the width).
inline constexpr int kMaxWaveWidth = 32;

class LaneMask {
public:
    constexpr LaneMask() = default;
    constexpr explicit LaneMask(uint32_t bits) : bits_(bits) {}
    // Lanes 0 .. count-1.
    static constexpr LaneMask first(int count) {
        return LaneMask(count >= 32 ? ~0u : (uint32_t(1) << count) - 1u);
    }
    static constexpr LaneMask only(int lane) { return LaneMask(uint32_t(1) << lane); }

    constexpr bool test(int lane) const { return (bits_ >> lane) & 1u; }
    constexpr void set(int lane) { bits_ |= uint32_t(1) << lane; }
    constexpr void clear(int lane) { bits_ &= ~(uint32_t(1) << lane); }
    constexpr bool empty() const { return bits_ == 0; }
    constexpr bool any() const { return bits_ != 0; }
    constexpr int count() const { return std::popcount(bits_); }
    constexpr int lowest() const { return std::countr_zero(bits_); }  // 32 when empty
    constexpr uint32_t bits() const { return bits_; }
    constexpr bool operator==(const LaneMask&) const = default;

    // for (int lane : mask): the set lanes in increasing order.
    class Iterator {
    public:
        constexpr explicit Iterator(uint32_t bits) : bits_(bits) {}
        constexpr int operator*() const { return std::countr_zero(bits_); }
        constexpr Iterator& operator++() {
            bits_ &= bits_ - 1u;
            return *this;
        }
        constexpr bool operator!=(const Iterator& other) const { return bits_ != other.bits_; }

    private:
        uint32_t bits_;
    };
    constexpr Iterator begin() const { return Iterator(bits_); }
    constexpr Iterator end() const { return Iterator(0); }

private:
    uint32_t bits_ = 0;
};

}  // namespace refray::dxr
