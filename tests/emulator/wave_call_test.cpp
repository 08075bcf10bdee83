// Wave calls (emulator/wave_call.h, docs/emulator.md "Waves" item 5): a ray generation shader's function handed to
// the wave runs once per group of lanes that call it with the same key, in calls of at most lanesPerCall lanes, and
// each lane gets its own outputs back, whatever the wave width. A shader written for waves (emulator/shader_wave.h,
// here a compute shader: emulator/compute_wave.h) makes its lanes' calls together, in a loop (ShaderWave::CallsInLoop),
// with the same grouping and results.
#include <gtest/gtest.h>

#include <algorithm>
#include <mutex>
#include <set>

#include "core/error.h"
#include "dispatch_rig.h"
#include "emulator/compute_wave.h"

namespace refray::test {
namespace {

using dispatch_rig::Rig;

// What one call of the test function saw: the keys and launches of its lanes.
struct CallRecord {
    std::vector<uint32_t> keys;
    std::vector<uint32_t> launches;
};

struct Log {
    std::mutex mutex;
    std::vector<CallRecord> calls;
};

// One lane's state: its inputs (the launch, its key, the log) and its output.
struct LaneState {
    uint32_t launch = 0;
    uint32_t key = 0;
    Log* log = nullptr;
    uint32_t failOn = ~0u;  // a call that holds this launch throws
    uint32_t out = 0;
};

void runTestCalls(std::span<void* const> lanes) {
    CallRecord record;
    bool fail = false;
    for (void* p : lanes) {
        LaneState& s = *static_cast<LaneState*>(p);
        record.keys.push_back(s.key);
        record.launches.push_back(s.launch);
        s.out = s.launch * 3 + 1;  // each lane's own result, whoever it met
        fail = fail || s.launch == s.failOn;
    }
    Log& log = *static_cast<LaneState*>(lanes[0])->log;  // a call has at least one lane
    {
        const std::lock_guard<std::mutex> lock(log.mutex);
        log.calls.push_back(record);
    }
    if (fail) throw Error("the wave call failed on purpose");
}

// What the rigs below share: the dispatch rig, the calls' log and function, how many keys the calls spread over, the
// launch whose call fails, the grid and each launch's output.
struct CallRigParts {
    Rig r;
    Log log;
    WaveFunction function{runTestCalls, 8};
    uint32_t keys = 1;
    uint32_t failOn = ~0u;
    uvec2 grid;
    std::vector<uint32_t> outputs;
};

// A rig whose ray generation shader hands one wave call per launch to its wave (key: the launch's number, y * width
// + x, modulo `keys`) and writes the call's output to `outputs`. A 4x4 grid is one wave of 16 lanes (waves are 4x4
// blocks), in lane order of its numbers.
struct WaveCallRig : CallRigParts {

    explicit WaveCallRig(uvec2 size) {
        grid = size;
        outputs.assign(size_t(size.x) * size.y, 0u);
        r.rg = [this](ShaderContext& ctx) {
            LaneState s;
            s.launch = ctx.DispatchRaysIndex().y * grid.x + ctx.DispatchRaysIndex().x;
            s.key = s.launch % keys;
            s.log = &log;
            s.failOn = failOn;
            ctx.callInWave(function, WaveCallKey{&log, s.key}, &s);
            outputs[s.launch] = s.out;
        };
    }
    DispatchResult run(uint32_t width, DispatchOptions options = {}) {
        log.calls.clear();
        std::fill(outputs.begin(), outputs.end(), 0u);
        options.waveWidth = width;
        options.tileSize = 64;  // one tile: its waves hold `width` lanes
        return r.run({}, uvec3(grid, 1u), options);
    }
};

TEST(WaveCall, LanesWithTheSameKeyRunTogetherInCallsOfAtMostLanesPerCall) {
    WaveCallRig w(uvec2(4, 4));
    w.keys = 3;
    w.run(16);
    for (uint32_t i = 0; i < 16; ++i) EXPECT_EQ(w.outputs[i], i * 3 + 1) << "launch " << i;
    // One wave of 16 lanes, keys 0..2 (6, 5 and 5 lanes): one call per key, lanes in order, the group of key 0
    // (lane 0) first.
    ASSERT_EQ(w.log.calls.size(), 3u);
    for (uint32_t k = 0; k < 3; ++k) {
        const CallRecord& c = w.log.calls[k];
        EXPECT_TRUE(std::all_of(c.keys.begin(), c.keys.end(), [k](uint32_t key) { return key == k; }));
        EXPECT_TRUE(std::is_sorted(c.launches.begin(), c.launches.end()));
        EXPECT_EQ(c.launches.size(), k == 0 ? 6u : 5u);
    }
    // One key: 16 lanes run in two calls of lanesPerCall = 8; with lanesPerCall 4, in four.
    w.keys = 1;
    w.run(16);
    ASSERT_EQ(w.log.calls.size(), 2u);
    EXPECT_EQ(w.log.calls[0].launches, (std::vector<uint32_t>{0, 1, 2, 3, 4, 5, 6, 7}));
    EXPECT_EQ(w.log.calls[1].launches, (std::vector<uint32_t>{8, 9, 10, 11, 12, 13, 14, 15}));
    w.function.lanesPerCall = 4;
    w.run(16);
    ASSERT_EQ(w.log.calls.size(), 4u);
    for (const CallRecord& c : w.log.calls) EXPECT_EQ(c.launches.size(), 4u);
}

TEST(WaveCall, ALaneAloneRunsItsCallAtOnce) {
    WaveCallRig w(uvec2(5, 1));
    // Width 1, and an observed dispatch (which runs waves of one lane): five calls of one lane.
    w.run(1);
    ASSERT_EQ(w.log.calls.size(), 5u);
    for (const CallRecord& c : w.log.calls) EXPECT_EQ(c.launches.size(), 1u);
    DispatchOptions profiled;
    profiled.profileStages = true;
    w.run(16, profiled);
    EXPECT_EQ(w.log.calls.size(), 5u);
    for (uint32_t i = 0; i < 5; ++i) EXPECT_EQ(w.outputs[i], i * 3 + 1);
}

TEST(WaveCall, EveryWidthGivesEveryLaneItsOwnOutput) {
    WaveCallRig w(uvec2(37, 3));  // waves that do not divide the launches
    w.keys = 4;
    for (const uint32_t width : {1u, 3u, 8u, 16u}) {
        w.run(width);
        for (uint32_t i = 0; i < w.outputs.size(); ++i)
            EXPECT_EQ(w.outputs[i], i * 3 + 1) << "width " << width << ", launch " << i;
        size_t lanes = 0;
        for (const CallRecord& c : w.log.calls) {
            EXPECT_LE(c.launches.size(), std::min<size_t>(width, 8));
            lanes += c.launches.size();
        }
        EXPECT_EQ(lanes, w.outputs.size()) << "width " << width;
    }
}

TEST(WaveCall, GEN_1_AFailingCallStopsTheLaunchesOfItsLanes) {
    WaveCallRig w(uvec2(4, 4));
    w.keys = 2;    // even launches in one call, odd ones in another
    w.failOn = 5;  // the odd call fails: its first lane, launch 1, is the error's
    const Diagnostic d = expectDxrError("GEN-1", [&] { w.run(16); });
    EXPECT_NE(d.message.find("the wave call failed on purpose"), std::string::npos) << d.format();
    ASSERT_TRUE(d.site);
    EXPECT_EQ(d.site->launchIndex, uvec3(1, 0, 0));  // launch 1
    EXPECT_EQ(d.site->stage, ShaderStage::RayGeneration);
    // The even call's lanes got their outputs; the odd ones stopped in their call.
    EXPECT_EQ(w.outputs[0], 1u);
    for (uint32_t i = 1; i < 16; i += 2) EXPECT_EQ(w.outputs[i], 0u) << "launch " << i;
}

// A compute shader written for waves, "CSW" (numthreads(1, 1, 1): one thread per grid cell), whose lanes loop over
// wave calls together (ShaderWave::CallsInLoop): the thread of number n (y * width + x) makes n % 3 + 1 calls, one
// after another, call k with key (n + k) % keys, and writes the sum of their outputs, (n % 3 + 1) * (3n + 1), and the
// number of calls it made.
struct ComputeLoopRig : CallRigParts {
    std::vector<uint32_t> made;

    explicit ComputeLoopRig(uvec2 size) {
        grid = size;
        r.h.library->addWaveCompute("CSW", uvec3(1u), [this](ComputeWave& wave) {
            std::array<LaneState, kMaxWaveWidth> states{};
            std::array<uint32_t, kMaxWaveWidth> calls{}, sums{};
            wave.CallsInLoop(wave.active(), [&](int i, ShaderContext& ctx, WaveCall& call) {
                const uint32_t n = number(ctx);
                LaneState& s = states[size_t(i)];
                uint32_t& k = calls[size_t(i)];
                if (k > 0) sums[size_t(i)] += s.out;  // the last call's output
                if (k == n % 3 + 1) return false;
                s = LaneState{n, (n + k) % keys, &log, failOn, 0};
                ++k;
                call = WaveCall{&function, WaveCallKey{&log, s.key}, &s};
                return true;
            });
            wave.forEachLane([&](int i, ShaderContext& ctx) {
                outputs[number(ctx)] = sums[size_t(i)];
                made[number(ctx)] = calls[size_t(i)];
            });
        });
    }
    uint32_t number(ShaderContext& ctx) const { return ctx.DispatchThreadID().y * grid.x + ctx.DispatchThreadID().x; }
    DispatchResult run(uint32_t width) {
        if (!r.so) r.build();
        log.calls.clear();
        outputs.assign(size_t(grid.x) * grid.y, 0u);
        made.assign(outputs.size(), 0u);
        DispatchOptions options;
        options.waveWidth = width;
        options.tileSize = 64;  // one tile: its waves hold `width` lanes
        return r.h.device.dispatch(DispatchDesc{"CSW", grid.x, grid.y, 1}, r.so, nullptr, options);
    }
};

TEST(ShaderWave, LanesThatLoopOverWaveCallsMakeThemTogether) {
    ComputeLoopRig w(uvec2(37, 3));  // waves that do not divide the threads
    for (const uint32_t keys : {1u, 2u}) {
        w.keys = keys;
        for (const uint32_t width : {1u, 3u, 8u, 16u, 32u}) {
            const DispatchResult res = w.run(width);
            EXPECT_TRUE(res.diagnostics.empty()) << "width " << width;
            size_t lanes = 0, widest = 0;
            for (const CallRecord& c : w.log.calls) {
                EXPECT_LE(c.launches.size(), std::min<size_t>(width, 8)) << "width " << width;
                EXPECT_TRUE(std::is_sorted(c.launches.begin(), c.launches.end())) << "width " << width;
                EXPECT_TRUE(std::all_of(c.keys.begin(), c.keys.end(), [&c](uint32_t key) { return key == c.keys[0]; }));
                lanes += c.launches.size();
                widest = std::max(widest, c.launches.size());
            }
            size_t expectedLanes = 0;
            for (uint32_t n = 0; n < w.outputs.size(); ++n) {
                EXPECT_EQ(w.made[n], n % 3 + 1) << "width " << width << ", thread " << n;
                EXPECT_EQ(w.outputs[n], (n % 3 + 1) * (3 * n + 1)) << "width " << width << ", thread " << n;
                expectedLanes += n % 3 + 1;
            }
            EXPECT_EQ(lanes, expectedLanes) << "width " << width;
            // The lanes of a wave made their calls together: with one key, as many a call as lanesPerCall (8) and
            // the wave (at least 8 lanes from width 8 up: its 3 rows of the grid) allow; with two, several.
            if (keys == 1) EXPECT_EQ(widest, std::min<size_t>(width, 8)) << "width " << width;
            else if (width == 1) EXPECT_EQ(widest, 1u);
            else EXPECT_GT(widest, 1u) << "width " << width;
        }
    }
    // One wave of 16 threads, one key: the first round's 16 calls run in two calls of 8; the second round's (the
    // threads with n % 3 > 0: 10 of them) in one of 8 and one of 2; the third round's (n % 3 == 2: 5) in one.
    ComputeLoopRig one(uvec2(4, 4));
    one.run(16);
    std::vector<size_t> sizes;
    for (const CallRecord& c : one.log.calls) sizes.push_back(c.launches.size());
    EXPECT_EQ(sizes, (std::vector<size_t>{8, 8, 8, 2, 5}));
}

TEST(ShaderWave, GEN_1_AFailingWaveCallStopsOnlyItsLanes) {
    ComputeLoopRig w(uvec2(4, 4));
    w.keys = 2;    // in each round, lanes of one key call together
    w.failOn = 5;  // thread 5's first call fails (key 1: threads 1, 3, 5, ... of the first round)
    const Diagnostic d = expectDxrError("GEN-1", [&] { w.run(16); });
    EXPECT_NE(d.message.find("the wave call failed on purpose"), std::string::npos) << d.format();
    ASSERT_TRUE(d.site);
    EXPECT_EQ(d.site->launchIndex, uvec3(1, 0, 0));  // thread 1, the lowest of the failed call
    EXPECT_EQ(d.site->stage, ShaderStage::Compute);
    // The threads of the other key went on through all their calls; those of the failed call wrote nothing.
    for (uint32_t n = 0; n < 16; ++n) {
        if (n % 2 == 0) {
            EXPECT_EQ(w.outputs[n], (n % 3 + 1) * (3 * n + 1)) << "thread " << n;
        } else {
            EXPECT_EQ(w.outputs[n], 0u) << "thread " << n;
        }
    }
}

}  // namespace
}  // namespace refray::test
