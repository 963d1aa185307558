/// @file tile_loop.h
/// @brief The CPU renderers' loop: square tiles handed out dynamically to the thread pool
/// (parallel_for), with a progress line for long renders (ProgressReporter).
#pragma once

#include <functional>
#include <string>

namespace sdf {

/// Calls fn(x0, y0, x1, y1) for every tile [x0, x1) x [y0, y1) of a width x height image,
/// on `threads` threads (0 = all). Progress is reported in pixels under `label`.
void for_each_tile(int width, int height, int tile, int threads, const std::string& label, bool progress,
                   const std::function<void(int, int, int, int)>& fn);

}  // namespace sdf
