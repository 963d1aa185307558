/// @file progress.h
/// @brief Progress lines on stderr for long runs: percent, rate and time left, at most one
/// line every `interval` seconds, and nothing for runs that finish before the first line.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

namespace sdf {

class TaskMonitor;

/// Items done are also counted on the monitor of the constructing thread (task_monitor.h).
class ProgressReporter {
public:
    ProgressReporter(std::string label, int64_t total, bool enabled, double interval_seconds = 2.0);
    ~ProgressReporter();
    /// Thread-safe; call with the number of items just finished.
    void advance(int64_t items);
    void finish();

    /// Global switch (e.g. --quiet, tests).
    static void set_globally_enabled(bool enabled);
    static bool globally_enabled();

private:
    using Clock = std::chrono::steady_clock;
    std::string label_;
    int64_t total_;
    bool enabled_;
    double interval_;
    std::atomic<int64_t> done_{0};
    Clock::time_point start_;
    /// Time of the last line, in Clock ticks since start_: atomic, because every thread reads
    /// it before deciding whether to take the mutex.
    std::atomic<Clock::rep> last_{0};
    std::mutex mutex_;
    TaskMonitor* monitor_;
    bool printed_ = false;
    bool finished_ = false;
};

}  // namespace sdf
