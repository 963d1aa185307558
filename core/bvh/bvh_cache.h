/// @file bvh_cache.h
/// @brief Keeps the BVH of the last mesh a sampler saw, so repeated sample() and query()
/// calls on one mesh build it once (the build time is reported by the call that built it).
#pragma once

#include <memory>
#include <mutex>
#include <string>

#include "core/bvh/triangle_bvh.h"

namespace sdf {

class BvhCache {
public:
    /// The BVH of `mesh` (a PreparedMesh: a template only so that core/bvh needs no include of
    /// core/mesh); `built` tells whether this call built it.
    template <class Mesh>
    std::shared_ptr<const TriangleBvh> get(const Mesh& mesh, bool& built, const BvhBuildOptions& options = {}) {
        std::lock_guard<std::mutex> lock(mutex_);
        built = false;
        if (!bvh_ || mesh_ != &mesh || sha_ != mesh.content_sha256() || triangles_ != mesh.triangles().size() ||
            !same_bounds(mesh.bounds())) {
            bvh_ = std::make_shared<const TriangleBvh>(build_triangle_bvh(mesh, options));
            mesh_ = &mesh;
            sha_ = mesh.content_sha256();
            triangles_ = mesh.triangles().size();
            bounds_ = mesh.bounds();
            built = true;
        }
        return bvh_;
    }

private:
    bool same_bounds(const Bounds3& b) const { return b.min == bounds_.min && b.max == bounds_.max; }

    std::mutex mutex_;
    std::shared_ptr<const TriangleBvh> bvh_;
    const void* mesh_ = nullptr;
    std::string sha_;
    size_t triangles_ = 0;
    Bounds3 bounds_;
};

}  // namespace sdf
