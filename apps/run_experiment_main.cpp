// run-experiment CONFIG.json [--output-root DIR] [--dry-run] [--no-cache] [--cache-dir DIR]
//                            [--check [--baseline PATH]] [--quiet] [--distribute slabs|runs]
// mpirun -np N run-experiment CONFIG.json ...   (docs/distributed.md)
// run-experiment --check-run RUN_DIR [--baseline PATH]
// run-experiment --write-baseline RUN_DIR [--baseline PATH] [--force]
//
// docs/harness.md describes configs, caching, results, checks and reports.
#include <CLI/CLI.hpp>

#include "apps/cli_exit.h"

#include <cstdlib>
#include <filesystem>
#include <iostream>

#include "core/mesh/sha256.h"
#include "core/parallel/progress.h"
#include "experiments/experiment_registry.h"
#include "harness/config/mesh_spec.h"
#include "harness/distributed/distributed.h"
#include "harness/resources/memory_budget.h"
#include "harness/runner/runner.h"

namespace {

/// What this rank's command line and environment chose: every rank of a distributed run must
/// have the same (sdf::require_same_settings_on_every_rank), the config's content included.
nlohmann::json run_settings(const sdf::RunnerOptions& o, const std::string& distribute, const std::string& check_run,
                            const std::string& make_baseline, bool force, bool quiet) {
    nlohmann::json s = {{"config", o.config_path},     {"--output-root", o.output_root}, {"--dry-run", o.dry_run},
                        {"--no-cache", o.no_cache},    {"--cache-dir", o.cache_dir},     {"--check", o.check},
                        {"--baseline", o.baseline},    {"--check-run", check_run},       {"--write-baseline", make_baseline},
                        {"--force", force},            {"--quiet", quiet},               {"--distribute", distribute}};
    std::error_code ec;
    if (!o.config_path.empty() && std::filesystem::is_regular_file(o.config_path, ec))
        s["config file SHA-256"] = sdf::sha256_of_file(o.config_path);
    for (const char* name : {"SDF_DATA_PATH", "SDF_CACHE_DIR", "SDF_MEMORY_AVAILABLE"})
        s[std::string("$") + name] = std::getenv(name) ? std::getenv(name) : "";
    return s;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"Runs an experiment described by a JSON config (docs/harness.md), checks runs against baselines, "
                 "and makes baselines."};
    sdf::add_version_flag(app, "run-experiment");
    sdf::RunnerOptions options;
    options.experiments = &sdf::experiment_registry();
    bool quiet = false, force = false;
    std::string check_run, make_baseline;
    app.add_option("config", options.config_path, "experiment config (JSON)");
    app.add_option("--output-root", options.output_root, "where <name>/<run-id>/ go")->capture_default_str();
    app.add_flag("--dry-run", options.dry_run, "validate the config and print the plan with cache hits; compute nothing");
    app.add_flag("--no-cache", options.no_cache, "sample every field again (neither read nor fill the field cache)");
    app.add_option("--cache-dir", options.cache_dir, "field cache directory (default $SDF_CACHE_DIR or <repo>/cache)");
    app.add_flag("--check", options.check, "after the run, compare its metrics with the baseline (exit 3 on failure)");
    app.add_option("--baseline", options.baseline,
                   "baseline file (default: the config's \"baseline\", else <repo>/results/baselines/<name>.json)");
    app.add_option("--check-run", check_run, "check a stored run directory against its baseline, run nothing");
    app.add_option("--write-baseline", make_baseline, "make a baseline from a stored run directory (clean runs only)");
    app.add_flag("--force", force, "with --write-baseline: replace an existing baseline file");
    app.add_flag("--quiet", quiet, "no progress lines");
    std::string distribute = "slabs";
    app.add_option("--distribute", distribute,
                   "under mpirun (docs/distributed.md): 'slabs' cuts every sampled lattice over the ranks; 'runs' gives "
                   "each rank whole runs of a sweep (needs a file system shared by the ranks)")
        ->check(CLI::IsMember({"slabs", "runs"}))
        ->capture_default_str();
    SDF_CLI_PARSE(app, argc, argv);
    // Under mpirun: rank 0 runs the config, the other ranks sample the slabs it hands out
    // (docs/distributed.md). Every rank has parsed the same command line by now.
    sdf::DistributedScope mpi(argc, argv);
    try {
        // Ranks that disagree would wait for each other's messages forever: stop them all now.
        sdf::require_same_settings_on_every_rank(run_settings(options, distribute, check_run, make_baseline, force, quiet));
    } catch (const std::exception& e) {
        // Rank 0 names every option that differs and the ranks; the others say why they stop.
        if (sdf::distributed_rank() == 0) std::cerr << "run-experiment: error: " << e.what() << "\n";
        else std::cerr << "run-experiment: rank " << sdf::distributed_rank() << " stops: rank 0 found options that differ\n";
        return 1;
    }
    if (distribute == "runs") sdf::set_distribution(sdf::Distribution::Runs);
    if (sdf::distributed_rank() != 0 && (distribute == "slabs" || options.config_path.empty()))
        return distribute == "slabs" ? sdf::serve_distributed_requests() : 0;
    sdf::ProgressReporter::set_globally_enabled(!quiet);
    const int modes = int(!options.config_path.empty()) + int(!check_run.empty()) + int(!make_baseline.empty());
    if (modes != 1) {
        std::cerr << "run-experiment: error: give a config to run, or --check-run RUN_DIR, or --write-baseline RUN_DIR "
                     "(exactly one)\n"
                  << app.help();
        return sdf::kExitCommandLineError;
    }
    try {
        if (!check_run.empty()) return sdf::check_stored_run(check_run, options.baseline);
        if (!make_baseline.empty()) return sdf::write_baseline(make_baseline, options.baseline, force);
        return sdf::run_experiment(options);
    } catch (const sdf::MeshFileNotFound& e) {
        std::cerr << "run-experiment: error: " << e.what() << "\n";
        return sdf::kExitMeshNotFound;
    } catch (const std::bad_alloc&) {
        // The plan refused what it could estimate (harness/resources/memory_budget.h); this is what it could not.
        std::cerr << "run-experiment: error: "
                  << sdf::out_of_memory_message("running " + (options.config_path.empty() ? check_run + make_baseline : options.config_path), 0)
                  << "\n";
        return 1;
    } catch (const std::exception& e) {
        std::cerr << "run-experiment: error: " << e.what() << "\n";
        return 1;
    }
}
