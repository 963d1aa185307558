#include "harness/sampling/mesh_sdf.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "core/parallel/parallel_for.h"
#include "core/sampling/sampler_sign.h"
#include "harness/sampling/sampler_table.h"
#include "kernels/distance/closest_point_on_triangle.h"
#include "kernels/winding/solid_angle.h"

namespace sdf {

MeshSdf::MeshSdf(std::shared_ptr<const PreparedMesh> mesh, const SamplerOptions& options, bool unsigned_distance)
    : mesh_(std::move(mesh)), options_(options), unsigned_distance_(unsigned_distance) {
    if (!mesh_) throw std::invalid_argument("MeshSdf: no mesh");
    const auto start = std::chrono::steady_clock::now();
    if (unsigned_distance_) options_.sign = SignMode::Pseudonormal;  // magnitudes are every mode's
    bound_ = make_sampler(options_)->bind(mesh_);  // the BVH, winding data and device upload
    sampler_name_ = bound_->name();
    if (unsigned_distance_) {
        sign_mode_ = "none";
        sign_reason_ = "unsigned distance requested";
    } else {
        sign_mode_ = sign_mode_name(bound_->sign().mode);
        sign_reason_ = bound_->sign().reason;
    }
    prepared_of_input_.assign(size_t(mesh_->report().input_triangles), -1);
    const std::vector<int>& source = mesh_->source_triangle();
    for (size_t t = 0; t < source.size(); ++t) prepared_of_input_[size_t(source[t])] = int32_t(t);
    build_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

MeshSdf::~MeshSdf() = default;

std::vector<PointSample> MeshSdf::query(const std::vector<Vec3d>& points) const {
    std::vector<PointSample> samples = bound_->query(points);
    if (unsigned_distance_) make_unsigned(samples);
    return samples;
}

void MeshSdf::query_device(const DevicePoints& points, const DeviceQueryResults& results) const {
    if (!bound_->query_device(points, results))
        throw std::invalid_argument("points on a GPU need an SDF whose backend is cuda; this one's sampler is '" +
                                    sampler_name_ + "'");
}

void MeshSdf::query_host(const HostPoints& points, const HostQueryResults& results, SamplingTimings* timings) const {
    const auto start = std::chrono::steady_clock::now();
    // The sampler's timings of this call; a sampler that measures no total gets the call's wall time.
    auto record = [&] {
        if (timings && timings->total <= 0)
            timings->total = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    };
    if (!unsigned_distance_) {
        bound_->query_host(points, results, timings);
        record();
        return;
    }
    // |d| needs d's sign for the gradient's flip, also where the caller asked for no distance.
    std::vector<double> own_distance;
    HostQueryResults r = results;
    if (!r.distance && r.gradient) {
        own_distance.resize(size_t(std::max<int64_t>(points.count, 0)));
        r.distance = own_distance.data();
    }
    bound_->query_host(points, r, timings);
    record();
    if (!r.distance) return;
    parallel_for(points.count, int64_t(1) << 16, options_.threads, [&](int64_t b, int64_t e) {
        for (int64_t i = b; i < e; ++i)
            if (std::signbit(r.distance[i])) {
                r.distance[i] = -r.distance[i];
                if (r.gradient)
                    for (int k = 0; k < 3; ++k) r.gradient[3 * i + k] = -r.gradient[3 * i + k];
            }
    });
}

void MeshSdf::closest_points(const HostPoints& points, const int32_t* triangle, double* point, double* barycentric,
                             int threads) const {
    parallel_for(points.count, int64_t(1) << 14, threads, [&](int64_t b, int64_t e) {
        for (int64_t i = b; i < e; ++i) {
            const ClosestPointOnMesh c = closest_point(points[i], triangle[i]);
            if (point) point[3 * i] = c.point.x, point[3 * i + 1] = c.point.y, point[3 * i + 2] = c.point.z;
            if (barycentric)
                barycentric[3 * i] = c.barycentric.x, barycentric[3 * i + 1] = c.barycentric.y, barycentric[3 * i + 2] = c.barycentric.z;
        }
    });
}

SampledField MeshSdf::sample(const Lattice& lattice) const {
    SampledField field = bound_->sample(lattice);
    if (unsigned_distance_) {
        make_unsigned(field);
        field.sampler.details["sign"] = {{"requested", "none"}, {"mode", "none"}, {"reason", sign_reason_}};
    }
    return field;
}

SparseBandField MeshSdf::sample_band(const Lattice& lattice, double width, BandChannels channels) const {
    if (unsigned_distance_)
        throw std::invalid_argument("band: a sparse band holds signed distances (inside tiles are -W); not with sign=\"none\"");
    if (!(width > 0) || !std::isfinite(width))
        throw std::invalid_argument("band: expected a positive width in mesh units, got " + std::to_string(width));
    return bound_->sample_band_sparse(lattice, width, channels);
}

ClosestPointOnMesh MeshSdf::closest_point(const Vec3d& p, int32_t triangle) const {
    if (triangle < 0 || size_t(triangle) >= prepared_of_input_.size() || prepared_of_input_[size_t(triangle)] < 0)
        throw std::invalid_argument("closest_point: " + std::to_string(triangle) + " is not a face of the prepared mesh");
    const int32_t t = prepared_of_input_[size_t(triangle)];
    const Int3 tri = mesh_->triangles()[size_t(t)];
    const std::vector<Vec3d>& v = mesh_->vertices();
    // The sampler's own evaluation of the winner (signed_distance_to_triangle), in double.
    const TriangleClosestPoint<double> cp = closest_point_on_triangle(p, v[size_t(tri.x)], v[size_t(tri.y)], v[size_t(tri.z)]);
    ClosestPointOnMesh out;
    out.point = cp.point;
    const double w0 = 1.0 - cp.s - cp.t, w1 = cp.s, w2 = cp.t;
    // Preparation keeps each face's corners in order, except that flipping an inward mesh
    // swaps the second and third (prepared_mesh.cpp).
    out.barycentric = mesh_->report().flipped ? Vec3d{w0, w2, w1} : Vec3d{w0, w1, w2};
    return out;
}

std::vector<double> MeshSdf::winding_numbers(const std::vector<Vec3d>& points, int threads, Winding evaluation,
                                             std::vector<double>* error_bound) const {
    std::vector<double> w(points.size());
    if (evaluation == Winding::Exact) {
        const MeshView<double> view = mesh_->buffers<double>().view();
        // Chunks of about a million solid angles: a stop request is honoured within one.
        const int64_t chunk = std::max<int64_t>(1, (int64_t(1) << 20) / std::max<int64_t>(1, view.num_triangles));
        parallel_for(int64_t(points.size()), chunk, threads, [&](int64_t begin, int64_t end) {
            for (int64_t i = begin; i < end; ++i) w[size_t(i)] = winding_number_exact(view, points[size_t(i)]);
        });
        return w;
    }
    std::shared_ptr<const WindingSign> winding;
    {
        std::lock_guard<std::mutex> lock(winding_mutex_);
        if (!winding_) winding_ = std::make_shared<const WindingSign>(*mesh_, SamplerSign::winding_options());
        winding = winding_;
    }
    if (error_bound) error_bound->assign(points.size(), 0.0);
    parallel_for(int64_t(points.size()), 256, threads, [&](int64_t begin, int64_t end) {
        for (int64_t i = begin; i < end; ++i) {
            const WindingEstimate<double> e = winding->estimate(points[size_t(i)]);
            w[size_t(i)] = e.value;
            if (error_bound) (*error_bound)[size_t(i)] = e.error_bound;
        }
    });
    return w;
}

void make_unsigned(std::vector<PointSample>& samples) {
    for (PointSample& s : samples)
        if (std::signbit(s.distance)) {
            s.distance = -s.distance;
            s.gradient = -s.gradient;
        }
}

void make_unsigned(SampledField& field) {
    const bool gradient = field.gradient.size() == field.distance.size();
    for (size_t i = 0; i < field.distance.size(); ++i)
        if (std::signbit(field.distance[i])) {
            field.distance[i] = -field.distance[i];
            if (gradient) field.gradient[i] = -field.gradient[i];
        }
}

}  // namespace sdf
