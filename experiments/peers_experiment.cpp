/// @file peers_experiment.cpp
/// @brief Kind "peers": our samplers (brute force and BVH, CPU and GPU) side by side with the
/// libraries users pick for signed distances (CGAL, Embree, Open3D, OpenVDB, FCPW, cuBQL), on
/// the same meshes, lattices, point sets, machine and thread counts, in one run (docs/bvh-peers.md).
///
///   "cases": [{"label": "dragon", "mesh": "dragon.obj", "samples": [262144, 2097152]}],
///   "threads": [1, 2], "ours": ["brute_cpu", "bvh_cpu", "bvh_cpu_per_point", "brute_gpu", "bvh_gpu"],
///   "peers": ["cgal", "embree", "open3d", "openvdb", "fcpw", "cubql"], "brute_cpu_max_points": 4096,
///   "openvdb_band_voxels": 3, "python": "", "repetitions": 1, "sign": "auto",
///   "point_sets": [{"kind": "uniform_box", "count": 1048576},
///                  {"kind": "gaussian_surface", "count": 1048576, "sigma": 0.01}], "seed": 1,
///   "point_set_meshes": ["dragon"], "point_set_sign": "pseudonormal", "gpu_bvh_build": "auto",
///   "band_resolutions": [512], "band_voxels": 3
///
/// Every method, ours and the peers', is a row of one table (experiments/peers/peer.h,
/// peer_registry.cpp) and runs through one timing loop (time_method): at each of its thread
/// counts, "repetitions" runs of the adapter, the medians of its build, query, end-to-end and
/// CPU times, its errors against the case's reference and its check (peer_rows.h). Our rows
/// are our samplers behind the same interface (ours_peer.cpp), their build the construction
/// of the build-once MeshSdf.
/// The reference of a lattice is our CPU BVH's field (equal to brute force: tests/
/// cpu_reference/bvh), at the first thread count; of a point set, our CPU BVH query with
/// "sign" (the exact sign; default auto: the winding number on open or self-intersecting
/// meshes): the row bvh_cpu, or where "point_set_sign" differs (a cheaper sign on point
/// sets) the row bvh_cpu_exact_sign (all cores), against which our faster-signed rows are
/// checked like the peers'. The CPU brute force runs on "brute_cpu_max_points" evenly strided
/// points, scaled to the set, and checks the reference there. A row passes its check when its
/// max |distance error| is within kCheckTolerance x the mesh's bounding-box diagonal and, if
/// it signs, no point farther than that from the surface has the wrong sign; the summary
/// compares only rows that pass (peer_rows.h), and every row says its sign. Lattices are CC,
/// the cube whose point count is nearest to each sample count. Point sets (issue 14) are
/// arbitrary points around the mesh (core/sampling/point_sets.h). GPU rows without a GPU say
/// "unavailable", peers whose package is missing "not built".
/// Narrow bands (issue 35; "band_resolutions", each case's CC lattice of N^3 points fitted as
/// above): the methods of Inputs::Bands (our sparse band, CPU and GPU; OpenVDB's
/// meshToLevelSet; NanoVDB's GPU MeshToGrid) each make the level set of half-width
/// "band_voxels" spacings on that lattice's transform and return their own active voxels; a
/// row's time is its build and band (total_seconds), its accuracy the max |error| over its
/// active voxels against the exact field there (our CPU BVH query with "sign", untimed) and
/// its wrong signs (none for unsigned rows: NanoVDB's distances are unsigned).
#include <algorithm>
#include <cstdio>
#include <ostream>
#include <sstream>
#include <stdexcept>

#include "core/bvh/triangle_bvh.h"
#include "core/lattice/lattice_fitting.h"
#include "core/parallel/parallel_for.h"
#include "core/sampling/point_sets.h"
#include "core/statistics.h"
#include "core/winding/sign_mode.h"
#include "experiments/common/lattice_points.h"
#include "experiments/common/mesh_cases.h"
#include "harness/study/study_inputs.h"
#include "experiments/peers/peer.h"
#include "experiments/peers/peer_rows.h"
#include "harness/config/lattice_spec.h"
#include "harness/experiment/experiment.h"
#include "harness/sampling/mesh_sdf.h"
#include "harness/sampling/sampler_table.h"

namespace sdf {
namespace {

using peers::By;
using peers::MethodKind;

/// The point sets' reference where point_set_sign differs from sign; not chosen in "ours".
constexpr const char* kExactSignReference = "bvh_cpu_exact_sign";
constexpr const char* kReference = "bvh_cpu";

/// A number as the shortest text that reads back as it (3, 2.5).
std::string shortest(double v) {
    std::ostringstream s;
    s << v;
    return s.str();
}

std::vector<std::string> configurable_ours() {
    std::vector<std::string> names = peers::method_names(By::Ours);
    names.erase(std::remove(names.begin(), names.end(), std::string(kExactSignReference)), names.end());
    return names;
}

/// What one set of query points is: a lattice (its points in storage order) or a point set.
struct QuerySet {
    std::string name;                    ///< lattice notation, or point_set_label()
    const Lattice* lattice = nullptr;    ///< null for point sets
    const PointSetSpec* point_set = nullptr;
    int64_t count = 0;
    double band_width = 0;               ///< > 0: a narrow-band case on `lattice` (mesh units)
    double band_voxels = 0;              ///< the same in spacings
};

/// One method of the run: its table row and its adapter (null: why_not).
struct Method {
    const MethodKind* kind = nullptr;
    std::unique_ptr<peers::PeerAdapter> adapter;
    std::string why_not;
};

class PeersExperiment final : public Experiment {
public:
    void configure(JsonReader& config, const RunContext& context) override {
        search_path_ = read_search_path(config, context);
        base_dir_ = context.config_dir;
        margin_ = read_domain_margin(config);
        cases_ = read_mesh_cases(config, search_path_, base_dir_);
        threads_ = config.optional<std::vector<int>>("threads", {1, 0}, "thread counts (0 = all cores)");
        if (threads_.empty()) config.fail("threads", "expected at least one thread count, got []");
        for (int t : threads_)
            if (t < 0) config.fail("threads", "expected thread counts >= 0, got " + std::to_string(t));
        ours_ = read_names(config, "ours", configurable_ours());
        peer_names_ = read_names(config, "peers", peers::method_names(peers::By::Peer));
        brute_max_points_ = config.optional<int64_t>("brute_cpu_max_points", 4096, "a point count (0 = all)");
        peer_options_.openvdb_band_voxels = config.optional<double>("openvdb_band_voxels", 3.0, "a band half-width in voxels");
        if (!(peer_options_.openvdb_band_voxels >= 1.0))
            config.fail("openvdb_band_voxels", "expected at least 1 voxel, got " + std::to_string(peer_options_.openvdb_band_voxels));
        peer_options_.python = config.optional<std::string>("python", "", "a python3 that imports open3d");
        lattice_sign_ = sign_mode_from_name(config.choice("sign", sign_mode_names(), sign_mode_name(kSignModes[0].mode)), "sign");
        point_set_sign_ = sign_mode_from_name(config.choice("point_set_sign", sign_mode_names(), sign_mode_name(lattice_sign_)),
                                              "point_set_sign");
        peer_options_.exact_sign = lattice_sign_;
        {
            std::vector<std::string> sites;
            for (const NamedBvhBuildSite& b : kBvhBuildSites) sites.emplace_back(b.name);
            const std::string site = config.choice("gpu_bvh_build", sites, bvh_build_site_name(peer_options_.gpu_bvh_build));
            for (const NamedBvhBuildSite& b : kBvhBuildSites)
                if (site == b.name) peer_options_.gpu_bvh_build = b.value;
        }
        band_resolutions_ = config.optional<std::vector<int>>("band_resolutions", {}, "CC lattice resolutions N (N^3 points)");
        for (int r : band_resolutions_)
            if (r < 2 || r > 65536) config.fail("band_resolutions", "expected resolutions from 2 to 65536, got " + std::to_string(r));
        peer_options_.band_voxels = config.optional<double>("band_voxels", 3.0, "a band half-width in spacings");
        if (!(peer_options_.band_voxels >= 1.0) || !(peer_options_.band_voxels <= 64.0))
            config.fail("band_voxels", "expected 1 to 64 spacings, got " + std::to_string(peer_options_.band_voxels));
        repetitions_ = config.optional<int>("repetitions", 1, "a positive count");
        if (repetitions_ < 1) config.fail("repetitions", "expected at least 1, got " + std::to_string(repetitions_));
        const int64_t seed = config.optional<int64_t>("seed", 1, "a non-negative seed for the point sets");
        if (seed < 0) config.fail("seed", "expected a non-negative seed, got " + std::to_string(seed));
        point_set_meshes_ = config.optional<std::vector<std::string>>("point_set_meshes", {}, "case labels (empty = every case)");
        for (const std::string& l : point_set_meshes_)
            if (std::none_of(cases_.begin(), cases_.end(), [&](const MeshCase& c) { return c.label == l; }))
                config.fail("point_set_meshes", "no case is labelled \"" + l + "\"");
        if (config.has("point_sets"))
            for (JsonReader& ps : config.objects("point_sets")) {
                PointSetSpec spec;
                const std::string kind = ps.required<std::string>("kind", "\"uniform_box\" or \"gaussian_surface\"");
                try {
                    spec.kind = point_set_kind_from_name(kind);
                } catch (const std::invalid_argument& e) {
                    ps.fail("kind", e.what());
                }
                spec.count = ps.required<int64_t>("count", "a point count");
                if (spec.count < 1 || spec.count > (int64_t(1) << 31))
                    ps.fail("count", "expected 1 to 2^31 points, got " + std::to_string(spec.count));
                if (spec.kind == PointSetKind::GaussianSurface) {
                    spec.sigma = ps.optional<double>("sigma", 0.01, "a standard deviation as a fraction of the bounding-box diagonal");
                    if (!(spec.sigma > 0)) ps.fail("sigma", "expected a positive fraction of the diagonal");
                }
                spec.margin = margin_;
                spec.seed = uint64_t(seed) + point_sets_.size();  // each set its own stream
                ps.finish();
                point_sets_.push_back(spec);
            }
    }

    std::vector<std::string> plan(const RunContext&) const override {
        std::vector<std::string> lines;
        auto methods = [&](const PointSetSpec* point_set, bool band = false) {
            std::string line;
            for (const MethodKind& m : peers::method_table())
                if (selected(m, point_set, band)) line += " " + std::string(m.name) + gpu_note(m);
            return line + "; threads " + thread_list() + "; errors against our exact field (CPU BVH)";
        };
        for (const MeshCase& c : cases_) {
            for (int64_t n : c.samples) {
                const int r = cubic_resolution_for_samples(LatticeType::CC, n);
                lines.push_back(c.label + " (" + c.mesh.label() + ") CC " + std::to_string(r) + "^3:" + methods(nullptr));
            }
            for (int r : band_resolutions_)
                lines.push_back(c.label + " (" + c.mesh.label() + ") CC " + std::to_string(r) + "^3, band " +
                                shortest(peer_options_.band_voxels) + " spacings:" + methods(nullptr, true));
            for (const PointSetSpec& ps : point_sets_)
                if (point_sets_for(c)) lines.push_back(c.label + " (" + c.mesh.label() + ") " + point_set_label(ps) + ":" + methods(&ps));
        }
        return lines;
    }

    void run(RunContext& ctx) override {
        for (const MethodKind& kind : peers::method_table()) {
            Method m;
            m.kind = &kind;
            m.adapter = kind.make(peer_options_, m.why_not);  // every peer, for its availability in the metrics
            if (kind.by == By::Peer)
                ctx.metrics["peers"][kind.name] =
                    m.adapter ? nlohmann::json{{"version", m.adapter->version()}, {"exact", kind.exact},
                                               {"gpu", kind.threads == peers::Threads::Gpu},
                                               {"sign", peers::sign_kind_name(kind.sign)}, {"sign_method", kind.sign_method}}
                              : nlohmann::json{{"status", m.why_not}};
            methods_.push_back(std::move(m));
        }
        ctx.metrics["machine"] = {{"hardware_threads", hardware_threads()}};
        ctx.metrics["check"] = {{"tolerance_relative_to_diagonal", peers::kCheckTolerance},
                                {"rule", "max |distance error| <= tolerance x bounding-box diagonal, and (signed rows) no wrong sign "
                                         "farther than that from the surface; unsigned peers pass as exact-unsigned; the summary "
                                         "compares only rows that pass"},
                                {"our_sign", sign_mode_name(lattice_sign_)},
                                {"our_sign_point_sets", sign_mode_name(point_set_sign_)},
                                {"our_gpu_bvh_build", bvh_build_site_name(peer_options_.gpu_bvh_build)}};
        for (const MeshCase& c : cases_) {
            const auto mesh = std::make_shared<const PreparedMesh>(load_case_mesh(c, search_path_, base_dir_, ctx));
            ctx.metrics["meshes"][c.label] = describe_prepared_mesh(*mesh);
            mesh->bvh();  // the mesh's own tree, once, untimed: our rows that search it add its build time
            for (int64_t samples : c.samples) {
                const int r = cubic_resolution_for_samples(LatticeType::CC, samples);
                const Lattice lattice = fit_lattice(LatticeType::CC, {r, r, r}, mesh->bounds(), margin_);
                *ctx.log << c.label << " CC " << lattice_notation(lattice) << " (" << with_commas(lattice.num_points()) << " points x "
                         << with_commas(int64_t(mesh->triangles().size())) << " triangles)\n";
                run_case(ctx, c.label, mesh, {lattice_notation(lattice), &lattice, nullptr, lattice.num_points()},
                         lattice_points(lattice), 1.5);
            }
            for (int r : band_resolutions_) {
                const Lattice lattice = fit_lattice(LatticeType::CC, {r, r, r}, mesh->bounds(), margin_);
                QuerySet set{lattice_notation(lattice) + " band " + shortest(peer_options_.band_voxels) + "h", &lattice, nullptr,
                             0, peer_options_.band_voxels * lattice.spacing, peer_options_.band_voxels};
                *ctx.log << c.label << " CC " << lattice_notation(lattice) << ", narrow band of half-width " << set.band_voxels
                         << " spacings (" << set.band_width << ") x " << with_commas(int64_t(mesh->triangles().size()))
                         << " triangles\n";
                run_case(ctx, c.label, mesh, set, {}, 1.0);
            }
            for (const PointSetSpec& ps : point_sets_) {
                if (!point_sets_for(c)) continue;
                const QuerySet set{point_set_label(ps), nullptr, &ps, ps.count};
                *ctx.log << c.label << " " << set.name << " (" << with_commas(ps.count) << " points x "
                         << with_commas(int64_t(mesh->triangles().size())) << " triangles)\n";
                run_case(ctx, c.label, mesh, set, make_point_set(*mesh, ps), 3.0);
            }
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

    bool point_sets_for(const MeshCase& c) const {
        return point_set_meshes_.empty() || std::count(point_set_meshes_.begin(), point_set_meshes_.end(), c.label) > 0;
    }

    /// The reference of a case: our CPU BVH, or on point sets with a cheaper point_set_sign its exact-sign query.
    const char* reference_of(const PointSetSpec* point_set) const {
        return point_set && point_set_sign_ != lattice_sign_ ? kExactSignReference : kReference;
    }

    /// Whether `m` runs on this case's points (a point set, or a lattice where null; `band`: a
    /// narrow-band case, where only the band methods run).
    bool selected(const MethodKind& m, const PointSetSpec* point_set, bool band = false) const {
        const std::string name = m.name;
        if (band || m.inputs == peers::Inputs::Bands) {
            if (!band || m.inputs != peers::Inputs::Bands) return false;
            const std::vector<std::string>& chosen = m.by == By::Ours ? ours_ : peer_names_;
            return std::count(chosen.begin(), chosen.end(), name) > 0;
        }
        if (name == reference_of(point_set)) return true;
        if (name == kExactSignReference) return false;
        if (m.by == By::Ours) {  // ours only where they apply; the peers' n/a is a row
            if (m.inputs == peers::Inputs::Lattices && point_set) return false;
            if (m.inputs == peers::Inputs::PointSets && !point_set) return false;
            return std::count(ours_.begin(), ours_.end(), name) > 0;
        }
        return std::count(peer_names_.begin(), peer_names_.end(), name) > 0;
    }

    static std::string gpu_note(const MethodKind& m) {
        return m.by == By::Ours && m.threads == peers::Threads::Gpu && !cuda_backend_available() ? " [unavailable here]" : "";
    }

    std::string thread_list() const {
        std::string s;
        for (int t : threads_) s += (s.empty() ? "" : ", ") + std::to_string(resolve_thread_count(t));
        return s;
    }

    nlohmann::json base_row(const std::string& label, const QuerySet& set, const PreparedMesh& mesh, const MethodKind& m) const {
        nlohmann::json row = {{"mesh", label}, {"resolution", set.name}, {"points", set.count},
                              {"triangles", mesh.triangles().size()}, {"method", m.name}, {"by", m.by == By::Ours ? "ours" : "peer"}};
        if (set.point_set)
            row["point_set"] = {{"kind", point_set_kind_name(set.point_set->kind)}, {"count", set.point_set->count},
                                {"sigma", set.point_set->kind == PointSetKind::GaussianSurface ? nlohmann::json(set.point_set->sigma)
                                                                                                 : nlohmann::json()},
                                {"seed", set.point_set->seed}};
        return row;
    }

    /// Every selected method on one case's points, in the table's order (the reference first),
    /// then the case's summary.
    void run_case(RunContext& ctx, const std::string& label, const std::shared_ptr<const PreparedMesh>& mesh, const QuerySet& set,
                  const std::vector<Vec3d>& points, double goal) {
        std::vector<double> reference;
        std::unique_ptr<MeshSdf> exact;  // band cases: the exact field at each row's own active voxels
        if (set.band_width > 0) {
            SamplerOptions o;
            o.backend = "cpu";
            o.method = "bvh";
            o.threads = 0;
            o.sign = lattice_sign_;
            o.progress = false;
            exact = std::make_unique<MeshSdf>(mesh, o);
        }
        for (Method& m : methods_)
            if (selected(*m.kind, set.point_set, set.band_width > 0))
                time_method(ctx, label, mesh, set, points, m, reference, exact.get());
        std::vector<nlohmann::json> thread_keys;
        for (int t : threads_) thread_keys.push_back(resolve_thread_count(t));
        // All cores too: the exact-sign reference runs there whatever "threads" says.
        const nlohmann::json all_cores = resolve_thread_count(0);
        if (std::count(thread_keys.begin(), thread_keys.end(), all_cores) == 0) thread_keys.push_back(all_cores);
        thread_keys.push_back("GPU");
        for (const nlohmann::json& s : peers::summarise_case(ctx.metrics["rows"], label, set.name, thread_keys, goal)) {
            *ctx.log << peers::summary_text(s);
            ctx.metrics["summary"].push_back(s);
            if (s.contains("not_compared")) continue;
            const std::string tkey = s["threads"].is_string() ? "gpu" : std::to_string(s["threads"].get<int>());
            ctx.metrics["regression"][label + "/" + set.name + "/" + tkey + "/" + s["ours"].get<std::string>() + "_vs_fastest_peer"] =
                {{"value", s["query_speedup"]}, {"kind", "speedup"}};
        }
    }

    /// The one timing loop of every method, ours and the peers': at each of its thread counts,
    /// `repetitions_` runs (the medians of their times), the errors against the reference
    /// (the reference method's first run makes it) and the check.
    void time_method(RunContext& ctx, const std::string& label, const std::shared_ptr<const PreparedMesh>& mesh, const QuerySet& set,
                     const std::vector<Vec3d>& points, Method& m, std::vector<double>& reference, const MeshSdf* exact) {
        const MethodKind& kind = *m.kind;
        nlohmann::json row = base_row(label, set, *mesh, kind);
        if (!m.adapter) return emit(ctx, row, m.why_not);
        if (kind.inputs == peers::Inputs::Lattices && !set.lattice)
            return emit(ctx, row, "n/a: a narrow-band grid on a lattice, not a point query");
        // Strided methods: every (N / n)-th point, timed and scaled to the set.
        std::vector<Vec3d> subset;
        std::vector<int64_t> index;
        const int64_t n = set.count;
        if (kind.strided) {
            const int64_t count = brute_max_points_ > 0 ? std::min(brute_max_points_, n) : n;
            for (int64_t k = 0; k < count; ++k) {
                index.push_back(k * (n / count));
                subset.push_back(points[size_t(index.back())]);
            }
        }
        const bool strided = kind.strided && int64_t(subset.size()) < n;
        peers::PeerInput input;
        input.mesh = mesh;
        input.lattice = kind.strided ? nullptr : set.lattice;
        input.points = set.band_width > 0 ? nullptr : kind.strided ? &subset : &points;
        input.band_width = set.band_width;
        input.our_sign = set.point_set ? point_set_sign_ : lattice_sign_;
        const double scale = kind.strided ? double(n) / double(subset.size()) : 1.0;
        const double tolerance = peers::kCheckTolerance * mesh->bounds().diagonal();
        const bool gpu = kind.threads == peers::Threads::Gpu;
        std::vector<int> thread_counts = threads_;
        if (gpu) thread_counts = {threads_.front()};
        if (kind.threads == peers::Threads::AllCores) thread_counts = {0};
        for (int t : thread_counts) {
            input.threads = resolve_thread_count(t);
            peers::PeerResult r;
            std::vector<double> build, query, end_to_end, cpu, build_cpu;
            for (int k = 0; k < repetitions_; ++k) {
                const double cpu0 = peers::process_cpu_seconds();
                r = m.adapter->run(input);
                build.push_back(r.build_seconds);
                query.push_back(r.query_seconds);
                end_to_end.push_back(r.end_to_end_seconds);
                cpu.push_back(r.cpu_seconds >= 0 ? r.cpu_seconds : peers::process_cpu_seconds() - cpu0);
                build_cpu.push_back(r.build_cpu_seconds);
            }
            if (kind.name == std::string(reference_of(set.point_set)) && reference.empty()) reference = r.distance;
            nlohmann::json row_t = row;
            if (!m.adapter->version().empty()) row_t["version"] = m.adapter->version();
            row_t["exact"] = kind.exact;
            row_t["build_seconds"] = median_of(build);
            row_t["query_seconds"] = median_of(query) * scale;
            row_t["total_seconds"] = row_t["build_seconds"].get<double>() + row_t["query_seconds"].get<double>();
            const size_t computed = input.points ? input.points->size() : r.band_points.size();
            row_t["points_per_second"] = median_of(query) > 0 ? double(computed) / median_of(query) : 0.0;
            if (gpu) {
                row_t["threads"] = "GPU";
                if (r.end_to_end_seconds >= 0) row_t["end_to_end_seconds"] = median_of(end_to_end) * scale;
            } else {
                row_t["threads"] = r.threads;
                // A strided row's query scales to the set, its build does not.
                row_t["cpu_seconds"] = median_of(build_cpu) + (median_of(cpu) - median_of(build_cpu)) * scale;
            }
            // The row's sign: ours, what the mode resolved to; a peer's, its table row's (checked).
            if (kind.sign != peers::SignKind::Mode && r.sign != kind.sign)
                throw std::logic_error(std::string("peers: ") + kind.name + " returned sign \"" + peers::sign_kind_name(r.sign) +
                                       "\", its table row says \"" + peers::sign_kind_name(kind.sign) + "\"");
            row_t["sign"] = peers::sign_kind_name(r.sign);
            const std::string sign_method = r.sign_method.empty() ? kind.sign_method : r.sign_method;
            if (!sign_method.empty()) row_t["sign_method"] = sign_method;
            std::vector<double> band_reference;
            if (exact) {  // a band case: the exact field at this row's active voxels
                for (const PointSample& p : exact->query(r.band_points)) band_reference.push_back(p.distance);
                row_t["points"] = int64_t(r.band_points.size());
                row_t["active_voxels"] = int64_t(r.band_points.size());
                row_t["level_set"] = {{"width", set.band_width}, {"width_voxels", set.band_voxels},
                                 {"active_voxels", int64_t(r.band_points.size())},
                                 {"lattice_points", set.lattice->num_points()},
                                 {"accuracy", r.is_signed() ? "max |d - exact| over the active voxels; wrong signs there"
                                                            : "unsigned: max ||d| - |exact|| over the active voxels; no sign"}};
            }
            const peers::Errors e = peers::compare(r.distance, exact ? band_reference : reference, index, r.is_signed(), tolerance);
            peers::set_errors(row_t, e, r.is_signed());
            peers::set_check(row_t, e, r.is_signed(), kind.exact, tolerance);
            if (!r.in_band.empty()) {
                const peers::Errors in = peers::compare(r.distance, reference, index, true, tolerance, &r.in_band, true);
                const peers::Errors out = peers::compare(r.distance, reference, index, true, tolerance, &r.in_band, false);
                row_t["band"] = {{"points_in_band", in.compared}, {"max_abs_error_in_band", in.max_abs},
                                 {"mean_abs_error_in_band", in.mean_abs()}, {"sign_disagreements_in_band", in.sign_disagreements},
                                 {"max_abs_error_outside_band", out.max_abs},
                                 {"sign_disagreements_outside_band", out.sign_disagreements}};
            }
            if (r.details.contains("first_call_seconds")) row_t["first_call_seconds"] = r.details["first_call_seconds"];
            row_t["details"] = r.details;
            if (kind.by == By::Ours) row_t["notes"] = r.notes + "; " + reference_note(kind, set);
            if (kind.strided) row_t["extrapolated"] = strided;
            emit(ctx, row_t);
        }
    }

    std::string reference_note(const MethodKind& kind, const QuerySet& set) const {
        const std::string ref = reference_of(set.point_set);
        std::string note = kind.name == ref ? "the reference of this case (equals brute force: tests/cpu_reference/bvh; "
                                              "checked against brute_cpu)"
                                            : "checked against the reference " + ref + " (sign " + sign_mode_name(lattice_sign_) + ")";
        if (kind.strided)
            note += "; timed on " + std::to_string(std::min<int64_t>(brute_max_points_ > 0 ? brute_max_points_ : set.count, set.count)) +
                    " evenly strided points and scaled; its errors check the reference there";
        return note;
    }

    void emit(RunContext& ctx, nlohmann::json row, const std::string& status = "") {
        if (!status.empty()) row["status"] = status;
        *ctx.log << peers::row_text(row) << std::flush;
        ctx.metrics["rows"].push_back(row);
    }

    std::vector<std::string> search_path_;
    std::string base_dir_;
    double margin_ = 0.1;
    std::vector<MeshCase> cases_;
    std::vector<PointSetSpec> point_sets_;
    std::vector<int> threads_;
    std::vector<int> band_resolutions_;
    std::vector<std::string> ours_, peer_names_;
    int64_t brute_max_points_ = 4096;
    peers::PeerOptions peer_options_;
    int repetitions_ = 1;
    SignMode lattice_sign_ = SignMode::Auto, point_set_sign_ = SignMode::Auto;
    std::vector<std::string> point_set_meshes_;
    std::vector<Method> methods_;
};

}  // namespace

std::unique_ptr<Experiment> make_peers_experiment() { return std::make_unique<PeersExperiment>(); }

}  // namespace sdf
