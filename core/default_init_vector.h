/// @file default_init_vector.h
/// @brief A std::vector whose resize(n) default-initialises its new elements, so that for
/// plain values (double, int32_t, Vec3d) it writes nothing: for arrays a kernel fills
/// completely, the zero fill and its first touch of every page are spared (a sparse band of
/// the dragon at 2048^3 is 5 GB of them). resize(n, value) and assign(n, value) still fill.
/// Arrays of 4 MiB and more are asked for in transparent huge pages where Linux offers them
/// (madvise): their first touch by the kernel's threads then faults one page in 512.
#pragma once

#include <cstdlib>
#include <memory>
#include <new>
#include <utility>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#endif

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

    static constexpr std::size_t kHugePage = std::size_t(2) << 20;
    static constexpr std::size_t kHugeFrom = std::size_t(4) << 20;

    T* allocate(std::size_t n) {
        const std::size_t bytes = n * sizeof(T);
#if defined(__linux__) && defined(MADV_HUGEPAGE)
        if (n <= std::size_t(-1) / sizeof(T) && bytes >= kHugeFrom) {
            void* p = nullptr;
            const std::size_t rounded = (bytes + kHugePage - 1) / kHugePage * kHugePage;
            if (posix_memalign(&p, kHugePage, rounded) != 0) throw std::bad_alloc();
            madvise(p, rounded, MADV_HUGEPAGE);  // advice: refused or ignored, the pages stay small
            return static_cast<T*>(p);
        }
#endif
        return std::allocator<T>::allocate(n);
    }
    void deallocate(T* p, std::size_t n) noexcept {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
        if (n * sizeof(T) >= kHugeFrom) {
            std::free(p);
            return;
        }
#endif
        std::allocator<T>::deallocate(p, n);
    }

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
