#include "core/progress.h"

#include <cmath>
#include <cstdio>

namespace refray {

Progress::Progress(std::string label, uint64_t total, Sink sink, std::chrono::milliseconds interval)
    : label_(std::move(label)), total_(total), sink_(std::move(sink)), interval_(interval),
      start_(std::chrono::steady_clock::now()) {}

ProgressState Progress::snapshot(bool finished) const {
    ProgressState s;
    s.label = label_;
    s.total = total_;
    s.done = finished ? total_ : done_.load(std::memory_order_relaxed);
    s.elapsedSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    if (s.done > 0 && s.total > 0) s.etaSeconds = s.elapsedSeconds * double(s.total - s.done) / double(s.done);
    s.finished = finished;
    return s;
}

void Progress::advance(uint64_t units) {
    done_.fetch_add(units, std::memory_order_relaxed);
    if (!sink_) return;
    const int64_t now =
        std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - start_).count();
    int64_t next = nextReportNs_.load(std::memory_order_relaxed);
    if (now < next) return;
    const int64_t after = now + std::chrono::duration_cast<std::chrono::nanoseconds>(interval_).count();
    if (!nextReportNs_.compare_exchange_strong(next, after)) return;
    std::unique_lock lock(sinkMutex_, std::try_to_lock);
    if (lock.owns_lock()) sink_(snapshot(false));
}

void Progress::finish() {
    if (!sink_) return;
    std::lock_guard lock(sinkMutex_);
    sink_(snapshot(true));
}

std::string formatProgressBar(const ProgressState& s, int width) {
    const double fraction = s.total ? double(s.done) / double(s.total) : 1.0;
    const int filled = int(std::lround(fraction * width));
    std::string bar = s.label + " [";
    for (int i = 0; i < width; ++i) bar += i < filled ? '#' : '.';
    char tail[96];
    if (s.finished)
        std::snprintf(tail, sizeof tail, "] 100%% %.1fs", s.elapsedSeconds);
    else if (s.etaSeconds >= 0.0)
        std::snprintf(tail, sizeof tail, "] %3d%% %.1fs ETA %.1fs", int(fraction * 100.0), s.elapsedSeconds,
                      s.etaSeconds);
    else
        std::snprintf(tail, sizeof tail, "] %3d%% %.1fs", int(fraction * 100.0), s.elapsedSeconds);
    return bar + tail;
}

}  // namespace refray
