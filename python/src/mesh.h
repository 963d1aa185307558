/// @file mesh.h
/// @brief sdf_lattices.Mesh is a PreparedMesh held by shared_ptr, so that a bound SDF object
/// (query.cpp) keeps the mesh it was built from alive.
#pragma once

#include <memory>

#include "core/mesh/prepared_mesh.h"
#include "python/src/common.h"

namespace sdf {

using MeshHolder = std::shared_ptr<PreparedMesh>;

/// The Mesh a `mesh` argument stands for: a Mesh itself, or whatever
/// sdf_lattices._adapters.as_mesh turns into one (a file path, (vertices, faces) arrays, a
/// trimesh-like object with vertices and faces, an Open3D TriangleMesh, legacy or tensor);
/// TypeError naming what is accepted otherwise.
MeshHolder mesh_argument(const py::handle& mesh);

/// `mesh` with its input vertices replaced by `new_vertices` (as many rows) and its input
/// faces kept, prepared with the options it was prepared with: what Mesh(new_vertices,
/// mesh.input_faces, ...) gives, bit for bit. ValueError when the preparation's
/// connectivity differs (welds, dropped triangles, the outward flip): the numbering of the
/// caller's results would change.
MeshHolder refit_mesh(const MeshHolder& mesh, const py::array& new_vertices);

}  // namespace sdf
