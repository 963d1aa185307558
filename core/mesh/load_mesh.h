/// @file load_mesh.h
/// @brief Loading a mesh file of any supported format: OBJ (tinyobjloader, load_obj.h), PLY,
/// STL and OFF (this project's readers, mesh_readers.h), each optionally gzip-compressed.
///
/// Why own readers for PLY, STL and OFF: the sign and the distances need the file's exact
/// vertices in double. Debian 12's assimp (5.2.5) is built in single precision (ai_real is
/// float: ASSIMP_DOUBLE_PRECISION is off in its config.h), so a double PLY would be rounded,
/// and its errors name neither line nor element; CGAL's readers keep doubles but report a
/// failure only as `false` (details on std::cerr) and would make Boost, GMP and MPFR build
/// dependencies; no PLY-only library (tinyply, happly, rply) is packaged. The three formats
/// are small and fully specified, and the readers check every size before allocating.
#pragma once

#include <string>

#include "core/mesh/triangle_mesh.h"

namespace sdf {

enum class MeshFormat { Obj, Ply, Stl, Off };

/// "OBJ", "PLY", "STL", "OFF": for messages.
const char* mesh_format_name(MeshFormat format);

/// The format of a file: by content where it is definite (the "ply" and "OFF" magic lines,
/// binary STL's exact size, ASCII STL's "solid ... facet"), else by extension (".gz"
/// stripped first). Throws std::runtime_error naming the file and the extension when
/// neither decides, e.g. "scene.fbx: unsupported mesh format 'fbx'; supported: ...".
MeshFormat detect_mesh_format(const std::string& path, const std::string& bytes);

/// Reads the mesh in `path`: file order, polygons triangulated, exact vertices (STL's welded
/// exactly), name = file name without extensions, content_sha256 of the file's bytes.
/// Every error names the file and where in it (line, element or byte) it went wrong.
TriangleMesh load_mesh_file(const std::string& path);

}  // namespace sdf
