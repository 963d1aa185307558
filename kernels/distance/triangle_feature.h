/// @file triangle_feature.h
/// @brief Names the part of a triangle (face, one of 3 edges, one of 3 vertices) that holds
/// the closest point to a query. The sign of the distance is taken from the angle-weighted
/// pseudonormal of exactly this feature (Baerentzen & Aanaes 2005).
#pragma once

#include "kernels/core/host_device.h"

namespace sdf {

/// Edge e joins the triangle's local vertices e and (e + 1) % 3.
enum class TriangleFeature : int {
    Face = 0,
    Edge01 = 1,
    Edge12 = 2,
    Edge20 = 3,
    Vertex0 = 4,
    Vertex1 = 5,
    Vertex2 = 6,
};

SDF_CPU_GPU constexpr bool is_edge(TriangleFeature f) {
    return f == TriangleFeature::Edge01 || f == TriangleFeature::Edge12 || f == TriangleFeature::Edge20;
}
SDF_CPU_GPU constexpr bool is_vertex(TriangleFeature f) { return static_cast<int>(f) >= 4; }
/// Local edge index 0..2 of an edge feature.
SDF_CPU_GPU constexpr int edge_index(TriangleFeature f) { return static_cast<int>(f) - 1; }
/// Local vertex index 0..2 of a vertex feature.
SDF_CPU_GPU constexpr int vertex_index(TriangleFeature f) { return static_cast<int>(f) - 4; }

inline const char* feature_name(TriangleFeature f) {
    switch (f) {
        case TriangleFeature::Face: return "face";
        case TriangleFeature::Edge01: return "edge01";
        case TriangleFeature::Edge12: return "edge12";
        case TriangleFeature::Edge20: return "edge20";
        case TriangleFeature::Vertex0: return "vertex0";
        case TriangleFeature::Vertex1: return "vertex1";
        case TriangleFeature::Vertex2: return "vertex2";
    }
    return "?";
}

}  // namespace sdf
