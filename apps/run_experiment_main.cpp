// run-experiment CONFIG.json [--output-root DIR] [--dry-run] [--no-cache] [--cache-dir DIR]
//                            [--check [--baseline PATH]] [--quiet] [--distribute slabs|runs]
// mpirun -np N run-experiment CONFIG.json ...   (docs/distributed.md)
// run-experiment --check-run RUN_DIR [--baseline PATH]
// run-experiment --write-baseline RUN_DIR [--baseline PATH] [--force]
//
// docs/harness.md describes configs, caching, results, checks and reports.
#include <CLI/CLI.hpp>

#include "apps/cli_exit.h"

#include <iostream>

#include "core/parallel/progress.h"
#include "experiments/experiment_registry.h"
#include "harness/config/mesh_spec.h"
#include "harness/distributed/distributed.h"
#include "harness/runner/runner.h"

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
    } catch (const std::exception& e) {
        std::cerr << "run-experiment: error: " << e.what() << "\n";
        return 1;
    }
}
