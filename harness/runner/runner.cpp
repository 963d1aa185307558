#include "harness/runner/runner.h"

#include <chrono>
#include <filesystem>
#include <iostream>
#include <regex>
#include <sstream>

#include "core/mesh/sha256.h"
#include "harness/experiment/experiment.h"
#include "harness/build_config.h"
#include "harness/cache/field_cache.h"
#include "harness/check/regression_check.h"
#include "harness/config/config_loader.h"
#include "harness/config/sweep.h"
#include "harness/distributed/distributed.h"
#include "harness/io/atomic_file.h"
#include "harness/provenance/provenance.h"

namespace sdf {
namespace fs = std::filesystem;

namespace {

/// One run of the plan (one sweep point), configured.
struct PlannedRun {
    SweepPoint point;
    std::shared_ptr<nlohmann::json> resolved;
    std::string kind, baseline;
    std::unique_ptr<Experiment> experiment;
    RunContext context;
};

/// Directories created on the way to the run directory; those still empty at the end (a
/// failed run) are removed again, innermost first.
class CreatedDirectories {
public:
    void create(const fs::path& dir) {
        std::vector<fs::path> missing;
        for (fs::path p = dir; !p.empty() && !fs::exists(p); p = p.parent_path()) missing.push_back(p);
        fs::create_directories(dir);
        created_.insert(created_.end(), missing.begin(), missing.end());
    }
    ~CreatedDirectories() {
        for (const fs::path& p : created_) {
            std::error_code ec;
            if (fs::is_directory(p, ec) && fs::is_empty(p, ec)) fs::remove(p, ec);
        }
    }

private:
    std::vector<fs::path> created_;  ///< innermost first
};

std::string read_run_name(JsonReader& root) {
    const std::string name = root.required<std::string>(
        "name", "a run name of letters, digits, '-', '_' or '.', starting with a letter or digit");
    if (!std::regex_match(name, std::regex("[A-Za-z0-9][A-Za-z0-9_.-]*")))
        root.fail("name", "expected letters, digits, '-', '_' or '.', starting with a letter or digit, got \"" + name + "\"");
    return name;
}

std::string config_hash(const std::vector<PlannedRun>& runs) {
    nlohmann::json all = nlohmann::json::array();
    for (const PlannedRun& r : runs) all.push_back(*r.resolved);
    const std::string text = runs.size() == 1 ? all[0].dump() : all.dump();
    return sha256_hex(text.data(), text.size());
}

std::vector<PlannedRun> configure_runs(const LoadedConfig& config, const RunnerOptions& options, const FieldCache* fields,
                                       const ContentCache* cache) {
    const std::string file = config.label();
    JsonReader top(config.merged, file);
    const std::string name = read_run_name(top);
    std::vector<PlannedRun> runs;
    for (SweepPoint& point : expand_sweep(config.merged, file, name)) {
        PlannedRun r;
        r.point = std::move(point);
        r.resolved = std::make_shared<nlohmann::json>(r.point.config);
        JsonReader root(r.point.config, file, "", r.resolved, nlohmann::json::json_pointer());
        read_run_name(root);
        r.kind = root.choice("kind", experiment_kind_names(*options.experiments), "sampling");
        root.optional<std::string>("description", "", "a string");
        r.baseline = root.optional<std::string>("baseline", "", "the path of the baseline file (relative to the config)");
        r.context.config_path = options.config_path;
        r.context.config_dir = fs::path(config.files.front()).parent_path().string();
        r.context.run_name = r.point.name;
        r.context.log = &std::cout;
        r.context.fields = fields;
        r.context.cache = cache;
        r.experiment = make_experiment(*options.experiments, r.kind);
        r.experiment->configure(root, r.context);
        root.finish();
        runs.push_back(std::move(r));
    }
    return runs;
}

/// The run's peak host memory: runs (sweep points) execute one after the other.
MemoryNeed largest_memory_need(const std::vector<PlannedRun>& runs) {
    MemoryNeed largest;
    for (const PlannedRun& r : runs) {
        MemoryNeed n = r.experiment->memory_need(r.context);
        if (runs.size() > 1 && n.host_bytes) n.what += " in " + r.point.name;
        if (n.host_bytes > largest.host_bytes) largest = std::move(n);
    }
    return largest;
}

void print_plan(const LoadedConfig& config, const std::vector<PlannedRun>& runs, const std::string& hash,
                const RunnerOptions& options, const std::string& cache_root) {
    std::cout << "plan for " << config.label() << " (kind " << runs[0].kind << ", " << runs.size()
              << (runs.size() == 1 ? " run" : " runs") << ", config " << hash.substr(0, 12) << "):\n";
    std::cout << "  cache: " << (options.no_cache ? "off (--no-cache: everything is sampled again)" : cache_root) << "\n";
    std::cout << "  memory: " << describe_memory_need(largest_memory_need(runs)) << "\n";
    for (size_t i = 0; i < runs.size(); ++i) {
        const PlannedRun& r = runs[i];
        if (runs.size() > 1)
            std::cout << "  [" << i + 1 << "/" << runs.size() << "] " << r.point.name << "  " << r.point.parameters.dump() << "\n";
        for (const std::string& line : r.experiment->plan(r.context)) std::cout << (runs.size() > 1 ? "      - " : "  - ") << line << "\n";
    }
    const std::string name = JsonReader(config.merged, config.label()).raw("name").get<std::string>();
    std::cout << "  results: " << (fs::path(options.output_root) / name).string()
              << "/<run-id>/ (manifest.json, metrics.json)" << (options.check ? ", then checked against the baseline" : "")
              << "\n";
}

std::string baseline_path_for(const std::string& explicit_path, const std::string& from_config, const std::string& config_dir,
                              const std::string& name) {
    if (!explicit_path.empty()) return explicit_path;
    if (!from_config.empty())
        return fs::path(from_config).is_absolute() ? from_config : (fs::path(config_dir) / from_config).string();
    return (fs::path(SDF_SOURCE_DIR) / "results" / "baselines" / (name + ".json")).string();
}

CheckResult check_against(const nlohmann::json& manifest, const nlohmann::json& metrics, const std::string& baseline_path) {
    if (!fs::is_regular_file(baseline_path))
        throw std::runtime_error("no baseline at " + baseline_path +
                                 "; make one from a clean run with: run-experiment --write-baseline RUN_DIR");
    const CheckResult r = check_run(manifest, metrics, read_json_file(baseline_path, "baseline"), baseline_path);
    std::cout << r.text();
    return r;
}

int report_check(const nlohmann::json& manifest, const nlohmann::json& metrics, const std::string& baseline_path) {
    return check_against(manifest, metrics, baseline_path).passed() ? 0 : kCheckFailedExitCode;
}

/// What a stored run records of its --check (harness/schema/run_schema.json: "check").
nlohmann::json check_record(const CheckResult& r, const std::string& baseline_path) {
    return {{"baseline", baseline_path}, {"passed", r.passed()},    {"ok", r.ok},
            {"failed", r.failed},        {"not_comparable", r.not_comparable}, {"missing", r.missing},
            {"added", r.added}};
}

nlohmann::json combined_metrics(std::vector<PlannedRun>& runs) {
    if (runs.size() == 1) return runs[0].context.metrics;
    nlohmann::json m = {{"points", nlohmann::json::array()}, {"regression", nlohmann::json::object()}};
    for (PlannedRun& r : runs) {
        nlohmann::json pm = r.context.metrics;
        if (pm.contains("regression"))
            for (const auto& [k, v] : pm["regression"].items()) m["regression"][r.point.name + "/" + k] = v;
        pm.erase("regression");
        m["points"].push_back({{"name", r.point.name}, {"parameters", r.point.parameters}, {"metrics", pm}});
    }
    m["sweep"] = nlohmann::json::array();
    for (const auto& [k, v] : runs[0].point.parameters.items()) m["sweep"].push_back(k);
    return m;
}

nlohmann::json make_manifest(const LoadedConfig& config, const std::vector<PlannedRun>& runs, const std::string& hash,
                             const std::string& run_id, const std::string& started, const nlohmann::json& load_at_start,
                             const RunnerOptions& options, const std::string& cache_root) {
    const PlannedRun& first = runs[0];
    nlohmann::json manifest = {{"run_id", run_id},
                               {"name", JsonReader(config.merged, config.label()).raw("name")},
                               {"kind", first.kind},
                               {"description", first.resolved->value("description", std::string())},
                               {"config", {{"path", fs::absolute(config.path).lexically_normal().string()},
                                           {"files", config.files},
                                           {"sha256", hash},
                                           {"as_written", config.as_written}}},
                               {"started", started},
                               {"finished", utc_timestamp()},
                               {"cache", {{"used", !options.no_cache}, {"root", options.no_cache ? "" : cache_root}}},
                               {"provenance", machine_and_build()}};
    manifest["provenance"]["load_average"] = {{"start", load_at_start}, {"end", load_average()}};
    if (distributed_active()) manifest["distributed"] = distributed_description();
    if (runs.size() == 1) {
        manifest["config"]["resolved"] = *first.resolved;
        manifest["inputs"] = first.context.inputs;
    } else {
        manifest["config"]["merged"] = config.merged;
        for (const PlannedRun& r : runs) {
            const std::string text = r.resolved->dump();
            manifest["points"].push_back({{"name", r.point.name},
                                          {"parameters", r.point.parameters},
                                          {"resolved", *r.resolved},
                                          {"sha256", sha256_hex(text.data(), text.size())}});
            manifest["inputs"][r.point.name] = r.context.inputs;
        }
    }
    return manifest;
}

/// Runs run i of the plan (one sweep point) into `staging`, as part of the run named `run_id`
/// ("<name>/<run-id>"): a sweep's runs each in their own subdirectory, announced on `log`.
/// The one per-run step of both ways to run a plan: all runs here, or this rank's share.
void run_one(std::vector<PlannedRun>& runs, size_t i, const std::string& staging, const std::string& run_id,
             std::ostream& log) {
    const bool sweep = runs.size() > 1;
    RunContext& ctx = runs[i].context;
    ctx.output_dir = sweep ? (fs::path(staging) / runs[i].point.name).string() : staging;
    ctx.run_id = run_id + (sweep ? "/" + runs[i].point.name : "");
    ctx.log = &log;
    if (sweep)
        log << "[" << i + 1 << "/" << runs.size() << "] " << runs[i].point.name << " " << runs[i].point.parameters.dump()
            << std::endl;
    runs[i].experiment->run(ctx);
}

/// Sends the root's staging directory to the workers of a run distributed by runs, or ""
/// when the root failed before it had one (the workers then stop).
class StagingAnnouncement {
public:
    explicit StagingAnnouncement(bool needed) : needed_(needed) {}
    void send(const std::string& staging) {
        if (needed_) broadcast_from_root(staging);
        needed_ = false;
    }
    ~StagingAnnouncement() {
        try {
            send("");
        } catch (...) {  // already failing
        }
    }

private:
    bool needed_;
};

/// Runs this rank's share of the runs (run i on rank i % ranks) into `staging` (the run's final
/// name is `run_id`, "<name>/<run-id>"); returns what
/// the root needs of them: ok or the error, and per run its metrics, inputs and seconds.
nlohmann::json run_my_share(std::vector<PlannedRun>& runs, const std::string& staging, const std::string& run_id,
                            std::ostream& log) {
    const nlohmann::json self = this_process();
    nlohmann::json mine = {{"ok", true}, {"rank", distributed_rank()}, {"host", self.value("host", std::string("?"))},
                           {"runs", nlohmann::json::array()}};
    try {
        if (!fs::is_directory(staging))
            throw std::runtime_error("the run's staging directory " + staging +
                                     " is not visible here: --distribute runs needs a file system shared by every rank");
        for (size_t i = 0; i < runs.size(); ++i) {
            if (int(i % size_t(distributed_size())) != distributed_rank()) continue;
            const auto start = std::chrono::steady_clock::now();
            fail_here_if_asked();
            run_one(runs, i, staging, run_id, log);
            const RunContext& ctx = runs[i].context;
            mine["runs"].push_back({{"index", i},
                                    {"metrics", ctx.metrics},
                                    {"inputs", ctx.inputs},
                                    {"seconds", std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()}});
        }
    } catch (const std::exception& e) {
        mine["ok"] = false;
        mine["error"] = e.what();
    }
    return mine;
}

/// The root's side of a run distributed by runs: every rank's results into `runs`; throws
/// naming each failed rank and its host. Returns the manifest's record of who ran what.
nlohmann::json collect_shares(std::vector<PlannedRun>& runs, const nlohmann::json& all) {
    std::string errors;
    nlohmann::json record = nlohmann::json::array();
    for (const nlohmann::json& share : all) {
        const std::string who = "rank " + std::to_string(share.value("rank", -1)) + " (host " + share.value("host", std::string("?")) + ")";
        if (!share.value("ok", false)) {
            errors += (errors.empty() ? "" : "; ") + who + ": " + share.value("error", std::string("unknown error"));
            continue;
        }
        for (const nlohmann::json& r : share["runs"]) {
            PlannedRun& run = runs[r["index"].get<size_t>()];
            run.context.metrics = r["metrics"];
            run.context.inputs = r["inputs"];
            record.push_back({{"name", run.point.name}, {"rank", share["rank"]}, {"host", share["host"]}, {"seconds", r["seconds"]}});
        }
    }
    if (!errors.empty()) throw std::runtime_error("distributed run failed: " + errors);
    return record;
}

}  // namespace

int run_experiment(const RunnerOptions& options) {
    if (options.experiments == nullptr || options.experiments->empty())
        throw std::logic_error("run_experiment: no experiment registry given (RunnerOptions::experiments)");
    const LoadedConfig config = load_config(options.config_path);
    const std::string cache_root = options.cache_dir.empty() ? ContentCache::default_root() : options.cache_dir;
    // Refused here, in the plan and the dry run alike, not after the first field is sampled.
    if (!options.no_cache)
        ContentCache::require_usable_root(cache_root, options.cache_dir.empty() ? "the cache directory" : "--cache-dir");
    const FieldCache fields(cache_root);
    const ContentCache cache(cache_root);
    std::vector<PlannedRun> runs =
        configure_runs(config, options, options.no_cache ? nullptr : &fields, options.no_cache ? nullptr : &cache);
    const std::string hash = config_hash(runs);
    const std::string name = JsonReader(config.merged, config.label()).raw("name").get<std::string>();
    const bool by_runs = distributed_active() && distribution() == Distribution::Runs;
    if (options.dry_run) {
        if (distributed_rank() == 0) print_plan(config, runs, hash, options, cache_root);
        return 0;
    }
    if (by_runs && distributed_rank() != 0) {
        // A worker of a run distributed by runs: the root stages, this rank runs its share.
        // The root sends "<staging directory>\n<name>/<run-id>", or "" when it failed first.
        const std::string announced = broadcast_from_root("");
        if (announced.empty()) return 1;  // the root failed first and says why
        const size_t cut = announced.find('\n');
        std::ostringstream quiet;
        const nlohmann::json mine = run_my_share(runs, announced.substr(0, cut), announced.substr(cut + 1), quiet);
        gather_to_root(mine);
        return mine["ok"].get<bool>() ? 0 : 1;
    }
    StagingAnnouncement announcement(by_runs);  // tells the workers if the root fails from here on
    // Before the run directory exists or anything is sampled (issue 11, class 5).
    require_host_memory(largest_memory_need(runs), config.label());

    const std::string started = utc_timestamp();
    const nlohmann::json load_at_start = load_average();
    const fs::path parent = fs::path(options.output_root) / name;
    CreatedDirectories created;  // declared first: removed (when empty) after the staging directory
    created.create(parent);
    remove_stale_staging(parent.string());
    // Run ids: UTC time to the millisecond and the config hash; a suffix when still taken.
    const std::string id_base = compact_utc_timestamp() + "-" + hash.substr(0, 8);
    // The id is reserved (an atomic mkdir) before the run starts, so that what the run writes
    // into its files (images' metadata) names the directory it will have: a concurrent run of
    // the same config in the same millisecond takes the next suffix instead of racing for the
    // final rename.
    std::string run_id = id_base;
    int suffix = 1;
    auto reservation = [&](const std::string& id) { return parent / ("." + id + ".reserved"); };
    while (fs::exists(parent / run_id) || !fs::create_directory(reservation(run_id)))
        run_id = id_base + "-" + std::to_string(++suffix);
    const std::string reserved_id = run_id;
    struct Unreserve {
        fs::path path;
        ~Unreserve() {
            std::error_code ec;
            fs::remove(path, ec);
        }
    } unreserve{reservation(reserved_id)};
    StagedDirectory out((parent / run_id).string());
    std::cout << "run " << name << "/" << run_id << " (kind " << runs[0].kind << (runs.size() > 1 ? ", " + std::to_string(runs.size()) + " sweep points" : std::string()) << ")" << std::endl;
    nlohmann::json ran_by;  // runs mode: which rank ran each run
    if (by_runs) {
        announcement.send(out.path() + "\n" + name + "/" + run_id);
        ran_by = collect_shares(runs, gather_to_root(run_my_share(runs, out.path(), name + "/" + run_id, std::cout)));
    } else {
        for (size_t i = 0; i < runs.size(); ++i) run_one(runs, i, out.path(), name + "/" + run_id, std::cout);
    }

    const nlohmann::json metrics = combined_metrics(runs);
    nlohmann::json manifest = make_manifest(config, runs, hash, run_id, started, load_at_start, options, cache_root);
    if (by_runs) manifest["distributed"]["points"] = ran_by;
    write_text_atomically(out.path() + "/metrics.json", metrics.dump(2) + "\n");
    write_text_atomically(out.path() + "/manifest.json", manifest.dump(2) + "\n");
    // A run of the same config may have taken this id meanwhile: take the next free one.
    while (!out.try_commit_as((parent / run_id).string())) {
        run_id = id_base + "-" + std::to_string(++suffix);
        manifest["run_id"] = run_id;
        write_text_atomically(out.path() + "/manifest.json", manifest.dump(2) + "\n", Overwrite::Allow);
    }
    std::cout << "results in " << out.final_path() << std::endl;
    if (!options.check) return 0;
    const std::string baseline = baseline_path_for(options.baseline, runs[0].baseline, runs[0].context.config_dir, name);
    const CheckResult r = check_against(manifest, metrics, baseline);
    // The stored run says whether it passed its check (the report shows it).
    manifest["check"] = check_record(r, baseline);
    write_text_atomically(out.final_path() + "/manifest.json", manifest.dump(2) + "\n", Overwrite::Allow);
    return r.passed() ? 0 : kCheckFailedExitCode;
}

int check_stored_run(const std::string& run_dir, const std::string& baseline_path) {
    const nlohmann::json manifest = read_json_file((fs::path(run_dir) / "manifest.json").string());
    const nlohmann::json metrics = read_json_file((fs::path(run_dir) / "metrics.json").string());
    const nlohmann::json cfg = manifest.at("config");
    const nlohmann::json resolved = cfg.contains("resolved") ? cfg["resolved"] : cfg.value("merged", nlohmann::json::object());
    const std::string config_dir = fs::path(cfg.value("path", std::string())).parent_path().string();
    return report_check(manifest, metrics,
                        baseline_path_for(baseline_path, resolved.value("baseline", std::string()), config_dir,
                                          manifest.at("name").get<std::string>()));
}

int write_baseline(const std::string& run_dir, const std::string& baseline_path, bool force) {
    const nlohmann::json manifest = read_json_file((fs::path(run_dir) / "manifest.json").string());
    const nlohmann::json metrics = read_json_file((fs::path(run_dir) / "metrics.json").string());
    const nlohmann::json baseline = make_baseline(manifest, metrics);
    const std::string path = baseline_path_for(baseline_path, "", "", manifest.at("name").get<std::string>());
    write_text_atomically(path, baseline.dump(2) + "\n", force ? Overwrite::Allow : Overwrite::Forbid);
    std::cout << "baseline " << path << ": " << baseline["metrics"].size() << " metrics from run "
              << manifest["run_id"].get<std::string>() << "\n";
    return 0;
}

}  // namespace sdf
