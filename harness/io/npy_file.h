/// @file npy_file.h
/// @brief NumPy's .npy files (format versions 1.0, 2.0 and 3.0), read and written without
/// NumPy: one array of little-endian float32, float64, int32 or int64 items in C order.
///
/// Used by the tools for binary points and results (sdf-query, sdf-eval: `.npy` points in,
/// `.npy` results out) and by the Python module's tests as the independent reader's
/// counterpart. The reader checks everything a user's file can get wrong before allocating:
/// the magic string and version, the header dictionary ('descr', 'fortran_order', 'shape' and
/// nothing else), the dtype (big-endian, Fortran order and object arrays are refused by name),
/// the shape's product in checked 64-bit arithmetic, and the file's size against it. Every
/// error names the file and what was expected, e.g.
///   "pts.npy: header: 'descr' is '>f8' (big-endian); expected one of '<f4', '<f8', '<i4', '<i8'".
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "harness/io/atomic_file.h"
#include "kernels/core/vec3.h"

namespace sdf {

enum class NpyDtype { Float32, Float64, Int32, Int64 };

/// One entry per dtype: the one table the reader, the writer and every message read.
struct NpyDtypeInfo {
    NpyDtype dtype;
    const char* descr;  ///< as in the header: "<f4"
    int item_size;      ///< bytes
};
inline constexpr NpyDtypeInfo kNpyDtypes[] = {
    {NpyDtype::Float32, "<f4", 4},
    {NpyDtype::Float64, "<f8", 8},
    {NpyDtype::Int32, "<i4", 4},
    {NpyDtype::Int64, "<i8", 8},
};

const char* npy_descr(NpyDtype dtype);
int npy_item_size(NpyDtype dtype);

/// An array as stored: dtype, shape (C order, last index fastest) and the raw items.
struct NpyArray {
    NpyDtype dtype = NpyDtype::Float64;
    std::vector<int64_t> shape;
    std::vector<unsigned char> data;  ///< count() * item size bytes, little-endian

    int64_t count() const;  ///< product of the shape (1 for a 0-d array)
    /// Every item converted to double (int64 beyond 2^53 rounds, as NumPy's astype does).
    std::vector<double> to_doubles() const;
    /// "(5, 3)", as NumPy prints a shape.
    std::string shape_text() const;
};

/// Reads `path`; throws std::runtime_error naming the file and what was wrong.
NpyArray read_npy(const std::string& path);
/// The same from bytes already in memory; `name` is used in messages.
NpyArray parse_npy(const std::string& bytes, const std::string& name);

/// The complete file (header and data) of an array.
std::string npy_bytes(NpyDtype dtype, const std::vector<int64_t>& shape, const void* data);
/// Writes an array atomically (harness/io/atomic_file.h); `data` holds the product of
/// `shape` items of `dtype`, C order.
void write_npy(const std::string& path, NpyDtype dtype, const std::vector<int64_t>& shape, const void* data,
               Overwrite overwrite = Overwrite::Forbid);
inline void write_npy(const std::string& path, const std::vector<double>& values, const std::vector<int64_t>& shape,
                      Overwrite overwrite = Overwrite::Forbid) {
    write_npy(path, NpyDtype::Float64, shape, values.data(), overwrite);
}

/// Points from a .npy file of shape (N, 3), any of the four dtypes, every coordinate finite.
std::vector<Vec3d> read_npy_points(const std::string& path);

/// True when `path` ends with ".npy" (any case): how the tools decide between text and binary.
bool is_npy_path(const std::string& path);

}  // namespace sdf
