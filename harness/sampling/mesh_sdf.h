/// @file mesh_sdf.h
/// @brief Build once, query many times: a prepared mesh bound to one sampler, a thin owner
/// of the BoundSampler (core/sampling/sampler.h) that Sampler::bind() makes: its
/// construction is the binding, which builds what every query of the mesh needs (the BVH,
/// the winding data when the sign is the winding number's, on the GPU the device upload);
/// query() and sample() then only search. `sdf-query` (point_query.h) and the Python
/// module's SDF class both use it, and the numbers are the bound sampler's own, bit for bit.
///
/// Beyond the sampler's distance, gradient and closest triangle it gives what users of a
/// distance query expect: the closest point with its barycentric coordinates on the closest
/// triangle (in the input's face and vertex order), the unsigned distance (sign "none"),
/// and the generalized winding number (occupancy).
#pragma once

#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "core/sampling/sampler.h"
#include "core/winding/winding_sign.h"

namespace sdf {

/// The closest point of a query point on its closest triangle.
struct ClosestPointOnMesh {
    Vec3d point{};        ///< on the prepared (welded) triangle
    /// Weights of the input face's three vertices, in the input's order: point =
    /// sum_k barycentric[k] * vertex(face[k]); each in [0, 1], summing to 1 up to rounding.
    Vec3d barycentric{};
};

class MeshSdf {
public:
    /// Binds `mesh` to the sampler of `options` (backend "cpu" or "cuda": resolve "auto"
    /// first, point_query.h) and builds its BVH, winding data and device upload. With
    /// `unsigned_distance`, the sign step is skipped: distances are |d| and gradients point
    /// away from the surface (the sampler runs with the pseudonormal sign, whose magnitudes
    /// are every mode's). Throws std::invalid_argument for options the sampler table refuses.
    MeshSdf(std::shared_ptr<const PreparedMesh> mesh, const SamplerOptions& options, bool unsigned_distance = false);
    ~MeshSdf();

    const PreparedMesh& mesh() const { return *mesh_; }
    const std::shared_ptr<const PreparedMesh>& shared_mesh() const { return mesh_; }
    const SamplerOptions& options() const { return options_; }
    const std::string& sampler_name() const { return sampler_name_; }
    /// The sign actually used: "pseudonormal", "winding" (auto resolved by the mesh's
    /// report, choose_sign_mode) or "none"; and why.
    const std::string& sign_mode() const { return sign_mode_; }
    const std::string& sign_reason() const { return sign_reason_; }
    /// Wall time of the construction (BVH, winding data, upload), seconds.
    double build_seconds() const { return build_seconds_; }

    /// Samples arbitrary points, returned in input order. Thread-safe (the bound sampler's
    /// queries are const; the GPU's serialise themselves).
    std::vector<PointSample> query(const std::vector<Vec3d>& points) const;
    /// Samples points in GPU memory, writing the results there in input order
    /// (core/sampling/device_query.h): bit for bit query()'s, with no host copy of either.
    /// Throws std::invalid_argument unless the bound sampler runs on a GPU. The distance is
    /// the signed one even with unsigned_distance (the caller takes |d| on its device).
    void query_device(const DevicePoints& points, const DeviceQueryResults& results) const;
    /// Samples points in the caller's host arrays (a NumPy array's buffer), writing the
    /// results into the caller's columns in input order (core/sampling/host_query.h): bit for
    /// bit query()'s, with no conversion in between (the GPU sampler streams both through
    /// pinned buffers). With unsigned_distance, |d| and the matching gradient. `timings`
    /// (optional) receives the sampler's timings of this call (kernel, transfers, total).
    void query_host(const HostPoints& points, const HostQueryResults& results, SamplingTimings* timings = nullptr) const;
    /// Samples every point of the lattice; with unsigned_distance, |d| everywhere.
    SampledField sample(const Lattice& lattice) const;
    /// The sparse narrow band of width `width` (core/sampling/sparse_band.h) by the bound
    /// sampler; densified, it is sample()'s field with band_width = width. Signed only. It
    /// holds `channels` (BoundSampler::sample_band_sparse).
    SparseBandField sample_band(const Lattice& lattice, double width, BandChannels channels = {}) const;

    /// The closest point of p on input face `triangle` (a query's PointSample::triangle).
    ClosestPointOnMesh closest_point(const Vec3d& p, int32_t triangle) const;
    /// closest_point() of every point i and triangle[i], into point[3i..] and barycentric[3i..]
    /// (either may be null), on `threads` threads (0: all).
    void closest_points(const HostPoints& points, const int32_t* triangle, double* point, double* barycentric,
                        int threads) const;

    /// How winding_numbers() evaluates.
    enum class Winding {
        /// Barill et al.'s fast evaluation at the winding sign's first accuracy
        /// (SamplerSign::winding_options: beta 2, order 2); its data are built on the first
        /// call. Not exact: off by up to a few hundredths near overlapping parts; each value
        /// comes with a rigorous bound of its truncation error (fast_winding_number.h,
        /// rounding aside). The winding sign is not this value's side of 1/2 but the
        /// certified side of the exact w (certified_winding.h), which this value may miss
        /// where it is within its bound of 1/2.
        Fast,
        /// The direct sum of every triangle's exact solid angle (Van Oosterom & Strackee,
        /// kernels/winding/solid_angle.h): O(triangles) per point.
        Exact,
    };
    /// The generalized winding number of every point (Jacobson et al. 2013): about 1 inside a
    /// closed outward mesh, 0 outside, fractional near holes. With Fast, `error_bound` (may be
    /// null) receives each value's bound: |value - exact| <= bound, rounding aside.
    std::vector<double> winding_numbers(const std::vector<Vec3d>& points, int threads, Winding evaluation = Winding::Fast,
                                        std::vector<double>* error_bound = nullptr) const;

private:
    std::shared_ptr<const PreparedMesh> mesh_;
    SamplerOptions options_;
    bool unsigned_distance_;
    std::unique_ptr<BoundSampler> bound_;
    std::string sampler_name_, sign_mode_, sign_reason_;
    double build_seconds_ = 0;
    std::vector<int32_t> prepared_of_input_;  ///< input face -> prepared triangle (-1: dropped)
    mutable std::mutex winding_mutex_;
    mutable std::shared_ptr<const WindingSign> winding_;
};

/// Unsigned distance in place: |d|, and the gradient turned to point away from the surface.
void make_unsigned(std::vector<PointSample>& samples);
void make_unsigned(SampledField& field);

}  // namespace sdf
