#include "cpu_reference/raycast/tile_loop.h"

#include <algorithm>

#include "core/parallel/parallel_for.h"
#include "core/parallel/progress.h"

namespace sdf {

void for_each_tile(int width, int height, int tile, int threads, const std::string& label, bool progress,
                   const std::function<void(int, int, int, int)>& fn) {
    tile = std::max(1, tile);
    const int tiles_x = (width + tile - 1) / tile, tiles_y = (height + tile - 1) / tile;
    ProgressReporter reporter(label, int64_t(width) * height, progress);
    parallel_for(int64_t(tiles_x) * tiles_y, 1, threads, [&](int64_t begin, int64_t end) {
        for (int64_t t = begin; t < end; ++t) {
            const int x0 = int(t % tiles_x) * tile, y0 = int(t / tiles_x) * tile;
            const int x1 = std::min(width, x0 + tile), y1 = std::min(height, y0 + tile);
            fn(x0, y0, x1, y1);
            reporter.advance(int64_t(x1 - x0) * (y1 - y0));
        }
    });
    reporter.finish();
}

}  // namespace sdf
