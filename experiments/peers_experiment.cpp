/// @file peers_experiment.cpp
/// @brief Kind "peers": our samplers (brute force and BVH, CPU and GPU) side by side with the
/// libraries users pick for signed distances (CGAL AABB_tree, Embree rtcPointQuery, Open3D
/// RaycastingScene, OpenVDB meshToSignedDistanceField), on the same meshes, lattices, machine
/// and thread counts, in one run (docs/bvh.md).
///
///   "cases": [{"label": "dragon", "mesh": "dragon.obj", "samples": [262144, 2097152]}],
///   "threads": [1, 2], "ours": ["brute_cpu", "bvh_cpu", "brute_gpu", "bvh_gpu"],
///   "peers": ["cgal", "embree", "open3d", "openvdb"], "brute_cpu_max_points": 4096,
///   "openvdb_band_voxels": 3, "python": "", "repetitions": 1
/// The lattice is CC, the cube whose point count is nearest to each sample count. The exact
/// field every method is compared with is our CPU BVH's (equal to brute force: tests/
/// cpu_reference/bvh); the CPU brute force is timed on "brute_cpu_max_points" evenly strided
/// points and scaled to the lattice (it costs the same per point), and its distances there
/// are checked against that reference. Rows: time (build, query, total), threads, points/s,
/// max |distance error|, sign disagreements, notes. GPU rows without a GPU say
/// "unavailable"; peers whose package is missing say "not built".
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ostream>

#include "core/lattice/lattice_fitting.h"
#include "core/parallel/parallel_for.h"
#include "experiments/common/lattice_points.h"
#include "experiments/common/mesh_cases.h"
#include "core/statistics.h"
#include "experiments/common/study_inputs.h"
#include "harness/experiment/experiment.h"
#include "experiments/peers/peer.h"
#include "harness/config/lattice_spec.h"
#include "harness/sampling/sampler_table.h"

namespace sdf {
namespace {

const std::vector<std::string> kOurs = {"brute_cpu", "bvh_cpu", "brute_gpu", "bvh_gpu"};
const std::vector<std::string> kPeers = {"cgal", "embree", "open3d", "openvdb"};

/// CPU time of this process, all threads (robust to other load on a shared machine).
double process_cpu_seconds() {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

/// Errors of `d` against the reference at the same points (`index[k]` = lattice index of d[k]).
struct Errors {
    double max_abs = 0;          ///< max |d - ref| (unsigned peers: max ||d| - |ref||)
    double max_abs_unsigned = 0; ///< max ||d| - |ref||: the distance alone, whatever the sign
    double sum_abs = 0;          ///< for the mean
    int64_t sign_disagreements = 0;
    int64_t compared = 0;
    double mean_abs() const { return compared > 0 ? sum_abs / double(compared) : 0.0; }
};

Errors compare(const std::vector<double>& d, const std::vector<double>& ref, const std::vector<int64_t>& index,
               bool is_signed, const std::vector<uint8_t>* mask = nullptr, bool mask_value = true) {
    Errors e;
    for (size_t k = 0; k < d.size(); ++k) {
        if (mask && !mask->empty() && bool((*mask)[k]) != mask_value) continue;
        const double r = ref[size_t(index.empty() ? int64_t(k) : index[k])];
        const double unsigned_error = std::abs(std::abs(d[k]) - std::abs(r));
        const double error = is_signed ? std::abs(d[k] - r) : unsigned_error;
        e.max_abs = std::max(e.max_abs, error);
        e.sum_abs += error;
        e.max_abs_unsigned = std::max(e.max_abs_unsigned, unsigned_error);
        if (is_signed && r != 0 && (d[k] < 0) != (r < 0)) ++e.sign_disagreements;
        ++e.compared;
    }
    return e;
}

class PeersExperiment final : public Experiment {
public:
    void configure(JsonReader& config, const RunContext& context) override {
        search_path_ = read_search_path(config, context);
        base_dir_ = context.config_dir;
        margin_ = read_domain_margin(config);
        cases_ = read_mesh_cases(config, search_path_, base_dir_);
        threads_ = config.optional<std::vector<int>>("threads", {1, 0}, "thread counts (0 = all cores)");
        for (int t : threads_)
            if (t < 0) config.fail("threads", "expected thread counts >= 0, got " + std::to_string(t));
        ours_ = read_names(config, "ours", kOurs);
        peer_names_ = read_names(config, "peers", kPeers);
        brute_max_points_ = config.optional<int64_t>("brute_cpu_max_points", 4096, "a point count (0 = all)");
        peer_options_.openvdb_band_voxels = config.optional<double>("openvdb_band_voxels", 3.0, "a band half-width in voxels");
        if (!(peer_options_.openvdb_band_voxels >= 1.0))
            config.fail("openvdb_band_voxels", "expected at least 1 voxel, got " + std::to_string(peer_options_.openvdb_band_voxels));
        peer_options_.python = config.optional<std::string>("python", "", "a python3 that imports open3d");
        repetitions_ = config.optional<int>("repetitions", 1, "a positive count");
        if (repetitions_ < 1) config.fail("repetitions", "expected at least 1, got " + std::to_string(repetitions_));
    }

    std::vector<std::string> plan(const RunContext&) const override {
        std::vector<std::string> lines;
        for (const MeshCase& c : cases_)
            for (int64_t n : c.samples) {
                const int r = cubic_resolution_for_samples(LatticeType::CC, n);
                std::string line = c.label + " (" + c.mesh.label() + ") CC " + std::to_string(r) + "^3:";
                for (const std::string& o : ours_) line += " " + o + gpu_note(o);
                for (const std::string& p : peer_names_) line += " " + p;
                lines.push_back(line + "; threads " + thread_list() + "; errors against our exact field (CPU BVH)");
            }
        return lines;
    }

    void run(RunContext& ctx) override {
        peers_ = peers::make_peers(peer_options_);
        for (const auto& p : peers_)
            ctx.metrics["peers"][p.name] = p.available ? nlohmann::json{{"version", p.adapter->version()}, {"exact", p.adapter->exact()}}
                                                       : nlohmann::json{{"status", p.reason}};
        ctx.metrics["machine"] = {{"hardware_threads", hardware_threads()}};
        for (const MeshCase& c : cases_) {
            const PreparedMesh mesh = load_case_mesh(c, search_path_, base_dir_, ctx);
            ctx.metrics["meshes"][c.label] = describe_mesh(mesh);
            for (int64_t samples : c.samples) run_case(ctx, c, mesh, samples);
        }
    }

private:
    static std::vector<std::string> read_names(JsonReader& config, const std::string& key, const std::vector<std::string>& known) {
        const auto names = config.optional<std::vector<std::string>>(key, known, "names");
        for (const std::string& n : names)
            if (std::find(known.begin(), known.end(), n) == known.end()) {
                std::string list;
                for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
                config.fail(key, "unknown name \"" + n + "\"; expected some of " + list);
            }
        return names;
    }

    static std::string gpu_note(const std::string& name) {
        return name.find("gpu") != std::string::npos && !cuda_backend_available() ? " [unavailable here]" : "";
    }

    std::string thread_list() const {
        std::string s;
        for (int t : threads_) s += (s.empty() ? "" : ", ") + std::to_string(resolve_thread_count(t));
        return s;
    }

    // ---- rows -----------------------------------------------------------------------
    nlohmann::json base_row(const std::string& label, const Lattice& lattice, const PreparedMesh& mesh,
                            const std::string& method, const std::string& who) const {
        return {{"mesh", label}, {"resolution", lattice_notation(lattice)}, {"points", lattice.num_points()},
                {"triangles", mesh.triangles().size()}, {"method", method}, {"by", who}};
    }

    static void set_times(nlohmann::json& row, double build, double query, int64_t points) {
        row["build_seconds"] = build;
        row["query_seconds"] = query;
        row["total_seconds"] = build + query;
        row["points_per_second"] = query > 0 ? double(points) / query : 0.0;
    }

    static void set_errors(nlohmann::json& row, const Errors& e, bool is_signed) {
        row["max_abs_error"] = e.max_abs;
        row["max_abs_error_unsigned"] = e.max_abs_unsigned;
        row["mean_abs_error"] = e.mean_abs();
        row["compared_points"] = e.compared;
        row["sign_disagreements"] = is_signed ? nlohmann::json(e.sign_disagreements) : nlohmann::json("n/a (unsigned)");
    }

    /// Our CPU BVH at every thread count; the first run's field is the reference.
    void run_bvh_cpu(RunContext& ctx, const std::string& label, const PreparedMesh& mesh, const Lattice& lattice,
                     std::vector<double>& reference) {
        for (int t : threads_) {
            SamplerOptions o;
            o.method = "bvh";
            o.threads = t;
            o.progress = false;
            auto sampler = make_sampler(o);
            std::vector<double> query, total;
            SampledField f;
            const double cpu0 = process_cpu_seconds();
            for (int r = 0; r < repetitions_; ++r) {
                f = sampler->sample(mesh, lattice);  // the first call builds the BVH
                query.push_back(f.timings.kernel);
                total.push_back(f.timings.total);
            }
            const double cpu = (process_cpu_seconds() - cpu0) / repetitions_;
            if (reference.empty()) reference = f.distance;
            nlohmann::json row = base_row(label, lattice, mesh, "bvh_cpu", "ours");
            const double build = f.sampler["bvh"]["build_seconds"].get<double>();
            set_times(row, build, median_of(query), lattice.num_points());
            row["cpu_seconds"] = cpu;
            row["threads"] = resolve_thread_count(t);
            set_errors(row, compare(f.distance, reference, {}, true), true);
            row["notes"] = "reference field (exact: equals brute force, tests/cpu_reference/bvh); kernel " +
                           f.sampler["kernel"].get<std::string>() + ", " + f.sampler["bvh"].dump();
            emit(ctx, row);
        }
    }

    /// Our CPU brute force on an evenly strided subset, scaled to the lattice.
    void run_brute_cpu(RunContext& ctx, const std::string& label, const PreparedMesh& mesh, const Lattice& lattice,
                       const std::vector<double>& reference) {
        const int64_t n = lattice.num_points();
        const LatticeSubset subset = strided_lattice_subset(lattice, brute_max_points_);
        const std::vector<Vec3d>& pts = subset.points;
        for (int t : threads_) {
            SamplerOptions o;
            o.threads = t;
            o.progress = false;
            auto sampler = make_sampler(o);
            std::vector<double> secs;
            std::vector<PointSample> res;
            const double cpu0 = process_cpu_seconds();
            for (int r = 0; r < repetitions_; ++r) {
                const auto start = std::chrono::steady_clock::now();
                res = sampler->query(mesh, pts);
                secs.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
            }
            std::vector<double> d;
            for (const auto& s : res) d.push_back(s.distance);
            nlohmann::json row = base_row(label, lattice, mesh, "brute_cpu", "ours");
            set_times(row, 0.0, median_of(secs) * double(n) / double(pts.size()), n);
            row["cpu_seconds"] = (process_cpu_seconds() - cpu0) / repetitions_ * double(n) / double(pts.size());
            row["threads"] = resolve_thread_count(t);
            set_errors(row, compare(d, reference, subset.index, true), true);
            row["notes"] = "timed on " + std::to_string(pts.size()) + " evenly strided points and scaled to the lattice";
            row["extrapolated"] = int64_t(pts.size()) < n;
            emit(ctx, row);
        }
    }

    /// Our GPU samplers (CUDA-event kernel time); "unavailable" without a GPU.
    void run_gpu(RunContext& ctx, const std::string& label, const PreparedMesh& mesh, const Lattice& lattice,
                 const std::vector<double>& reference, const std::string& name) {
        nlohmann::json row = base_row(label, lattice, mesh, name, "ours");
        if (!cuda_backend_available()) {
            row["status"] = "unavailable (no CUDA device or no CUDA backend in this build)";
            emit(ctx, row);
            return;
        }
        SamplerOptions o;
        o.backend = "cuda";
        o.method = name == "bvh_gpu" ? "bvh" : "brute_force";
        o.progress = false;
        auto sampler = make_sampler(o);
        sampler->sample(mesh, lattice);  // warm-up: module load, uploads (and the BVH build)
        std::vector<double> kernel, total;
        SampledField f;
        for (int r = 0; r < repetitions_; ++r) {
            f = sampler->sample(mesh, lattice);
            kernel.push_back(f.timings.kernel);
            total.push_back(f.timings.total);
        }
        set_times(row, 0.0, median_of(kernel), lattice.num_points());
        row["end_to_end_seconds"] = median_of(total);
        row["threads"] = "GPU";
        set_errors(row, compare(f.distance, reference, {}, true), true);
        row["notes"] = "CUDA-event time of the search and the double finalize; " + f.sampler["device"].value("name", std::string());
        emit(ctx, row);
    }

    void run_peer(RunContext& ctx, const std::string& label, const PreparedMesh& mesh, const Lattice& lattice,
                  const std::vector<Vec3d>& points, const std::vector<double>& reference, peers::PeerEntry& peer) {
        if (!peer.available) {
            nlohmann::json row = base_row(label, lattice, mesh, peer.name, "peer");
            row["status"] = peer.reason;
            emit(ctx, row);
            return;
        }
        for (int t : threads_) {
            const double cpu0 = process_cpu_seconds();
            const peers::PeerResult r = peer.adapter->run(mesh, lattice, points, resolve_thread_count(t));
            const double cpu = r.cpu_seconds >= 0 ? r.cpu_seconds : process_cpu_seconds() - cpu0;
            nlohmann::json row = base_row(label, lattice, mesh, peer.name, "peer");
            row["version"] = peer.adapter->version();
            row["exact"] = peer.adapter->exact();
            set_times(row, r.build_seconds, r.query_seconds, lattice.num_points());
            row["cpu_seconds"] = cpu;
            row["threads"] = r.threads;
            set_errors(row, compare(r.distance, reference, {}, r.is_signed), r.is_signed);
            if (!r.in_band.empty()) {
                const Errors in = compare(r.distance, reference, {}, true, &r.in_band, true);
                const Errors out = compare(r.distance, reference, {}, true, &r.in_band, false);
                row["band"] = {{"points_in_band", in.compared}, {"max_abs_error_in_band", in.max_abs},
                               {"mean_abs_error_in_band", in.mean_abs()},
                               {"sign_disagreements_in_band", in.sign_disagreements},
                               {"max_abs_error_outside_band", out.max_abs},
                               {"sign_disagreements_outside_band", out.sign_disagreements}};
            }
            row["details"] = r.details;
            emit(ctx, row);
        }
    }

    void run_case(RunContext& ctx, const MeshCase& c, const PreparedMesh& mesh, int64_t samples) {
        const int r = cubic_resolution_for_samples(LatticeType::CC, samples);
        const Lattice lattice = fit_lattice(LatticeType::CC, {r, r, r}, mesh.bounds(), margin_);
        *ctx.log << c.label << " CC " << lattice_notation(lattice) << " (" << with_commas(lattice.num_points()) << " points x "
                 << with_commas(int64_t(mesh.triangles().size())) << " triangles)\n";
        std::vector<double> reference;
        run_bvh_cpu(ctx, c.label, mesh, lattice, reference);  // always: it is the reference
        if (std::count(ours_.begin(), ours_.end(), "brute_cpu")) run_brute_cpu(ctx, c.label, mesh, lattice, reference);
        for (const char* gpu : {"brute_gpu", "bvh_gpu"})
            if (std::count(ours_.begin(), ours_.end(), gpu)) run_gpu(ctx, c.label, mesh, lattice, reference, gpu);
        const std::vector<Vec3d> points = lattice_points(lattice);
        for (auto& p : peers_)
            if (std::count(peer_names_.begin(), peer_names_.end(), p.name)) run_peer(ctx, c.label, mesh, lattice, points, reference, p);
        summarise(ctx, c.label, lattice);
    }

    /// Speedup of our CPU BVH over the fastest exact peer at each thread count (query time
    /// and build + query), the goal being 1.5x.
    void summarise(RunContext& ctx, const std::string& label, const Lattice& lattice) {
        const std::string res = lattice_notation(lattice);
        for (int t : threads_) {
            const int threads = resolve_thread_count(t);
            const nlohmann::json* ours = nullptr;
            const nlohmann::json* best = nullptr;
            for (const auto& row : ctx.metrics["rows"]) {
                if (row["mesh"] != label || row["resolution"] != res || !row.contains("threads") || row["threads"] != threads) continue;
                if (row["method"] == "bvh_cpu") ours = &row;
                if (row["by"] == "peer" && row.value("exact", false) &&
                    (!best || row["query_seconds"].get<double>() < (*best)["query_seconds"].get<double>()))
                    best = &row;
            }
            if (!ours || !best) continue;
            const double q = (*best)["query_seconds"].get<double>() / (*ours)["query_seconds"].get<double>();
            const double tot = (*best)["total_seconds"].get<double>() / (*ours)["total_seconds"].get<double>();
            const double cpu = (*best)["cpu_seconds"].get<double>() / (*ours)["cpu_seconds"].get<double>();
            const nlohmann::json s = {{"mesh", label}, {"resolution", res}, {"threads", threads},
                                      {"fastest_exact_peer", (*best)["method"]}, {"query_speedup", q},
                                      {"total_speedup", tot}, {"cpu_time_ratio", cpu}, {"goal", 1.5}};
            ctx.metrics["summary"].push_back(s);
            ctx.metrics["regression"][label + "/" + res + "/" + std::to_string(threads) + "/bvh_cpu_vs_fastest_peer"] =
                {{"value", q}, {"kind", "speedup"}};
            char line[256];
            std::snprintf(line, sizeof line, "    => bvh_cpu vs fastest exact peer (%s), %d threads: %.2fx query, %.2fx build+query, %.2fx CPU time\n",
                          (*best)["method"].get<std::string>().c_str(), threads, q, tot, cpu);
            *ctx.log << line;
        }
    }

    void emit(RunContext& ctx, const nlohmann::json& row) {
        char line[512];
        if (row.contains("status")) {
            std::snprintf(line, sizeof line, "    %-10s %s\n", row["method"].get<std::string>().c_str(),
                          row["status"].get<std::string>().c_str());
        } else {
            const std::string threads = row["threads"].is_string() ? row["threads"].get<std::string>() : std::to_string(row["threads"].get<int>());
            const std::string signs = row["sign_disagreements"].is_string() ? "n/a" : std::to_string(row["sign_disagreements"].get<int64_t>());
            std::snprintf(line, sizeof line,
                          "    %-10s %4s threads  build %8.4f s  query %9.4f s  cpu %9.4f s  %10.4g points/s  max|dd| %.3g (unsigned %.3g)  "
                          "sign disagreements %s\n",
                          row["method"].get<std::string>().c_str(), threads.c_str(), row["build_seconds"].get<double>(),
                          row["query_seconds"].get<double>(), row.value("cpu_seconds", -1.0), row["points_per_second"].get<double>(),
                          row["max_abs_error"].get<double>(), row["max_abs_error_unsigned"].get<double>(), signs.c_str());
        }
        *ctx.log << line << std::flush;
        ctx.metrics["rows"].push_back(row);
    }

    std::vector<std::string> search_path_;
    std::string base_dir_;
    double margin_ = 0.1;
    std::vector<MeshCase> cases_;
    std::vector<int> threads_;
    std::vector<std::string> ours_, peer_names_;
    int64_t brute_max_points_ = 4096;
    peers::PeerOptions peer_options_;
    int repetitions_ = 1;
    std::vector<peers::PeerEntry> peers_;
};

}  // namespace

std::unique_ptr<Experiment> make_peers_experiment() { return std::make_unique<PeersExperiment>(); }

}  // namespace sdf
