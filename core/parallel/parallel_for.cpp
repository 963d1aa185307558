#include "core/parallel/parallel_for.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include "core/parallel/task_monitor.h"

namespace sdf {

int hardware_threads() { return std::max(1u, std::thread::hardware_concurrency()); }

int resolve_thread_count(int requested) { return requested > 0 ? requested : hardware_threads(); }

void parallel_for(int64_t n, int64_t chunk, int threads, const std::function<void(int64_t, int64_t)>& fn) {
    if (n <= 0) return;
    chunk = std::max<int64_t>(1, chunk);
    threads = int(std::min<int64_t>(resolve_thread_count(threads), (n + chunk - 1) / chunk));
    // A caller's stop request (task_monitor.h) is honoured between chunks.
    const TaskMonitor* monitor = current_task_monitor();
    const auto stop = [monitor] {
        if (monitor && monitor->stop_requested()) throw TaskStopped();
    };
    if (threads <= 1) {
        for (int64_t b = 0; b < n; b += chunk) {
            stop();
            fn(b, std::min(n, b + chunk));
        }
        return;
    }
    std::atomic<int64_t> next{0};
    std::exception_ptr error;
    std::mutex error_mutex;
    auto worker = [&] {
        try {
            for (int64_t b; (b = next.fetch_add(chunk)) < n;) {
                stop();
                fn(b, std::min(n, b + chunk));
            }
        } catch (...) {
            std::lock_guard<std::mutex> lock(error_mutex);
            if (!error) error = std::current_exception();
            next.store(n);
        }
    };
    std::vector<std::thread> pool;
    for (int t = 1; t < threads; ++t) pool.emplace_back(worker);
    worker();
    for (auto& t : pool) t.join();
    if (error) std::rethrow_exception(error);
}

}  // namespace sdf
