/// @file interpolators.h
/// @brief The one table of reconstruction filters. Every list of names, every count, every
/// run-time dispatch (CPU reconstruction, the CUDA ray caster, the tools' help text, config
/// validation) is generated from `AllInterpolators`, so adding a filter is one header and one
/// entry here; a filter that lacks part of the static interface (interpolator.h) is a compile
/// error at each place that uses that part.
///
///   visit_interpolator(kind, [&](auto interp) {
///       using I = decltype(interp);
///       return I::evaluate(view, p);
///   });
#pragma once

#include <type_traits>
#include <utility>

#include "kernels/reconstruction/bcc_box_linear.h"
#include "kernels/reconstruction/bcc_box_quintic.h"
#include "kernels/reconstruction/bcc_cubic.h"
#include "kernels/reconstruction/bcc_cubic_c0.h"
#include "kernels/reconstruction/bcc_linear.h"
#include "kernels/reconstruction/catmull_rom.h"
#include "kernels/reconstruction/cc_bspline3.h"
#include "kernels/reconstruction/tricubic_lekien_marsden.h"
#include "kernels/reconstruction/trilinear.h"

namespace sdf {

template <typename... Interpolators>
struct InterpolatorList {
    static constexpr int size = int(sizeof...(Interpolators));
};

/// Every filter, in the order the tools list them. An InterpolatorKind is an index here.
using AllInterpolators = InterpolatorList<Trilinear, CatmullRom, TricubicLekienMarsden, CcBspline3,  // CC
                                         BccLinear, BccCubic, BccCubicC0, BccBoxLinear, BccBoxQuintic,
                                         BccBoxQuinticQi, BccBoxQuinticApprox>;  // BCC

/// A run-time choice of filter: the index of its type in AllInterpolators. Values come from
/// kind_of<I>() and parse_interpolator() only.
enum class InterpolatorKind : int {};

constexpr int kInterpolatorKinds = AllInterpolators::size;

namespace detail {
template <int K, typename List>
struct InterpolatorAt;
template <int K, typename First, typename... Rest>
struct InterpolatorAt<K, InterpolatorList<First, Rest...>> {
    using type = typename InterpolatorAt<K - 1, InterpolatorList<Rest...>>::type;
};
template <typename First, typename... Rest>
struct InterpolatorAt<0, InterpolatorList<First, Rest...>> {
    using type = First;
};

template <typename I, typename List>
struct IndexOf;
template <typename I, typename... Rest>
struct IndexOf<I, InterpolatorList<I, Rest...>> {
    static constexpr int value = 0;
};
template <typename I, typename First, typename... Rest>
struct IndexOf<I, InterpolatorList<First, Rest...>> {
    static constexpr int value = 1 + IndexOf<I, InterpolatorList<Rest...>>::value;
};
}  // namespace detail

/// The filter type at index K of AllInterpolators.
template <int K>
using InterpolatorAt = typename detail::InterpolatorAt<K, AllInterpolators>::type;

/// The kind of filter type I (a compile error when I is not in AllInterpolators).
template <typename I>
constexpr InterpolatorKind kind_of() {
    return InterpolatorKind(detail::IndexOf<I, AllInterpolators>::value);
}

/// Calls f(I{}) with the filter type of `kind` (host code: the CUDA ray caster calls it on the
/// host to pick the kernel instantiation). A kind outside the table is a logic error.
template <int K = 0, typename F>
decltype(auto) visit_interpolator(InterpolatorKind kind, F&& f) {
    if constexpr (K + 1 == kInterpolatorKinds) {
        return f(InterpolatorAt<K>{});
    } else {
        if (int(kind) == K) return f(InterpolatorAt<K>{});
        return visit_interpolator<K + 1>(kind, std::forward<F>(f));
    }
}

namespace detail {
template <typename F, int... K>
void for_each_interpolator(F& f, std::integer_sequence<int, K...>) {
    (f(typename InterpolatorAt<K, AllInterpolators>::type{}), ...);
}
}  // namespace detail

/// Calls f(I{}) for every filter, in table order.
template <typename F>
void for_each_interpolator(F&& f) {
    detail::for_each_interpolator(f, std::make_integer_sequence<int, kInterpolatorKinds>{});
}

}  // namespace sdf
