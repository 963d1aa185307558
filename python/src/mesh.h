/// @file mesh.h
/// @brief sdf_lattices.Mesh is a PreparedMesh held by shared_ptr, so that a bound SDF object
/// (query.cpp) keeps the mesh it was built from alive.
#pragma once

#include <memory>

#include "core/mesh/prepared_mesh.h"
#include "python/src/common.h"

namespace sdf {

using MeshHolder = std::shared_ptr<PreparedMesh>;

}  // namespace sdf
