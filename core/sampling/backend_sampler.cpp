#include "core/sampling/backend_sampler.h"

#include <stdexcept>

#include "core/sampling/sampler_results.h"
#include "core/sampling/search_range.h"
#include "core/sampling/sparse_band_sampler.h"

namespace sdf {

BoundSampler::BoundSampler(std::shared_ptr<const PreparedMesh> mesh) : mesh_(std::move(mesh)) {
    if (!mesh_) throw std::invalid_argument("a sampler cannot be bound to no mesh");
}

SampledField sample_once(const Sampler& sampler, std::shared_ptr<const PreparedMesh> mesh, const Lattice& lattice) {
    return sampler.bind(std::move(mesh))->sample(lattice);
}

std::vector<PointSample> query_once(const Sampler& sampler, std::shared_ptr<const PreparedMesh> mesh,
                                    const std::vector<Vec3d>& points, SamplingTimings* timings) {
    return sampler.bind(std::move(mesh))->query(points, timings);
}

BackendSampler::BackendSampler(std::shared_ptr<const PreparedMesh> mesh, const SamplerOptions& options, const char* backend,
                               const char* method, const char* kernel)
    : BoundSampler(std::move(mesh)), options_(options), sign_(options.sign), backend_(backend), method_(method),
      kernel_(kernel) {
    require_band_width(options_.band_width, "sampler band_width");
    solid_ = choose_sign_mode(this->mesh().report(), SignMode::Auto).mode == SignMode::Pseudonormal;
}

SampledField BackendSampler::sample_slab(const Lattice& lattice, const LatticeSlab& slab) const {
    SlabRun run(lattice, slab, options_.bcc_strategy);
    SampledField field = sample_blocks(run);
    finish_slab(field, run);
    return field;
}

void BackendSampler::finish_slab(SampledField& field, SlabRun& run, std::optional<NarrowBandCounts> band) const {
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - run.start).count();
    const double w = options_.band_width;
    if (w > 0 && !band) band = run.band_applied ? count_narrow_band(field) : apply_narrow_band(field, w);
    const int64_t computed = run.computed - (run.skip_counts ? run.skip_counts->points_skipped : 0);
    SamplingTimings& t = field.timings;
    t.upload = run.device.upload;
    t.download = run.device.download;
    t.kernel = run.device.kernel > 0 ? run.device.kernel : seconds;
    t.total = seconds;
    t.point_triangle_pairs = double(computed) * double(mesh().triangles().size());
    field.sampler = sampler_provenance(backend_, method_, kernel_, options_, run.lattice, computed, sign_);
    for (auto it = run.details.begin(); it != run.details.end(); ++it) field.sampler.details[it.key()] = it.value();
    record_certificate(t, run.certificate);
    field.sampler.search_certificate = certificate_provenance(float_search(), run.certified, run.certificate);
    if (sign_.winding()) {
        const WindingSignCounts c = run.winding.load();
        field.sampler.winding_sign = WindingSignReport{c.fast, c.refined, c.direct, c.ties, c.surface, c.nearest};
    }
    if (w > 0) {
        BandReport report = narrow_band_provenance(
            w, *band, run.band_skips ? "bricks skipped by the distance bound" : "post-processed");
        if (run.skip_counts) {
            report.counts_skips = true;
            report.probes = run.skip_counts->probes;
            report.bricks_skipped = run.skip_counts->bricks_skipped;
            report.points_skipped = run.skip_counts->points_skipped;
        }
        field.sampler.band = report;
    }
}

SparseBandField BackendSampler::sample_band_sparse(const Lattice& lattice, double width, BandChannels channels) const {
    require_band_width(width, "sparse band width");
    SparseBandPlan plan;
    plan.precision = options_.precision;
    plan.threads = options_.threads;
    plan.channels = channels;
    SparseBandField band = sample_sparse_band(*this, lattice, width, plan, band_block_kernel(width));
    band.sampler.backend = backend_;
    band.sampler.method = method_;
    band.sampler.kernel = kernel_;
    return band;
}

std::vector<PointSample> BackendSampler::query(const std::vector<Vec3d>& points, SamplingTimings* timings) const {
    const auto start = std::chrono::steady_clock::now();
    require_search_range(mesh(), points, options_.precision, options_.threads);
    SamplingTimings t;
    CertificateCounters certificate;
    std::vector<PointSample> out = points.empty() ? std::vector<PointSample>() : query_points(points, t, certificate);
    if (timings) {
        record_certificate(t, certificate);
        t.point_triangle_pairs = double(points.size()) * double(mesh().triangles().size());
        if (t.total <= 0) t.total = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        *timings = t;
    }
    return out;
}

}  // namespace sdf
