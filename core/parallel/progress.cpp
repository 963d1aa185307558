#include "core/parallel/progress.h"

#include <cstdio>

#include "core/parallel/task_monitor.h"

namespace sdf {
namespace {
std::atomic<bool> g_enabled{true};
}

void ProgressReporter::set_globally_enabled(bool enabled) { g_enabled = enabled; }
bool ProgressReporter::globally_enabled() { return g_enabled; }

ProgressReporter::ProgressReporter(std::string label, int64_t total, bool enabled, double interval_seconds)
    : label_(std::move(label)), total_(total), enabled_(enabled && g_enabled), interval_(interval_seconds),
      start_(Clock::now()), monitor_(current_task_monitor()) {}

ProgressReporter::~ProgressReporter() { finish(); }

void ProgressReporter::advance(int64_t items) {
    const int64_t done = done_.fetch_add(items) + items;
    if (monitor_) monitor_->advance(items);
    if (!enabled_) return;
    const auto now = Clock::now();
    const auto since_last = [&] {
        return std::chrono::duration<double>(now - (start_ + Clock::duration(last_.load()))).count();
    };
    if (since_last() < interval_) return;
    std::unique_lock<std::mutex> lock(mutex_, std::try_to_lock);
    if (!lock.owns_lock() || since_last() < interval_) return;
    last_.store((now - start_).count());
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    const double fraction = total_ > 0 ? double(done) / double(total_) : 1.0;
    const double left = fraction > 0 ? elapsed * (1.0 - fraction) / fraction : 0.0;
    std::fprintf(stderr, "  %s: %5.1f%%  %.0f s elapsed, about %.0f s left\n", label_.c_str(), 100.0 * fraction,
                 elapsed, left);
    printed_ = true;
}

void ProgressReporter::finish() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (finished_) return;
    finished_ = true;
    if (enabled_ && printed_) {
        const double elapsed = std::chrono::duration<double>(Clock::now() - start_).count();
        std::fprintf(stderr, "  %s: done in %.1f s\n", label_.c_str(), elapsed);
    }
}

}  // namespace sdf
