/// @file load_obj.h
/// @brief Wavefront OBJ loading through tinyobjloader (double precision; polygons triangulated
/// by polygon_triangulation.h, as in every other format).
#pragma once

#include <string>

#include "core/mesh/triangle_mesh.h"

namespace sdf {

/// Loads every face of every shape in file order; polygons are triangulated by
/// polygon_triangulation.h (ear clipping in the polygon's plane, shortest cut first: a quad
/// along its shorter diagonal).
/// Throws std::runtime_error naming the file (and the line where known) when the file is
/// missing, unparsable, holds no triangles, or has non-finite coordinates.
TriangleMesh load_obj(const std::string& path);

/// The same from OBJ text already in memory (e.g. a gunzipped .obj.gz); `path` names it in
/// errors and in the mesh's name and source. content_sha256 is left to the caller.
TriangleMesh load_obj_text(const std::string& text, const std::string& path);

}  // namespace sdf
