// Progress of long work, reported to whoever draws it (the CLI draws a bar).
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <mutex>
#include <string>

namespace refray {

struct ProgressState {
    std::string label;
    uint64_t done = 0;
    uint64_t total = 0;
    double elapsedSeconds = 0.0;
    // Estimated seconds left; negative while unknown.
    double etaSeconds = -1.0;
    bool finished = false;
};

// Thread-safe counter. Workers call advance(); the sink is called at most every
// `interval` (and once at finish) from whichever thread crosses the interval, never
// concurrently. Below tools/ nothing draws: the sink decides what to do.
class Progress {
public:
    using Sink = std::function<void(const ProgressState&)>;

    Progress(std::string label, uint64_t total, Sink sink,
             std::chrono::milliseconds interval = std::chrono::milliseconds(100));
    void advance(uint64_t units = 1);
    void finish();
    uint64_t done() const { return done_.load(std::memory_order_relaxed); }

private:
    ProgressState snapshot(bool finished) const;

    std::string label_;
    uint64_t total_;
    Sink sink_;
    std::chrono::milliseconds interval_;
    std::chrono::steady_clock::time_point start_;
    std::atomic<uint64_t> done_{0};
    std::atomic<int64_t> nextReportNs_{0};
    std::mutex sinkMutex_;
};

// Renders a one-line bar: "label [#####.....]  42% 1.2s ETA 3.4s".
std::string formatProgressBar(const ProgressState& state, int width = 30);

}  // namespace refray
