/// @file sampled_field.h
/// @brief The output of every sampler: signed distance, exact gradient and closest triangle
/// at every lattice point, with the provenance of how they were computed.
#pragma once

#include <cstdint>
#include <future>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/mesh/mesh_provenance.h"
#include "core/sampling/sampler_report.h"
#include "kernels/lattice/lattice.h"

namespace sdf {

enum class Precision { Float, Double };

/// closest_triangle of a point outside a narrow band (SamplerOptions::band_width): its
/// distance is the band's value with the point's sign, its gradient zero. -1 stays "none".
inline constexpr int32_t kOutsideBandTriangle = -2;

inline const char* precision_name(Precision p) { return p == Precision::Float ? "float" : "double"; }

/// Wall-clock and device timings of one sampling run, in seconds.
struct SamplingTimings {
    double total = 0;        ///< everything, host preparation included
    double kernel = 0;       ///< the distance computation itself (GPU: CUDA events)
    double upload = 0;       ///< host -> device transfers (GPU only)
    double download = 0;     ///< device -> host transfers (GPU only)
    double point_triangle_pairs = 0;  ///< points evaluated x triangles
    /// Certified float search (kernels/distance/search_certificate.h): points searched, of
    /// them re-ranked in double (several candidates) and sent to the full double search.
    int64_t certified_points = 0, reranked_points = 0, full_double_points = 0;
    double pairs_per_second() const { return kernel > 0 ? point_triangle_pairs / kernel : 0.0; }
};

struct SampledField {
    Lattice lattice;
    std::vector<double> distance;       ///< signed, negative inside
    std::vector<Vec3d> gradient;        ///< unit length
    std::vector<int32_t> closest_triangle;  ///< 0-based, in the mesh file's face order
    Precision precision = Precision::Float;
    SamplingTimings timings;
    SamplerReport sampler;              ///< how it was sampled (sampler_report.h)
    MeshProvenance mesh;                ///< the mesh it was sampled from (mesh_provenance.h)

    int64_t size() const { return int64_t(distance.size()); }
    /// n points of every channel, zero (triangle -1). From a million points on, the three
    /// channels are filled on three threads: a fresh allocation's pages are mapped at their
    /// first write, which costs more than the fill (36 bytes a point, 604 MB at 256^3).
    void resize(int64_t n) {
        if (n < (int64_t(1) << 20)) {
            distance.assign(size_t(n), 0.0);
            gradient.assign(size_t(n), Vec3d(0.0));
            closest_triangle.assign(size_t(n), -1);
            return;
        }
        std::future<void> d = std::async(std::launch::async, [&] { distance.assign(size_t(n), 0.0); });
        std::future<void> t = std::async(std::launch::async, [&] { closest_triangle.assign(size_t(n), -1); });
        gradient.assign(size_t(n), Vec3d(0.0));
        d.get();
        t.get();
    }
};

}  // namespace sdf
