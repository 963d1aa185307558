/// @file band_distances.h
/// @brief A sparse band's distances, held in double or in float32.
///
/// The band's samplers compute every distance in double (the certified float search returns
/// the double search's triangle, and its distance is evaluated in double). Outputs that store
/// float32 only (a `.nvdb` or `.vdb` level set, a field file in float32) round each value once
/// when written; a band held for them may round it when sampled instead, and holds 4 bytes a
/// point, not 8: the same bytes in the files, half the band's host memory and its download.
/// Reading gives a double either way; writing stores through set(), which rounds as the
/// type asks (float(d): round to nearest, as every float32 writer rounds).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "core/default_init_vector.h"

namespace sdf {

/// How a band holds its distances.
enum class BandDistanceType : uint8_t { Float64, Float32 };

struct NamedBandDistanceType {
    const char* name;
    BandDistanceType type;
    size_t bytes;
};
/// One table: reports' names and each type's bytes a point.
inline constexpr NamedBandDistanceType kBandDistanceTypes[] = {{"float64", BandDistanceType::Float64, sizeof(double)},
                                                               {"float32", BandDistanceType::Float32, sizeof(float)}};
inline const NamedBandDistanceType& band_distance_type(BandDistanceType type) { return kBandDistanceTypes[size_t(type)]; }

class BandDistances {
public:
    explicit BandDistances(BandDistanceType type = BandDistanceType::Float64) : type_(type) {}

    BandDistanceType type() const { return type_; }
    bool float32() const { return type_ == BandDistanceType::Float32; }
    /// Bytes a value takes (8 or 4).
    size_t value_bytes() const { return band_distance_type(type_).bytes; }

    size_t size() const { return float32() ? f32_.size() : f64_.size(); }
    bool empty() const { return size() == 0; }
    /// n values; new ones unwritten (a block kernel writes them all).
    void resize(size_t n) { float32() ? f32_.resize(n) : f64_.resize(n); }
    /// n values; new ones `value`.
    void resize(size_t n, double value) { float32() ? f32_.resize(n, float(value)) : f64_.resize(n, value); }
    void assign(size_t n, double value) { float32() ? f32_.assign(n, float(value)) : f64_.assign(n, value); }

    double operator[](size_t i) const { return float32() ? double(f32_[i]) : f64_[i]; }
    /// d as the band holds it.
    double rounded(double d) const { return float32() ? double(float(d)) : d; }
    void set(size_t i, double d) {
        if (float32()) f32_[i] = float(d);
        else f64_[i] = d;
    }

    /// The values' bytes, value_bytes() each: for a copy in the held type (a device's
    /// download, a file's reader of the same dtype).
    void* data() { return float32() ? static_cast<void*>(f32_.data()) : static_cast<void*>(f64_.data()); }
    const void* data() const { return float32() ? static_cast<const void*>(f32_.data()) : static_cast<const void*>(f64_.data()); }
    /// The values as T (double or float): T must be the held type (std::logic_error).
    template <typename T>
    T* values() {
        static_assert(std::is_same_v<T, double> || std::is_same_v<T, float>, "a band holds double or float distances");
        if (float32() != std::is_same_v<T, float>)
            throw std::logic_error(std::string("BandDistances: the band holds ") + band_distance_type(type_).name +
                                   " distances, not " + (std::is_same_v<T, float> ? "float32" : "float64"));
        if constexpr (std::is_same_v<T, float>) return f32_.data();
        else return f64_.data();
    }
    /// Calls f with a pointer to the values in the held type (const double* or const float*):
    /// loops over many values branch once.
    template <typename F>
    decltype(auto) visit(F&& f) const {
        return float32() ? f(static_cast<const float*>(f32_.data())) : f(static_cast<const double*>(f64_.data()));
    }

    /// The same type and values, byte for byte (tests: -0 and +0 differ).
    bool same_bytes(const BandDistances& o) const {
        return type_ == o.type_ && size() == o.size() && (empty() || std::memcmp(data(), o.data(), size() * value_bytes()) == 0);
    }

    /// Bytes held (capacity, not size).
    size_t memory_bytes() const { return f64_.capacity() * sizeof(double) + f32_.capacity() * sizeof(float); }

private:
    BandDistanceType type_;
    DefaultInitVector<double> f64_;
    DefaultInitVector<float> f32_;
};

}  // namespace sdf
