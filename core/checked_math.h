/// @file checked_math.h
/// @brief Sizes in checked 64-bit arithmetic: every count that decides an allocation (lattice
/// points, channel bytes, vertex indices) is computed here, so an input whose sizes overflow
/// is refused with a message instead of wrapping to a small, valid-looking number.
#pragma once

#include <cstdint>
#include <optional>

namespace sdf {

/// a * b, or nothing when it overflows int64.
inline std::optional<int64_t> checked_mul(int64_t a, int64_t b) {
    int64_t product = 0;
    if (__builtin_mul_overflow(a, b, &product)) return std::nullopt;
    return product;
}

/// a + b, or nothing when it overflows int64.
inline std::optional<int64_t> checked_add(int64_t a, int64_t b) {
    int64_t sum = 0;
    if (__builtin_add_overflow(a, b, &sum)) return std::nullopt;
    return sum;
}

/// a * b * c, or nothing when any step overflows int64.
inline std::optional<int64_t> checked_mul(int64_t a, int64_t b, int64_t c) {
    const std::optional<int64_t> ab = checked_mul(a, b);
    return ab ? checked_mul(*ab, c) : std::nullopt;
}

}  // namespace sdf
