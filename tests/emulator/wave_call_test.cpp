// Wave calls (emulator/wave_call.h, docs/emulator.md "Waves" item 5): a ray generation shader's function handed to
// the wave runs once per group of lanes that call it with the same key, in calls of at most lanesPerCall lanes, and
// each lane gets its own outputs back, whatever the wave width.
#include <gtest/gtest.h>

#include <algorithm>
#include <mutex>
#include <set>

#include "core/error.h"
#include "dispatch_rig.h"

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

// A rig whose ray generation shader hands one wave call per launch to its wave (key: the launch's number, y * width
// + x, modulo `keys`) and writes the call's output to `outputs`. A 4x4 grid is one wave of 16 lanes (waves are 4x4
// blocks), in lane order of its numbers.
struct WaveCallRig {
    Rig r;
    Log log;
    WaveFunction function{runTestCalls, 8};
    uint32_t keys = 1;
    uint32_t failOn = ~0u;
    uvec2 grid;
    std::vector<uint32_t> outputs;

    explicit WaveCallRig(uvec2 size) : grid(size), outputs(size_t(size.x) * size.y, 0u) {
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

}  // namespace
}  // namespace refray::test
