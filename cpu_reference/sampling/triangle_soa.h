/// @file triangle_soa.h
/// @brief PackedTriangle constants stored field by field (structure of arrays), so that the
/// CPU loop over triangles loads one SIMD register per field and vectorises.
#pragma once

#include <vector>

#include "core/default_init_vector.h"
#include "kernels/distance/packed_triangle.h"

namespace sdf {

template <typename T>
class TriangleSoA {
public:
    static constexpr int kFields = int(sizeof(PackedTriangle<T>) / sizeof(T));

    explicit TriangleSoA(const DefaultInitVector<PackedTriangle<T>>& packed) : size_(int(packed.size())) {
        for (int f = 0; f < kFields; ++f) fields_[f].resize(packed.size());
        for (size_t i = 0; i < packed.size(); ++i) {
            const T* src = reinterpret_cast<const T*>(&packed[i]);
            for (int f = 0; f < kFields; ++f) fields_[f][i] = src[f];
            if (is_interior_sliver(packed[i])) interior_slivers_.push_back(int(i));
        }
    }

    int size() const { return size_; }
    /// The triangles (ascending) whose squared_distance() is sliver_squared_distance(): the
    /// vector loops run the branch-free form and then re-evaluate these.
    const std::vector<int>& interior_slivers() const { return interior_slivers_; }
    const T* field(int f) const { return fields_[f].data(); }

    /// Reassembles triangle i; inside a loop the compiler keeps each field in a register.
    SDF_INLINE PackedTriangle<T> operator[](int i) const {
        PackedTriangle<T> t;
        T* dst = reinterpret_cast<T*>(&t);
        for (int f = 0; f < kFields; ++f) dst[f] = fields_[f][size_t(i)];
        return t;
    }

private:
    int size_;
    std::vector<T> fields_[kFields];
    std::vector<int> interior_slivers_;
};

}  // namespace sdf
