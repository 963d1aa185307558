/// @file task_monitor.h
/// @brief What a caller that waits for a long call can watch and steer (the Python module:
/// a progress callback, Ctrl-C, Python warnings): the call's progress, a request to stop it,
/// and the warnings it would otherwise write on stderr.
///
/// A monitor is installed for one thread (ScopedTaskMonitor). ProgressReporter and
/// parallel_for read the installing thread's monitor when they start, so the worker threads
/// they run report to it too; parallel_for stops between chunks once a stop is requested
/// (TaskStopped). Without a monitor nothing changes: no check, no cost, the same results.
#pragma once

#include <atomic>
#include <cstdint>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

namespace sdf {

/// Thrown by parallel_for when the monitor of its call asked to stop.
class TaskStopped : public std::runtime_error {
public:
    TaskStopped() : std::runtime_error("stopped on request") {}
};

class TaskMonitor {
public:
    /// Thread-safe: asks every parallel loop of the call to stop at its next chunk.
    void request_stop() { stop_.store(true); }
    bool stop_requested() const { return stop_.load(std::memory_order_relaxed); }

    /// Items finished so far, summed over every ProgressReporter of the call.
    void advance(int64_t items) { done_.fetch_add(items, std::memory_order_relaxed); }
    int64_t done() const { return done_.load(std::memory_order_relaxed); }

    /// Thread-safe; kept for the caller instead of being written on stderr.
    void warn(const std::string& text);
    /// The warnings collected so far, and none after.
    std::vector<std::string> take_warnings();

private:
    std::atomic<bool> stop_{false};
    std::atomic<int64_t> done_{0};
    std::mutex mutex_;
    std::vector<std::string> warnings_;
};

/// The monitor installed for the calling thread, or null.
TaskMonitor* current_task_monitor();

/// Installs `monitor` for the calling thread for the scope's life.
class ScopedTaskMonitor {
public:
    explicit ScopedTaskMonitor(TaskMonitor* monitor);
    ~ScopedTaskMonitor();
    ScopedTaskMonitor(const ScopedTaskMonitor&) = delete;
    ScopedTaskMonitor& operator=(const ScopedTaskMonitor&) = delete;

private:
    TaskMonitor* previous_;
};

/// A warning of a library call: to the calling thread's monitor when one is installed, else
/// on stderr as "warning: TEXT".
void report_warning(const std::string& text);

}  // namespace sdf
