// Fibers (emulator/fiber.h): the floating-point control state follows the code that set it, and a stack colour and a
// prefetch move where the frames lie but not what runs. The switches go between fibers whose MXCSR values differ and
// between fibers whose values are equal, so a switch that skipped a load it needs would show, and each side's
// values are checked after every switch.
#include <gtest/gtest.h>
#include <xmmintrin.h>

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <vector>

#include "emulator/fiber.h"

namespace refray::dxr {
namespace {

constexpr uint32_t kFlushDenormals = 0x8040u;  // MXCSR's FTZ (bit 15) and DAZ (bit 6)
constexpr uint32_t kRoundTowardZero = 0x6000u;  // MXCSR's rounding control = 11
constexpr uintptr_t kCacheLine = 64;
constexpr uintptr_t kPage = kCacheLine * Fiber::kColours;  // the span of the colours: a 4 KiB page

uint16_t x87Control() {
    uint16_t cw = 0;
    asm volatile("fnstcw %0" : "=m"(cw));
    return cw;
}
void setX87Control(uint16_t cw) { asm volatile("fldcw %0" : : "m"(cw)); }

// Restores the thread's MXCSR and x87 control word when a test ends, whatever it left.
struct ControlStateGuard {
    uint32_t mxcsr = _mm_getcsr();
    uint16_t x87 = x87Control();
    ~ControlStateGuard() {
        _mm_setcsr(mxcsr);
        setX87Control(x87);
    }
};

TEST(Fiber, MxcsrFollowsTheFiberThatSetIt) {
    ControlStateGuard guard;
    const uint32_t outside = _mm_getcsr();
    Fiber fiber(Fiber::defaultStackBytes());
    std::vector<uint32_t> seenInside;
    fiber.start([&] {
        seenInside.push_back(_mm_getcsr());  // the starter's value
        _mm_setcsr(outside | kFlushDenormals);
        Fiber::yield();
        seenInside.push_back(_mm_getcsr());  // its own value again, after the resumer changed its own
        Fiber::yield();
        seenInside.push_back(_mm_getcsr());
    });
    fiber.resume();
    EXPECT_EQ(_mm_getcsr(), outside) << "the fiber's MXCSR leaked into its resumer";
    _mm_setcsr(outside | kRoundTowardZero);
    fiber.resume();
    EXPECT_EQ(_mm_getcsr(), outside | kRoundTowardZero) << "the resumer lost its own MXCSR";
    _mm_setcsr(outside);
    fiber.resume();
    EXPECT_FALSE(fiber.running());
    EXPECT_EQ(_mm_getcsr(), outside);
    ASSERT_EQ(seenInside.size(), 3u);
    EXPECT_EQ(seenInside[0], outside);
    EXPECT_EQ(seenInside[1], outside | kFlushDenormals);
    EXPECT_EQ(seenInside[2], outside | kFlushDenormals);
}

TEST(Fiber, X87ControlWordFollowsTheFiberThatSetIt) {
    ControlStateGuard guard;
    const uint16_t outside = x87Control();
    const uint16_t single = uint16_t(outside & ~0x0300u);  // precision control: 24-bit mantissa
    Fiber fiber(Fiber::defaultStackBytes());
    std::vector<uint16_t> seenInside;
    fiber.start([&] {
        seenInside.push_back(x87Control());
        setX87Control(single);
        Fiber::yield();
        seenInside.push_back(x87Control());
    });
    fiber.resume();
    EXPECT_EQ(x87Control(), outside);
    fiber.resume();
    EXPECT_EQ(x87Control(), outside);
    ASSERT_EQ(seenInside.size(), 2u);
    EXPECT_EQ(seenInside[0], outside);
    EXPECT_EQ(seenInside[1], single);
}

TEST(Fiber, InterleavedFibersEachKeepTheirOwnControlState) {
    // A wave's lanes: several fibers resumed in turn, some with the thread's values and some with their own, so the
    // switch meets both equal and differing values in both directions.
    ControlStateGuard guard;
    const uint32_t outside = _mm_getcsr();
    constexpr int kFibers = 4;
    constexpr int kRounds = 5;
    std::vector<std::unique_ptr<Fiber>> fibers;
    std::vector<int> wrong(kFibers, 0);
    for (int f = 0; f < kFibers; ++f) {
        fibers.push_back(std::make_unique<Fiber>(Fiber::defaultStackBytes()));
        const uint32_t own = (f % 2) ? (outside | kFlushDenormals) : outside;
        fibers.back()->start([&wrong, f, own] {
            _mm_setcsr(own);
            for (int round = 0; round < kRounds; ++round) {
                Fiber::yield();
                if (_mm_getcsr() != own) ++wrong[size_t(f)];
            }
        });
    }
    for (int round = 0; round <= kRounds; ++round)
        for (auto& fiber : fibers) {
            fiber->resume();
            EXPECT_EQ(_mm_getcsr(), outside) << "round " << round;
        }
    for (int f = 0; f < kFibers; ++f) {
        EXPECT_FALSE(fibers[size_t(f)]->running());
        EXPECT_EQ(wrong[size_t(f)], 0) << "fiber " << f << " found another's MXCSR after a switch";
    }
}

TEST(Fiber, AnExceptionLeavingTheBodyReachesTheResumerWithItsControlState) {
    ControlStateGuard guard;
    const uint32_t outside = _mm_getcsr();
    Fiber fiber(Fiber::defaultStackBytes());
    fiber.start([&] {
        _mm_setcsr(outside | kFlushDenormals);
        throw std::runtime_error("stopped");
    });
    EXPECT_THROW(fiber.resume(), std::runtime_error);
    EXPECT_EQ(_mm_getcsr(), outside);
    EXPECT_FALSE(fiber.running());
}

TEST(Fiber, AColourMovesTheFramesThatManyLinesDownAndPrefetchChangesNothing) {
    // A wave gives each lane's stack a colour (its frames start that many cache lines below the top) and prefetches
    // the next lane's stack before resuming it. The same body at the same depth on stacks of every colour: its frame
    // lies 64 * colour bytes lower within the page, and the body runs the same with prefetches before each resume.
    const auto localOffset = [](unsigned colour, bool prefetch) {
        Fiber fiber(Fiber::defaultStackBytes(), colour);
        uintptr_t at = 0;
        int steps = 0;
        fiber.start([&] {
            at = reinterpret_cast<uintptr_t>(__builtin_frame_address(0));  // the real stack, sanitizers or not
            ++steps;
            Fiber::yield();
            ++steps;
        });
        if (prefetch) fiber.prefetch();
        fiber.resume();
        if (prefetch) fiber.prefetch();
        fiber.resume();
        EXPECT_FALSE(fiber.running());
        EXPECT_EQ(steps, 2) << "colour " << colour;
        return at % kPage;
    };
    const uintptr_t plain = localOffset(0, false);
    for (unsigned colour = 0; colour < Fiber::kColours; ++colour) {
        const uintptr_t got = localOffset(colour, colour % 2 == 1);
        EXPECT_EQ((plain + kPage - got) % kPage, kCacheLine * colour) << "colour " << colour;
    }
}

TEST(Fiber, AColourBeyondAPageIsRefused) {
    EXPECT_THROW(Fiber(Fiber::defaultStackBytes(), Fiber::kColours), std::exception);
}

}  // namespace
}  // namespace refray::dxr
