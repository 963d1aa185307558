/// @file certified_search.h
/// @brief The host side of the certified float search (kernels/distance/search_certificate.h):
/// the mesh's error-bound constants, the counters of re-ranked points, and what a field's
/// provenance says about them.
#pragma once

#include <atomic>
#include <cstdint>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/bvh/search_bound.h"
#include "core/mesh/prepared_mesh.h"
#include "core/sampling/host_query.h"
#include "core/sampling/sampled_field.h"
#include "kernels/distance/search_certificate.h"

namespace sdf {

/// The constants of the float error bound of `mesh`: the smallest sin^2 of an angle of its
/// non-sliver triangles, its longest |E0| + |E1| and its largest |coordinate| (made with the
/// mesh: PreparedMesh::search_bound()).
FloatSearchBound float_search_bound(const PreparedMesh& mesh);

/// Largest |coordinate| of p.
inline double largest_coordinate(const Vec3d& p) { return std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)}); }

/// Largest |coordinate| of the points, on `threads` threads (0: all) for a long list (a maximum
/// is the same whichever thread finds it).
double largest_coordinate(const std::vector<Vec3d>& points, int threads = 0);
double largest_coordinate(const HostPoints& points, int threads = 0);

/// Largest |coordinate| of a lattice's points.
inline double largest_lattice_coordinate(const Lattice& lattice) {
    return std::max(largest_coordinate(lattice.domain_min()), largest_coordinate(lattice.domain_max())) + lattice.spacing;
}

/// How a run's points were certified, summed over threads.
struct CertificateCounters {
    std::atomic<int64_t> points{0};       ///< float searches certified
    std::atomic<int64_t> reranked{0};     ///< of them, with more than one candidate (evaluated in double)
    std::atomic<int64_t> full_double{0};  ///< of them, with too many candidates: the full double search
};

/// Copies the counters into a run's timings.
inline void record_certificate(SamplingTimings& t, const CertificateCounters& c) {
    t.certified_points = c.points.load();
    t.reranked_points = c.reranked.load();
    t.full_double_points = c.full_double.load();
}

/// The manifest entry "search_certificate": for float runs whether the triangle is the double
/// search's (certified) and how many points needed double work; for double runs the search
/// is the reference itself. `certified` false: a search that keeps its own float winner
/// (the thesis's kernel, the Eberly kernel).
CertificateReport certificate_provenance(bool float_search, bool certified, const CertificateCounters& counters);

}  // namespace sdf
