#include "cpu_reference/sampling/brute_force_cpu.h"

#include <stdexcept>
#include <type_traits>

#include "core/parallel/parallel_for.h"
#include "core/parallel/progress.h"
#include "cpu_reference/dispatch/cpu_kernels.h"
#include "cpu_reference/sampling/nearest_triangle_cpu.h"
#include "core/sampling/backend_sampler.h"
#include "core/sampling/sampler_results.h"
#include "kernels/distance/signed_distance.h"

namespace sdf {
namespace {

using CpuKernel = CpuBruteForceKernel;

/// The double search's winner at p from the certified float search's winner and candidates
/// (search_certificate.h); with too many candidates, every triangle within the radius is
/// collected by one more float pass and re-ranked. counts: points, re-ranked, full pass.
int certify_brute_force(const CpuCertifiedKernels& kernels, const TriangleSoA<float>& soa, const PackedTriangle<double>* exact,
                        const Vec3d& p, int winner, float best_q, const CpuCertifiedNear& near, int64_t* counts) {
    const float radius = near.radius(best_q);
    const NearCandidates<float, kCpuNearCandidates>& c = near.near;
    Rerank r = kernels.rerank(exact, nullptr, p, winner, radius, c.slot, c.q, c.count, c.dropped);
    if (r.overflow) {
        // The same float pass keeps every triangle within its (shrinking) radius, so all
        // within the final one, which is this radius: best_q is the same float minimum.
        AllNear all{near.slack, {}, {}};
        const Vec3f pf(p);
        int again = -1;
        float again_q = 0;
        kernels.nearest_triangles_all(soa, 1, &pf.x, &pf.y, &pf.z, &again, &again_q, &all);
        r = kernels.rerank(exact, nullptr, p, winner, radius, all.slot.data(), all.q.data(), int(all.slot.size()), NAN);
        r.reranked = true;
        ++counts[2];
    }
    ++counts[0];
    counts[1] += r.reranked;
    return r.slot;
}

/// Evaluates n points: pos(i) gives the position, emit(i, sample) receives the result.
/// The nearest triangle is searched in precision T; the winner is then evaluated in double
/// (closest point, sign, gradient) at the exact double position. The vectorized float search
/// is certified (search_certificate.h), so its triangle is the double search's; the Eberly
/// kernel's float search is not (it ranks by its own formula), so a float run of it differs
/// from a double run where it resolved a near-tie differently. In winding mode `sign` then
/// gives each sample the winding number's certified side, counted in `winding`.
template <typename T, typename PositionFn, typename EmitFn>
void evaluate_points(const PreparedMesh& mesh, CpuKernel kernel, const SamplerSign& sign, int threads, bool progress,
                     int64_t n, double point_coordinate, CertificateCounters& counters, SharedWindingCounts& winding,
                     PositionFn pos, EmitFn emit) {
    const MeshBuffers<T>& buffers = mesh.buffers<T>();
    const MeshView<T> view = buffers.view();
    const MeshView<double> exact = mesh.buffers<double>().view();
    const TriangleSoA<T> soa(buffers.packed);
    constexpr bool kCertify = std::is_same_v<T, float>;
    SearchSlack<float> slack;
    if constexpr (kCertify) slack = make_search_slack(float_search_bound(mesh), point_coordinate);
    const CpuKernels<T>& plain = cpu_kernels<T>();  // the widest ISA the CPU has
    const CpuCertifiedKernels& certified = certified_cpu_kernels();
    ProgressReporter reporter("sampling " + mesh.name(), n, progress);
    parallel_for(n, kPointTile, threads, [&](int64_t begin, int64_t end) {
        const int count = int(end - begin);
        T px[kPointTile], py[kPointTile], pz[kPointTile], best_q[kPointTile];
        int best[kPointTile];
        for (int k = 0; k < count; ++k) {
            const Vec3<T> p(pos(begin + k));
            px[k] = p.x; py[k] = p.y; pz[k] = p.z;
        }
        if (kernel == CpuKernel::Vectorized) {
            if constexpr (kCertify) {
                CpuCertifiedNear near[kPointTile];
                for (int k = 0; k < count; ++k) near[k].slack = slack;
                certified.nearest_triangles(soa, count, px, py, pz, best, best_q, near);
                int64_t counts[3] = {0, 0, 0};
                for (int k = 0; k < count; ++k)
                    best[k] = certify_brute_force(certified, soa, exact.packed, pos(begin + k), best[k], best_q[k], near[k], counts);
                counters.points += counts[0];
                counters.reranked += counts[1];
                counters.full_double += counts[2];
            } else {
                plain.nearest_triangles(soa, count, px, py, pz, best, best_q);
            }
        } else {
            for (int k = 0; k < count; ++k) best[k] = plain.nearest_triangle_eberly(view, Vec3<T>(px[k], py[k], pz[k]));
        }
        WindingSignCounts signed_points;
        for (int k = 0; k < count; ++k) {
            const Vec3d p = pos(begin + k);
            emit(begin + k, sign.apply(signed_distance_to_triangle(exact, p, best[k]), p, signed_points));
        }
        winding.add(signed_points);
        reporter.advance(count);
    });
}

class BoundCpuBruteForce final : public BackendSampler {
public:
    BoundCpuBruteForce(std::shared_ptr<const PreparedMesh> mesh, const SamplerOptions& options, CpuKernel kernel)
        : BackendSampler(std::move(mesh), options, "cpu", "brute_force", kernel_name(kCpuBruteForceKernels, kernel)),
          kernel_(kernel) {
        sign_.prepare(this->mesh());
    }

private:
    std::vector<PointSample> query_points(const std::vector<Vec3d>& points, SamplingTimings&,
                                          CertificateCounters& certificate) const override {
        std::vector<PointSample> out = unfilled_point_samples(points.size(), options_.threads);
        const double coordinate = largest_coordinate(points, options_.threads);
        SharedWindingCounts unreported;  // a query has no report
        with_precision(options_.precision, [&](auto zero) {
            using T = decltype(zero);
            evaluate_points<T>(mesh(), kernel_, sign_, options_.threads, options_.progress, int64_t(points.size()), coordinate,
                               certificate, unreported, [&](int64_t i) { return points[size_t(i)]; },
                               [&](int64_t i, const SignedDistanceSample<double>& s) {
                                   out[size_t(i)] = point_sample(mesh(), s.distance, s.gradient, s.triangle);
                               });
        });
        return out;
    }

    SampledField sample_blocks(SlabRun& run) const override {
        const Lattice& lattice = run.lattice;
        SampledField field = unfilled_field(mesh(), lattice, run.slab, options_.precision);
        const double coordinate = largest_lattice_coordinate(lattice);
        for (const GridBlock& block : run) {
            with_precision(options_.precision, [&](auto zero) {
                evaluate_points<decltype(zero)>(
                    mesh(), kernel_, sign_, options_.threads, options_.progress, block.count(), coordinate, run.certificate, run.winding,
                    [&](int64_t i) { return lattice.position_of_coords(block.coords(i)); },
                    [&](int64_t i, const SignedDistanceSample<double>& s) {
                        const int64_t out = block.output_index(lattice, i);
                        if (out < 0) return;  // strategy A: not a BCC point
                        store_sample(field, out, mesh(), s.distance, s.gradient, s.triangle);
                    });
            });
            run.computed += block.count();
        }
        run.details["threads"] = resolve_thread_count(options_.threads);
        run.certified = kernel_ == CpuKernel::Vectorized;
        run.band_applied = false;  // brute force tests every pair anyway: the band by post-processing
        return field;
    }

    CpuKernel kernel_;
};

}  // namespace

std::unique_ptr<Sampler> make_cpu_brute_force_sampler(const SamplerOptions& options) {
    auto sampler = std::make_unique<BackendFactory<BoundCpuBruteForce, CpuKernel>>(options, "cpu", "brute_force",
                                                                                   kCpuBruteForceKernels, "CPU brute-force");
    active_cpu_kernels();  // a bad SDF_CPU_ISA is reported here, before any work
    return sampler;
}

}  // namespace sdf
