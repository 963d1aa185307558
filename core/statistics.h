/// @file statistics.h
/// @brief Summary statistics of repeated measurements: timings (experiments, the ray casters)
/// are reported as the median of their repetitions, which one slow outlier (a page fault, a
/// context switch on a shared machine) does not move. The one median of the project.
#pragma once

#include <algorithm>
#include <vector>

namespace sdf {

/// The median of `values` (the mean of the middle two for an even count); 0 when empty.
inline double median_of(std::vector<double> values) {
    std::sort(values.begin(), values.end());
    const size_t n = values.size();
    if (n == 0) return 0.0;
    return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

}  // namespace sdf
