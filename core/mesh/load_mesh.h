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

#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "core/mesh/triangle_mesh.h"

namespace sdf {

enum class MeshFormat { Obj, Ply, Stl, Off };

/// One row of the mesh formats' table: how a file is recognised and which reader reads it.
struct MeshFormatRow {
    MeshFormat format;
    const char* name;                       ///< "PLY": for messages and help texts
    const char* variants;                   ///< " (ascii and binary)", or "": for help texts
    std::array<const char*, 2> extensions;  ///< lower case, without the dot (".gz" stripped first); null = none
    /// Content that decides the format before the extension is looked at (a magic line, an
    /// exact size), or null.
    bool (*definite)(std::string_view bytes);
    /// Content that decides it only when no extension does (OBJ's statements), or null.
    bool (*likely)(std::string_view bytes);
    /// The reader, from the file's bytes (gunzipped, byte-order mark removed).
    TriangleMesh (*read)(const std::string& bytes, const std::string& path);
};

/// The one table of mesh formats, in the order their content is tested (detect_mesh_format)
/// and help texts list them. Adding a format: its MeshFormat, its row and its reader
/// (docs/architecture-recipes.md).
const std::vector<MeshFormatRow>& mesh_formats();

/// The row of `format`.
const MeshFormatRow& mesh_format(MeshFormat format);

/// "OBJ", "PLY", "STL", "OFF": for messages.
const char* mesh_format_name(MeshFormat format);

/// "OBJ, PLY, OFF, STL, optionally .gz": the formats for a tool's help text.
std::string mesh_formats_help();

/// "OBJ, PLY (ascii and binary), OFF, STL (ascii and binary), each optionally .gz": the
/// formats and their variants, for messages.
std::string mesh_formats_supported();

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
