/// @file mesh_readers.h
/// @brief The readers behind load_mesh_file(), one per format, each from the file's bytes
/// (already gunzipped). Every one returns the file's own vertices (exactly, in double) and
/// its faces in file order, polygons triangulated by polygon_triangulation.h, and throws std::runtime_error naming the
/// file and the header line, element or byte offset of what it could not read.
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "core/mesh/mesh_file_bytes.h"
#include "core/mesh/triangle_mesh.h"

namespace sdf {

/// PLY (Turk 1994): ascii, binary_little_endian and binary_big_endian; element "vertex"
/// with scalar properties x, y, z of any type; element "face" with a list property
/// "vertex_indices" (or "vertex_index"); other elements and properties are skipped.
TriangleMesh read_ply(const std::string& bytes, const std::string& path);

/// The most bytes a binary PLY whose header `bytes` begin with may have: the header, then
/// every declared element at its properties' sizes, lists at their count type's largest
/// count (nothing may follow the last element); ascii PLY declares no byte size (the limit
/// is kMaxMeshFileBytes). std::nullopt while `bytes` hold only part of the header. Lets a
/// .ply.gz be decompressed no further than its own header allows. Throws, as read_ply()
/// would, for a complete header that does not parse.
std::optional<ContentLimit> ply_size_limit(std::string_view bytes, const std::string& path);

/// STL, binary (80-byte header, uint32 count, 50 bytes per triangle; recognised by its exact
/// size even when the header starts with "solid") or ASCII. STL repeats each corner per
/// triangle: vertices with equal coordinates are welded exactly, in order of first use.
TriangleMesh read_stl(const std::string& bytes, const std::string& path);

/// Whether `bytes` begin as ASCII STL: first word "solid" (in any case) and no control
/// bytes (binary data) in the first records.
bool is_ascii_stl_start(std::string_view bytes);

/// Whether the first records of `bytes` hold control bytes other than white space, as
/// binary data does and text does not.
bool holds_binary_bytes(std::string_view bytes);

/// OFF (Geomview): header OFF, COFF, NOFF, CNOFF, STOFF, ... (extra per-vertex columns
/// skipped), counts, vertex lines, face lines "n i_0 ... i_(n-1) [colour]"; `#` comments.
TriangleMesh read_off(const std::string& bytes, const std::string& path);

}  // namespace sdf
