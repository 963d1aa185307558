/// @file warp_reduce.cuh
/// @brief Minimum, maximum and sum over the 32 lanes of a warp (every lane must call them):
/// one redux.sync where the GPU has it (sm_80 and later) for 32-bit integers and for floats
/// (through bits that order as signed integers), five dependent shuffles otherwise (sm_75,
/// doubles, other types). Float values must not be NaN: the bits order a NaN beyond the
/// infinities where min()/max() ignore it (the searches' values never are: their points
/// are checked finite).
#pragma once

#include <type_traits>

namespace sdf::cuda {

constexpr unsigned kFullWarp = 0xffffffffu;

namespace detail {

/// A float's bits as an int whose signed order is the float's (a negative float's magnitude
/// bits flipped; the map is its own inverse).
__device__ inline int ordered_bits(float v) {
    const int i = __float_as_int(v);
    return i ^ ((i >> 31) & 0x7fffffff);
}
__device__ inline float from_ordered_bits(int i) { return __int_as_float(i ^ ((i >> 31) & 0x7fffffff)); }

template <typename T>
constexpr bool kReduxInteger = std::is_same_v<T, int> || std::is_same_v<T, unsigned>;

}  // namespace detail

template <typename T>
__device__ inline T warp_min(T v) {
#if defined(__CUDA_ARCH__) && __CUDA_ARCH__ >= 800
    if constexpr (std::is_same_v<T, float>) return detail::from_ordered_bits(__reduce_min_sync(kFullWarp, detail::ordered_bits(v)));
    else if constexpr (detail::kReduxInteger<T>) return __reduce_min_sync(kFullWarp, v);
    else
#endif
    {
        for (int o = 16; o > 0; o >>= 1) v = min(v, __shfl_xor_sync(kFullWarp, v, o));
        return v;
    }
}

template <typename T>
__device__ inline T warp_max(T v) {
#if defined(__CUDA_ARCH__) && __CUDA_ARCH__ >= 800
    if constexpr (std::is_same_v<T, float>) return detail::from_ordered_bits(__reduce_max_sync(kFullWarp, detail::ordered_bits(v)));
    else if constexpr (detail::kReduxInteger<T>) return __reduce_max_sync(kFullWarp, v);
    else
#endif
    {
        for (int o = 16; o > 0; o >>= 1) v = max(v, __shfl_xor_sync(kFullWarp, v, o));
        return v;
    }
}

/// The sum; a floating-point sum in the shuffles' order (a fixed tree over the lanes).
template <typename T>
__device__ inline T warp_sum(T v) {
#if defined(__CUDA_ARCH__) && __CUDA_ARCH__ >= 800
    if constexpr (detail::kReduxInteger<T>) return __reduce_add_sync(kFullWarp, v);
    else
#endif
    {
        for (int o = 16; o > 0; o >>= 1) v += __shfl_xor_sync(kFullWarp, v, o);
        return v;
    }
}

}  // namespace sdf::cuda
