/// @file parallel_for.h
/// @brief The CPU dispatch point (pbrt-v4's ParallelFor): runs fn(begin, end) over [0, n) in
/// chunks on `threads` threads with dynamic scheduling. Results never depend on the thread
/// count, because every item is computed the same way whoever computes it.
#pragma once

#include <cstdint>
#include <functional>

namespace sdf {

/// Number of hardware threads (at least 1).
int hardware_threads();

/// Resolves a requested count: 0 or negative means all hardware threads.
int resolve_thread_count(int requested);

void parallel_for(int64_t n, int64_t chunk, int threads, const std::function<void(int64_t, int64_t)>& fn);

}  // namespace sdf
