// One field sampled slab by slab over the ranks and gathered by the root (slab_exchange.h).
#include "harness/distributed/slab_exchange.h"

#include <algorithm>
#include <chrono>

#include "core/lattice/lattice_fitting.h"
#include "harness/distributed/fault_injection.h"
#include "harness/distributed/mpi_session.h"
#include "harness/distributed/mpi_transport.h"

namespace sdf::mpi {

namespace {

/// Copies a rank's part (its slab's primary points, then its secondary ones) to its offsets.
void place_part(SampledField& field, const Lattice& lattice, const LatticeSlab& slab, const SampledField& part) {
    if (part.size() == 0) return;
    int64_t from = 0;
    for (int p = 0; p < 2; ++p) {
        const StorageRange r = slab_storage(lattice, slab, p);
        std::copy_n(part.distance.begin() + from, r.count, field.distance.begin() + r.offset);
        std::copy_n(part.gradient.begin() + from, r.count, field.gradient.begin() + r.offset);
        std::copy_n(part.closest_triangle.begin() + from, r.count, field.closest_triangle.begin() + r.offset);
        from += r.count;
    }
}

/// Root: rank `rank`'s part (as send_part sends it) at its offsets.
void receive_part(SampledField& field, const Lattice& lattice, const LatticeSlab& slab, int rank) {
    for (int p = 0; p < 2; ++p) {
        const StorageRange r = slab_storage(lattice, slab, p);
        const size_t n = size_t(r.count), at = size_t(r.offset);
        receive_into(field.distance.data() + at, n * sizeof(double), rank, kTagData);
        receive_into(field.gradient.data() + at, n * sizeof(Vec3d), rank, kTagData);
        receive_into(field.closest_triangle.data() + at, n * sizeof(int32_t), rank, kTagData);
    }
}

}  // namespace

SampledField sample_part(const BoundSampler& sampler, const Lattice& lattice, const LatticeSlab& slab) {
    if (slab.z_end <= slab.z_begin) {
        SampledField empty;
        empty.lattice = lattice;
        return empty;
    }
    return sampler.sample_slab(lattice, slab);
}

nlohmann::json describe_part(const SampledField& part, int rank, const std::string& host, const LatticeSlab& slab,
                             double wall_seconds) {
    nlohmann::json j = {{"rank", rank},
                        {"host", host},
                        {"z_planes", {slab.z_begin, slab.z_end}},
                        {"points", part.size()},
                        {"seconds", wall_seconds},
                        {"kernel_seconds", part.timings.kernel},
                        {"upload_seconds", part.timings.upload},
                        {"download_seconds", part.timings.download},
                        {"pairs", part.timings.point_triangle_pairs}};
    j["points_computed"] = part.sampler.points_computed;
    for (const char* key : {"device", "threads"})
        if (part.sampler.details.contains(key)) j[key] = part.sampler.details.at(key);
    return j;
}

void send_part(const SampledField& part, const Lattice& lattice, const LatticeSlab& slab) {
    for (int p = 0; p < 2; ++p) {
        const StorageRange r = slab_storage(lattice, slab, p);
        const size_t first = p == 0 ? 0 : size_t(slab_storage(lattice, slab, 0).count);
        const size_t n = part.size() == 0 ? 0 : size_t(r.count);
        send_bytes(part.distance.data() + first, n * sizeof(double), 0, kTagData);
        send_bytes(part.gradient.data() + first, n * sizeof(Vec3d), 0, kTagData);
        send_bytes(part.closest_triangle.data() + first, n * sizeof(int32_t), 0, kTagData);
    }
}

void receive_answers(Gathered& g, SampledField* field, const Lattice& lattice, const std::vector<LatticeSlab>& slabs) {
    for (int r = 1; r < session().size; ++r) {
        const nlohmann::json status = nlohmann::json::parse(receive_string(r, kTagStatus));
        const std::string host = status.value("host", std::string("?"));
        if (!status.value("ok", false)) {
            g.failures.push_back({r, host, status.value("error", std::string("unknown error")), status.value("setup", false)});
            continue;
        }
        if (!status.contains("part") || field == nullptr) continue;  // nothing sampled: the root had failed first
        receive_part(*field, lattice, slabs[size_t(r)], r);
        g.parts.push_back(status["part"]);
        g.sampler.merge(status["sampler"].get<SamplerReport>());  // in rank order
    }
}

Gathered sample_and_gather(const std::function<SampledField(const LatticeSlab&)>& sample_mine, const Lattice& lattice,
                           const SlabPlan& plan, SampledField& field) {
    const std::string host = session().self["host"].get<std::string>();
    Gathered g;
    try {
        const auto t0 = std::chrono::steady_clock::now();
        maybe_inject_failure(0);
        const SampledField part = sample_mine(plan.slabs[0]);
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        place_part(field, lattice, plan.slabs[0], part);
        g.parts.push_back(describe_part(part, 0, host, plan.slabs[0], seconds));
        g.sampler.merge(part.sampler);
    } catch (const std::exception& e) {
        g.failures.push_back({0, host, e.what()});
    }
    receive_answers(g, &field, lattice, plan.slabs);
    return g;
}

std::string failure_message(const std::string& lattice, const std::vector<RankFailure>& failures) {
    std::string text = "distributed sampling" + (lattice.empty() ? std::string() : " of " + lattice) + " failed on " +
                       std::to_string(failures.size()) + " of " + std::to_string(session().size) + " ranks: ";
    for (size_t i = 0; i < failures.size(); ++i)
        text += (i ? "; " : "") + rank_and_host(failures[i].rank, failures[i].host) + ": " + failures[i].error;
    return text;
}

nlohmann::json finish_provenance(SampledField& field, const SamplerOptions& options, const SlabPlan& plan,
                                 const Gathered& gathered, double total_seconds, double sampling_seconds) {
    const Session& s = session();
    nlohmann::json parts = gathered.parts;
    SamplerReport sampler = gathered.sampler;  // every rank's counters, merged
    std::sort(parts.begin(), parts.end(), [](const nlohmann::json& a, const nlohmann::json& b) { return a["rank"] < b["rank"]; });
    double pairs = 0, max_seconds = 0, sum_seconds = 0, upload = 0, download = 0, kernel = 0;
    for (size_t r = 0; r < parts.size(); ++r) {
        nlohmann::json& p = parts[r];
        p["estimated_cost"] = plan.slab_cost(int(r));
        pairs += p["pairs"].get<double>();
        max_seconds = std::max(max_seconds, p["seconds"].get<double>());
        sum_seconds += p["seconds"].get<double>();
        upload = std::max(upload, p["upload_seconds"].get<double>());
        download = std::max(download, p["download_seconds"].get<double>());
        kernel = std::max(kernel, p.value("kernel_seconds", 0.0));
    }
    if (sampler.backend.empty()) {  // no rank sampled a point
        sampler.backend = options.backend;
        sampler.method = options.method;
        sampler.kernel = options.kernel;
        sampler.precision = precision_name(options.precision);
    }
    const double mean = sum_seconds / double(std::max<size_t>(1, parts.size()));
    nlohmann::json d = {{"ranks", s.size},
                        {"lattice", lattice_notation(field.lattice)},
                        {"cost_estimate", plan.estimate},
                        {"estimate_seconds", plan.estimate_seconds},
                        {"slabs", parts},
                        {"load_balance", {{"seconds_max_over_mean", mean > 0 ? max_seconds / mean : 1.0},
                                          {"estimate_max_over_mean", plan.estimated_max_over_mean()}}},
                        {"seconds", total_seconds},
                        {"sampling_seconds", sampling_seconds}};
    if (field.lattice.type == LatticeType::BCC && options.bcc_strategy == BccStrategy::DoubleResolution)
        d["slab_bcc_strategy"] = "two_grids";  // lattice_slab.h: the same positions, the same samples
    sampler.details["distributed"] = d;
    field.sampler = sampler;
    field.timings.total = total_seconds;
    // The device time of the slowest rank's slab (the ranks run at once), as one process
    // reports its kernels: the wall clock of the sampling, with the ranks' waits and the
    // gather, is "sampling_seconds" (issue 36: reported as kernel seconds, 12x one GPU's).
    field.timings.kernel = kernel;
    field.timings.upload = upload;
    field.timings.download = download;
    field.timings.point_triangle_pairs = pairs;
    return d;
}
}  // namespace sdf::mpi
