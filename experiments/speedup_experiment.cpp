/// @file speedup_experiment.cpp
/// @brief Kind "speedup": thesis Tables 3-1 and 3-2. For each mesh and sample count, the
/// time of every configured sampler (CPU 1 thread, CPU all threads, GPU thesis kernel, GPU
/// tuned kernel), repeated, with median and spread; speedups are ratios of medians measured
/// in the same run (end-to-end times, transfers included), printed beside the thesis's
/// figures; pairs per second use the computation time alone.
///
///   "cases": [{"label": "dragon", "mesh": "dragon-legacy.obj", "samples": [32768, 262144]}],
///   "lattice_types": ["cc"],
///   "backends": [{"name": "cpu_1", "backend": "cpu", "threads": 1, "max_points": 2048}, ...],
///   "reference": "cpu_1", "repetitions": 5
/// Each backend object is a sampler object (sampler_spec.h) plus "name" and "max_points".
/// CUDA backends on a machine without a GPU are listed as unavailable, never faked. Times
/// are never taken from the field cache. Meshes whose label is a thesis mesh ("soccer ball",
/// "bunny", "dragon") get the thesis's Table 3-1 counts beside ours, rows its Table 3-2 times.
/// A CPU backend with "max_points" below the lattice size is timed on that many lattice
/// points (evenly strided) and its time scaled by N / n: brute force costs exactly the same
/// per point, and this keeps a 1-thread 2-million-point run from taking an hour.
#include <algorithm>
#include <chrono>
#include <map>
#include <cstdio>
#include <ostream>

#include "core/lattice/lattice_fitting.h"
#include "experiments/common/lattice_points.h"
#include "experiments/common/mesh_cases.h"
#include "core/quoted_alternatives.h"
#include "core/statistics.h"
#include "harness/study/study_inputs.h"
#include "experiments/common/thesis_tables.h"
#include "harness/experiment/experiment.h"
#include "harness/config/mesh_spec.h"
#include "harness/config/sampler_spec.h"
#include "harness/sampling/sampler_table.h"

namespace sdf {
namespace {

struct BackendSpec {
    std::string name;
    SamplerOptions options;
    int64_t max_points = 0;  ///< 0 = the whole lattice
};

struct Timing {
    std::vector<double> seconds;  ///< computation per repetition (scaled to the lattice if subset)
    std::vector<double> total;    ///< end to end per repetition: transfers and host work included
    int64_t points_timed = 0;
    double median() const { return median_of(seconds); }
    double median_total() const { return median_of(total); }
};

class SpeedupExperiment final : public Experiment {
public:
    void configure(JsonReader& config, const RunContext& context) override {
        search_path_ = read_search_path(config, context);
        base_dir_ = context.config_dir;
        margin_ = read_domain_margin(config);
        cases_ = read_mesh_cases(config, search_path_, base_dir_);
        const std::string kinds = quoted_alternatives(lattice_type_names());
        const auto types = config.optional<std::vector<std::string>>(
            "lattice_types", {lattice_type_name(LatticeType::CC)}, "an array of lattice types (" + kinds + ")");
        if (types.empty()) config.fail("lattice_types", "expected a non-empty array of " + kinds + ", got []");
        for (const std::string& t : types) {
            const LatticeKind* kind = find_lattice_kind(t);
            if (!kind) config.fail("lattice_types", "expected " + kinds + ", got \"" + t + "\"");
            lattice_types_.push_back(kind->type);
        }
        std::vector<JsonReader> backends = config.objects("backends");
        if (backends.empty()) config.fail("backends", "expected at least one backend, got []");
        for (JsonReader& b : backends) {
            BackendSpec spec;
            spec.name = b.required<std::string>("name", "a short name such as \"gpu_tuned\"");
            for (const BackendSpec& other : backends_)
                if (other.name == spec.name) b.fail("name", "\"" + spec.name + "\" names two backends");
            spec.max_points = b.optional<int64_t>("max_points", 0, "a number of points to time (0 = all)");
            if (spec.max_points < 0) b.fail("max_points", "expected 0 (all) or a positive count, got " + std::to_string(spec.max_points));
            spec.options = parse_sampler_options(b);  // reads the sampler keys and finishes
            spec.options.progress = false;
            // Scaling a subset's time to the lattice is right only where every point costs the same.
            if (spec.max_points > 0 && sampler_kind(spec.options).cost != CostModel::PerPoint)
                b.fail("max_points", "times a subset and scales it, which needs a sampler whose points all cost the "
                                     "same; \"" + spec.options.method + "\" does not: name \"method\": \"brute_force\" "
                                     "or drop max_points");
            backends_.push_back(spec);
        }
        reference_ = config.optional<std::string>("reference", backends_[0].name,
                                                  "the name of the backend speedups are relative to");
        if (std::none_of(backends_.begin(), backends_.end(), [&](const BackendSpec& b) { return b.name == reference_; }))
            config.fail("reference", "names no backend: \"" + reference_ + "\"");
        repetitions_ = config.optional<int>("repetitions", 3, "a positive count");
        if (repetitions_ < 1) config.fail("repetitions", "expected at least 1, got " + std::to_string(repetitions_));
    }

    std::vector<std::string> plan(const RunContext&) const override {
        std::vector<std::string> lines;
        for (const MeshCase& c : cases_)
            for (int64_t n : c.samples)
                for (LatticeType t : lattice_types_) {
                    const int r = cubic_resolution_for_samples(t, n);
                    std::string line = c.label + " (" + c.mesh.label() + ") " + with_commas(n) + " samples, " +
                                       lattice_type_name(t) + " " + std::to_string(r) + "^3" +
                                       (t == LatticeType::BCC ? " + " + std::to_string(r - 1) + "^3" : "") + ":";
                    for (const BackendSpec& b : backends_) {
                        line += " " + b.name + " x" + std::to_string(repetitions_);
                        if (b.max_points > 0) line += " (on " + with_commas(b.max_points) + " points, scaled)";
                        if (sampler_kind(b.options).on_gpu && !cuda_backend_available()) line += " [unavailable here: reported, not run]";
                        line += ";";
                    }
                    lines.push_back(line + " speedups vs " + reference_ + "; never from the cache");
                }
        return lines;
    }

    void run(RunContext& ctx) override {
        for (const MeshCase& c : cases_) {
            const auto shared_mesh = std::make_shared<const PreparedMesh>(load_case_mesh(c, search_path_, base_dir_, ctx));
            const PreparedMesh& mesh = *shared_mesh;
            nlohmann::json described = describe_prepared_mesh(mesh);
            for (const ThesisMeshCounts& t : kThesisTable31)
                if (c.label == t.mesh) described["thesis_table_3_1"] = {{"triangles", t.triangles}, {"vertices", t.vertices}};
            ctx.metrics["meshes"][c.label] = described;
            for (int64_t samples : c.samples)
                for (LatticeType type : lattice_types_) run_row(ctx, c, shared_mesh, samples, type);
        }
    }

private:
    Timing time_backend(const BackendSpec& b, const std::shared_ptr<const PreparedMesh>& mesh, const Lattice& lattice,
                        std::vector<double>& subset_distance, const LatticeSubset& subset) {
        Timing t;
        const auto sampler = make_sampler(b.options)->bind(mesh);  // the BVH, sign data, uploads: not timed
        const int64_t n = lattice.num_points();
        const bool whole = b.max_points <= 0 || b.max_points >= n;
        if (!whole) {
            // Strided subset: same cost per point as the whole lattice.
            t.points_timed = int64_t(subset.points.size());
            for (int r = 0; r < repetitions_; ++r) {
                const auto start = std::chrono::steady_clock::now();
                const auto res = sampler->query(subset.points);
                const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
                t.seconds.push_back(s * double(n) / double(subset.points.size()));
                t.total.push_back(t.seconds.back());
                if (r == 0) for (const auto& q : res) subset_distance.push_back(q.distance);
            }
            return t;
        }
        t.points_timed = n;
        if (sampler_kind(b.options).on_gpu) sampler->sample(lattice);  // warm-up: module load, first allocations
        for (int r = 0; r < repetitions_; ++r) {
            const SampledField f = sampler->sample(lattice);
            t.seconds.push_back(f.timings.kernel);
            t.total.push_back(f.timings.total);
            if (r == 0)
                for (int64_t i : subset.index) subset_distance.push_back(f.distance[size_t(i)]);
        }
        return t;
    }

    void run_row(RunContext& ctx, const MeshCase& c, const std::shared_ptr<const PreparedMesh>& shared_mesh, int64_t samples,
                 LatticeType type) {
        const PreparedMesh& mesh = *shared_mesh;
        const int r = cubic_resolution_for_samples(type, samples);
        const Lattice lattice = fit_lattice(type, {r, r, r}, mesh.bounds(), margin_);
        const int64_t n = lattice.num_points();
        // The subset every backend reports distances on, for a cross-check of the results.
        int64_t subset_size = n;
        for (const BackendSpec& b : backends_)
            if (b.max_points > 0) subset_size = std::min(subset_size, b.max_points);
        const LatticeSubset subset = strided_lattice_subset(lattice, subset_size);

        nlohmann::json row = {{"mesh", c.label},
                              {"samples_requested", samples},
                              {"lattice", lattice_type_name(type)},
                              {"resolution", lattice_notation(lattice)},
                              {"points", n},
                              {"triangles", mesh.triangles().size()}};
        std::map<std::string, double> medians;
        std::vector<double> reference_distance;
        for (const BackendSpec& b : backends_) {
            nlohmann::json entry = {{"name", b.name}, {"sampler", sampler_options_to_json(b.options)}};
            if (sampler_kind(b.options).on_gpu && !cuda_backend_available()) {
                entry["status"] = "unavailable (no CUDA device or no CUDA backend in this build)";
                row["backends"].push_back(entry);
                continue;
            }
            std::vector<double> dist;
            const Timing t = time_backend(b, shared_mesh, lattice, dist, subset);
            const double med = t.median();
            medians[b.name] = t.median_total();
            entry["status"] = "ok";
            entry["total_seconds_median"] = t.median_total();
            entry["seconds_median"] = med;
            entry["seconds_min"] = *std::min_element(t.seconds.begin(), t.seconds.end());
            entry["seconds_max"] = *std::max_element(t.seconds.begin(), t.seconds.end());
            entry["seconds_all"] = t.seconds;
            entry["points_timed"] = t.points_timed;
            entry["extrapolated"] = t.points_timed < n;
            entry["pairs_per_second"] = double(n) * double(mesh.triangles().size()) / med;
            if (b.name == reference_) reference_distance = dist;
            if (!reference_distance.empty() && dist.size() == reference_distance.size()) {
                double worst = 0;
                for (size_t k = 0; k < dist.size(); ++k) worst = std::max(worst, std::abs(dist[k] - reference_distance[k]));
                entry["max_abs_distance_vs_reference"] = worst;
            }
            row["backends"].push_back(entry);
        }
        if (medians.count(reference_))
            for (auto& e : row["backends"])
                if (e.contains("total_seconds_median")) {
                    const double speedup = medians[reference_] / e["total_seconds_median"].get<double>();
                    e["speedup_vs_reference"] = speedup;
                    if (e["name"] != reference_)
                        ctx.metrics["regression"][c.label + "/" + std::to_string(samples) + "/" + lattice_type_name(type) +
                                                  "/" + e["name"].get<std::string>() + "/speedup"] = {{"value", speedup},
                                                                                                      {"kind", "speedup"}};
                }
        if (const ThesisTiming* th = thesis_timing(c.label, samples))
            row["thesis"] = {{"gpu_seconds", th->gpu_seconds}, {"cpu_seconds", th->cpu_seconds}, {"speedup", th->speedup},
                             {"gpu", "GeForce GTX 465"}};
        print_row(*ctx.log, row);
        ctx.metrics["rows"].push_back(row);
        ctx.metrics["reference"] = reference_;
    }

    static void print_row(std::ostream& log, const nlohmann::json& row) {
        char line[512];
        std::snprintf(line, sizeof line, "%s %s %s (%lld points x %lld triangles):\n", row["mesh"].get<std::string>().c_str(),
                      row["lattice"].get<std::string>().c_str(), row["resolution"].get<std::string>().c_str(),
                      (long long)row["points"].get<int64_t>(), (long long)row["triangles"].get<int64_t>());
        log << line;
        for (const auto& e : row["backends"]) {
            if (e["status"] != "ok") {
                log << "    " << e["name"].get<std::string>() << ": " << e["status"].get<std::string>() << "\n";
                continue;
            }
            std::snprintf(line, sizeof line, "    %-12s %10.4f s end to end, %.4f s computing [%.4f, %.4f]%s  %.3g pairs/s  speedup %.1f\n",
                          e["name"].get<std::string>().c_str(), e["total_seconds_median"].get<double>(), e["seconds_median"].get<double>(),
                          e["seconds_min"].get<double>(), e["seconds_max"].get<double>(),
                          e["extrapolated"].get<bool>() ? " (extrapolated)" : "", e["pairs_per_second"].get<double>(),
                          e.value("speedup_vs_reference", 0.0));
            log << line;
        }
        if (row.contains("thesis")) {
            std::snprintf(line, sizeof line, "    thesis (GTX 465 vs 1 CPU core): GPU %.4f s, CPU %.1f s, speedup %.0f\n",
                          row["thesis"]["gpu_seconds"].get<double>(), row["thesis"]["cpu_seconds"].get<double>(),
                          row["thesis"]["speedup"].get<double>());
            log << line;
        }
    }

    std::vector<std::string> search_path_;
    std::string base_dir_;
    double margin_ = 0.1;
    std::vector<MeshCase> cases_;
    std::vector<LatticeType> lattice_types_;
    std::vector<BackendSpec> backends_;
    std::string reference_;
    int repetitions_ = 3;
};

}  // namespace

std::unique_ptr<Experiment> make_speedup_experiment() { return std::make_unique<SpeedupExperiment>(); }

}  // namespace sdf
