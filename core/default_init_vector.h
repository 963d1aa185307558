/// @file default_init_vector.h
/// @brief A std::vector whose resize(n) default-initialises its new elements, so that for
/// plain values (double, int32_t, Vec3d) it writes nothing: for arrays a kernel fills
/// completely, the zero fill and its first touch of every page are spared (a sparse band of
/// the dragon at 2048^3 is 5 GB of them). resize(n, value) and assign(n, value) still fill.
#pragma once

#include <memory>
#include <new>
#include <utility>
#include <vector>

namespace sdf {

template <typename T>
struct DefaultInitAllocator : std::allocator<T> {
    template <typename U>
    struct rebind {
        using other = DefaultInitAllocator<U>;
    };
    DefaultInitAllocator() noexcept = default;
    template <typename U>
    DefaultInitAllocator(const DefaultInitAllocator<U>&) noexcept {}

    /// Value-less construction: default-initialisation (no write for trivial types).
    template <typename U>
    void construct(U* p) noexcept(noexcept(::new (static_cast<void*>(p)) U)) {
        ::new (static_cast<void*>(p)) U;
    }
    template <typename U, typename... Args>
    void construct(U* p, Args&&... args) {
        ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
    }
};

template <typename T, typename U>
bool operator==(const DefaultInitAllocator<T>&, const DefaultInitAllocator<U>&) noexcept {
    return true;
}
template <typename T, typename U>
bool operator!=(const DefaultInitAllocator<T>&, const DefaultInitAllocator<U>&) noexcept {
    return false;
}

template <typename T>
using DefaultInitVector = std::vector<T, DefaultInitAllocator<T>>;

}  // namespace sdf
