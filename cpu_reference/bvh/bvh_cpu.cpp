// The CPU BVH sampler bound to its mesh: the mesh's BVH and the sign's winding moments are
// made at binding; lattices go through bvh_cpu_bricks.h (kernel "brick") or the one-point
// path of bvh_cpu_search.h, point lists through bvh_cpu_points.h.
#include "cpu_reference/bvh/bvh_cpu.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "core/sampling/backend_sampler.h"
#include "core/sampling/host_query.h"
#include "core/sampling/sampler_results.h"
#include "cpu_reference/bvh/bvh_cpu_bricks.h"
#include "cpu_reference/bvh/bvh_cpu_points.h"
#include "cpu_reference/bvh/bvh_cpu_search.h"
#include "cpu_reference/bvh/bvh_cpu_sweep.h"

namespace sdf {
namespace {

using namespace cpu_bvh;

class BoundCpuBvh final : public BackendSampler {
public:
    BoundCpuBvh(std::shared_ptr<const PreparedMesh> mesh, const SamplerOptions& options, BvhKernel kernel)
        : BackendSampler(std::move(mesh), options, "cpu", "bvh", kernel_name(kCpuBvhKernels, kernel)), kernel_(kernel) {
        bvh_ = this->mesh().bvh(&built_);  // the mesh's own, built once (unless its preparation did)
        sign_.prepare(this->mesh());       // over the same BVH: only the winding moments are added
        band_ = band_skip();
    }

private:
    /// "seeded" queries point lists one by one, each seeded with the previous point's
    /// triangle; "brick" sorts them into Morton-ordered packets (evaluate_point_packets).
    bool seeded() const { return kernel_ != BvhKernel::Unseeded; }

    /// Kernel "brick"'s query of `points` (a vector or the caller's arrays) in Morton-ordered
    /// packets, each result to `store(i, sample)`. 32-bit indices in the sort.
    template <typename Points, typename Store>
    void query_packets(const Points& points, CertificateCounters& certificate, Store store) const {
        SharedWindingCounts unreported;  // a query has no report
        QueryCounters counters(certificate, unreported);
        const double coordinate = largest_coordinate(points, options_.threads);
        with_precision(options_.precision, [&](auto zero) {
            using T = decltype(zero);
            evaluate_point_packets<T>(mesh(), *bvh_, sign_, points, options_.threads, options_.progress, coordinate, counters,
                                      [&](int64_t i, const SignedDistanceSample<double>& s) {
                                          store(i, point_sample(mesh(), s.distance, s.gradient, s.triangle));
                                      });
        });
    }
    bool packets_for(int64_t count) const { return kernel_ == BvhKernel::Brick && count < (int64_t(1) << 32); }

    std::vector<PointSample> query_points(const std::vector<Vec3d>& points, SamplingTimings&,
                                          CertificateCounters& certificate) const override {
        std::vector<PointSample> out = unfilled_point_samples(points.size(), options_.threads);
        if (packets_for(int64_t(points.size()))) {
            query_packets(points, certificate, [&](int64_t i, const PointSample& r) { out[size_t(i)] = r; });
            return out;
        }
        SharedWindingCounts unreported;  // a query has no report
        QueryCounters counters(certificate, unreported);
        const double coordinate = largest_coordinate(points, options_.threads);
        with_precision(options_.precision, [&](auto zero) {
            using T = decltype(zero);
            evaluate_points<T>(mesh(), *bvh_, sign_, seeded(), options_.threads, options_.progress, int64_t(points.size()),
                               coordinate, counters, [&](int64_t i) { return points[size_t(i)]; },
                               [&](int64_t i, const SignedDistanceSample<double>& s) {
                                   out[size_t(i)] = point_sample(mesh(), s.distance, s.gradient, s.triangle);
                               });
        });
        return out;
    }

    /// The caller's arrays read where they are and the results written into its columns, on
    /// every thread (kernel "brick"): no gathered copy of the points, no vector of samples to
    /// scatter (for a million points 64 MB written on the calling thread before). The bits of
    /// query() on the same points.
    void query_host(const HostPoints& points, const HostQueryResults& results, SamplingTimings* timings) const override {
        if (!packets_for(points.count)) {
            BackendSampler::query_host(points, results, timings);
            return;
        }
        if (points.count <= 0) return;
        const auto start = std::chrono::steady_clock::now();
        require_finite_points(points, "points", options_.threads);
        require_search_range(mesh(), points, options_.precision, options_.threads);
        CertificateCounters certificate;
        query_packets(points, certificate, [&](int64_t i, const PointSample& r) { store_result(results, i, r); });
        if (timings) {
            SamplingTimings t;
            record_certificate(t, certificate);
            t.point_triangle_pairs = double(points.count) * double(mesh().triangles().size());
            t.total = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            *timings = t;
        }
    }

    SampledField sample_blocks(SlabRun& run) const override {
        const Lattice& lattice = run.lattice;
        SampledField field = unfilled_field(mesh(), lattice, run.slab, options_.precision);
        const double w = options_.band_width;
        QueryCounters counters(run.certificate, run.winding);
        BandCounters band_counters;
        for (const GridBlock& block : run) {
            auto emit = [&](int64_t i, const SignedDistanceSample<double>& s) {
                const int64_t out = block.output_index(lattice, i);
                if (out < 0) return;  // strategy A: not a BCC point
                if (outside_band(s.distance, w)) store_outside_band(field, out, std::signbit(s.distance), w);
                else store_sample(field, out, mesh(), s.distance, s.gradient, s.triangle);
            };
            auto emit_outside = [&](int64_t i, BandSide side) {  // a probe's ball: a side always
                const int64_t out = block.output_index(lattice, i);
                if (out >= 0) store_outside_band(field, out, side == kBandSideInside, w);
            };
            with_precision(options_.precision, [&](auto zero) {
                using T = decltype(zero);
                if (kernel_ == BvhKernel::Brick)
                    evaluate_bricks<T>(mesh(), *bvh_, sign_, lattice, block, options_.threads, options_.progress, band_,
                                       counters, band_counters, emit, emit_outside);
                else
                    evaluate_points<T>(mesh(), *bvh_, sign_, seeded(), options_.threads, options_.progress, block.count(),
                                       largest_lattice_coordinate(lattice), counters,
                                       [&](int64_t i) { return lattice.position_of_coords(block.coords(i)); }, emit);
            });
            run.computed += block.count();
        }
        const int64_t computed = run.computed - band_counters.points_skipped;
        nlohmann::json bvh_info = bvh_->stats.to_json();
        bvh_info["built_by_bind"] = built_;
        bvh_info["node_visits_per_point"] = computed > 0 ? double(counters.nodes) / double(computed) : 0.0;
        bvh_info["point_triangle_tests_per_point"] = computed > 0 ? double(counters.triangles) / double(computed) : 0.0;
        run.details["threads"] = resolve_thread_count(options_.threads);
        run.details["bvh"] = bvh_info;
        run.band_skips = band_.enabled();
        if (w > 0) {
            BandReport skips;
            skips.probes = band_counters.probes.load();
            skips.bricks_skipped = band_counters.bricks_skipped.load();
            skips.points_skipped = band_counters.points_skipped.load();
            run.skip_counts = skips;
        }
        return field;
    }

    /// A sparse band's active blocks, each block of 8^3 points one GridBlock: the same values
    /// as the dense band's, every lattice point's channels written (the arrays come unwritten;
    /// padding is the sampler's), the gradient only when the band holds it. On a solid with a
    /// band at least a spacing wide the triangles sweep each block (bvh_cpu_sweep.h: the double
    /// search's triangle of every point within the band) and the points beyond it take their
    /// sides from their neighbours (band_sides.h); every other band runs the dense path's
    /// brick kernel with its brick skip.
    BandBlockKernel band_block_kernel(double width) const override {
        if (kernel_ != BvhKernel::Brick) return {};
        const BandSkip skip = band_skip(width);
        if (!skip.enabled()) return {};  // a pseudonormal sign off a solid: every point searched by the queries
        return [this, skip](SparseBandField& out, size_t first, size_t last) {
            const BandLayout& layout = out.layout();
            const Lattice& lattice = out.lattice;
            const BandSkip& band = skip;
            // The sweep where the sides beyond the band come from the neighbours (band_sides.h).
            const bool swept = band.probe_sign && band.winding == nullptr && band.width >= lattice.spacing;
            const double scale = band.coordinate_scale + largest_lattice_coordinate(lattice);
            const double sweep_bound = band_sweep_bound_squared(band.width, scale);
            CertificateCounters certificate;
            SharedWindingCounts winding;  // a sparse band's report has no winding counters (as queries)
            QueryCounters counters(certificate, winding);
            BandCounters band_counters;
            std::atomic<int64_t> searched_blocks{0}, flooded{0};
            parallel_for(int64_t(last - first), 8, options_.threads, [&](int64_t begin, int64_t end) {
                SweepScratch scratch;
                int64_t beyond = 0;
                for (size_t a = first + size_t(begin); a < first + size_t(end); ++a) {
                    const BandBlockCoords b = layout.block_coords(out.active[a]);
                    const BandCoset& coset = layout.coset(b.coset);
                    const Int3 p0{b.block.x * kBandBlockDim, b.block.y * kBandBlockDim, b.block.z * kBandBlockDim};
                    const Int3 r{std::min(kBandBlockDim, coset.points.x - p0.x), std::min(kBandBlockDim, coset.points.y - p0.y),
                                 std::min(kBandBlockDim, coset.points.z - p0.z)};
                    const GridBlock block{{coset.first.x + 2 * p0.x, coset.first.y + 2 * p0.y, coset.first.z + 2 * p0.z}, 2, r, 0, false};
                    const size_t base = a * kBandBlockPoints;
                    const auto local_of = [&](int64_t i) {  // GridBlock's index to the block's
                        const int x = int(i % r.x), y = int((i / r.x) % r.y), z = int(i / (int64_t(r.x) * r.y));
                        return x + kBandBlockDim * (y + kBandBlockDim * z);
                    };
                    // Each point's side for the flood (padding has none and is never open).
                    BandSideLayers sides;
                    bool flood = false;
                    const bool gradient = out.channels.gradient, triangle = out.channels.closest_triangle;
                    BandPointMask in_band{};  // the block's band points
                    const auto store_outside = [&](size_t v, bool negative) {
                        out.distance.set(v, negative ? -band.width : band.width);
                        if (gradient) out.gradient[v] = Vec3d(0.0);
                        if (triangle) out.closest_triangle[v] = kOutsideBandTriangle;
                    };
                    // By block-local index (x + 8 y + 64 z).
                    auto emit_at = [&](int local, const SignedDistanceSample<double>& s) {
                        const size_t v = base + size_t(local);
                        sides.set(local, std::signbit(s.distance) ? kBandSideInside : kBandSideOutside);
                        if (outside_band(s.distance, band.width)) {
                            store_outside(v, std::signbit(s.distance));
                            return;
                        }
                        out.distance.set(v, s.distance);
                        if (gradient) out.gradient[v] = s.gradient;
                        if (triangle) out.closest_triangle[v] = s.triangle < 0 ? s.triangle : mesh().source_triangle()[size_t(s.triangle)];
                        set_mask_bit(in_band, local);
                    };
                    auto outside_at = [&](int local, BandSide s) {
                        sides.set(local, s);
                        flood = flood || s == kBandSideNone;
                        store_outside(base + size_t(local), s == kBandSideInside);
                    };
                    if (swept) {
                        beyond += sweep_block(mesh(), *bvh_, lattice, block, sweep_bound, scale, scratch, emit_at, outside_at);
                    } else {
                        auto emit = [&](int64_t i, const SignedDistanceSample<double>& s) { emit_at(local_of(i), s); };
                        auto emit_outside = [&](int64_t i, BandSide s) { outside_at(local_of(i), s); };
                        with_precision(options_.precision, [&](auto zero) {
                            using T = decltype(zero);
                            evaluate_bricks<T>(mesh(), *bvh_, sign_, lattice, block, 1, false, band, counters, band_counters,
                                               emit, emit_outside);
                        });
                    }
                    out.band_mask[a] = in_band;
                    if (!flood) continue;
                    if (!sides.any_known()) {  // its point 0 by the double search
                        sides.set(0, nearest_side_inside(lattice.position_of_coords(block.first)) ? kBandSideInside : kBandSideOutside);
                        ++searched_blocks;
                    }
                    if (!sides.spread()) {  // neighbours beyond the band on opposite sides
                        const Vec3d p = lattice.position_of_coords(block.first);
                        throw std::runtime_error(
                            "CPU BVH sparse band: " + mesh().name() + ": points beyond the band in the block at (" +
                            std::to_string(p.x) + ", " + std::to_string(p.y) + ", " + std::to_string(p.z) +
                            ") have neighbours on both sides by the pseudonormal sign, which is not consistent there "
                            "(slivers within the search's rounding of a sharp edge?); sample this mesh with the winding "
                            "sign (--sign winding, sampler \"sign\": \"winding\")");
                    }
                    for (int z = 0; z < kBandBlockDim; ++z)
                        for (uint64_t in = sides.open[z] & sides.inside[z]; in != 0; in &= in - 1)
                            out.distance.set(base + size_t(64 * z + __builtin_ctzll(in)), -band.width);
                }
                flooded += beyond;
            });
            out.sampler.details["band_blocks_on_host"] = {{"bounded_search", swept},
                                                          {"nearest", swept ? "triangle_sweep" : "search"},
                                                          {"points_flooded", flooded.load()},
                                                          {"blocks_signed_by_a_search", searched_blocks.load()}};
        };
    }

    /// Whether p is inside by the pseudonormal sign at its nearest triangle, found by the
    /// double search (the reference: exact where a float search may tie across a thin part;
    /// p lies beyond the band of a solid).
    bool nearest_side_inside(const Vec3d& p) const {
        BvhStats stats;
        const BvhView<double> view = bvh_->view<double>();
        const BvhHit<double> hit = cpu_kernels<double>().closest_triangle(view, p, seed_hit(view, -1, p), stats);
        return signed_distance_to_triangle(mesh().buffers<double>().view(), p, view.triangle_index[hit.slot]).distance < 0;
    }

    /// The brick skip of the band: with the winding sign (each point's own), or with the
    /// pseudonormal sign where the mesh is the solid that makes it one side per ball; a
    /// pseudonormal sign requested on any other mesh computes every point (and bands them
    /// afterwards), as does the "seeded"/"unseeded" kernel.
    BandSkip band_skip() const { return band_skip(options_.band_width); }
    BandSkip band_skip(double w) const {
        BandSkip band;
        band.width = w;
        if (w <= 0) return band;
        band.winding = sign_.winding() ? sign_.winding_sign() : nullptr;
        band.probe_sign = !sign_.winding() && solid();
        // Float searches choose among triangles within a few ulps (2^-24) of the minimum.
        band.relative_margin = float_search() ? 1e-5 : 1e-12;
        const FloatSearchBound& bound = mesh().search_bound();
        band.sliver_reach = float_search() ? bound.sliver_reach_float : bound.sliver_reach_double;
        const MeshView<double> exact = mesh().buffers<double>().view();
        for (const Vec3d& v : {exact.box_lo, exact.box_hi})
            band.coordinate_scale = std::max({band.coordinate_scale, std::abs(v.x), std::abs(v.y), std::abs(v.z)});
        return band;
    }

    BvhKernel kernel_;
    std::shared_ptr<const TriangleBvh> bvh_;
    bool built_ = false;  ///< the mesh's BVH was built by this binding (else by its preparation or another)
    BandSkip band_;
};

}  // namespace

std::unique_ptr<Sampler> make_cpu_bvh_sampler(const SamplerOptions& options) {
    auto sampler = std::make_unique<BackendFactory<BoundCpuBvh, BvhKernel>>(options, "cpu", "bvh", kCpuBvhKernels, "CPU BVH");
    active_cpu_kernels();  // a bad SDF_CPU_ISA is reported here, before any work
    return sampler;
}

}  // namespace sdf
