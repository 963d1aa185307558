/// @file shared_mesh.h
/// @brief A prepared mesh as the shared owner Sampler::bind() takes, for tests that hold
/// theirs by value or by pointer: a copy (which shares the original's buffers and BVH) or
/// the shared pointer itself.
#pragma once

#include <memory>

#include "core/mesh/prepared_mesh.h"

namespace sdf {

inline std::shared_ptr<const PreparedMesh> share(const PreparedMesh& mesh) { return std::make_shared<const PreparedMesh>(mesh); }
inline std::shared_ptr<const PreparedMesh> share(const PreparedMesh* mesh) { return share(*mesh); }
inline std::shared_ptr<const PreparedMesh> share(std::shared_ptr<const PreparedMesh> mesh) { return mesh; }
inline std::shared_ptr<const PreparedMesh> share(const std::shared_ptr<PreparedMesh>& mesh) { return mesh; }
inline std::shared_ptr<const PreparedMesh> share(const std::unique_ptr<PreparedMesh>& mesh) { return share(*mesh); }
inline std::shared_ptr<const PreparedMesh> share(const std::unique_ptr<const PreparedMesh>& mesh) { return share(*mesh); }

}  // namespace sdf
