/// @file runner.h
/// @brief Runs one experiment config end to end: load it (with its parents), expand its
/// sweep, validate every run, plan (--dry-run), stage a run directory, run, write metrics
/// and the provenance manifest, move the directory into place, and optionally check the
/// result against its baseline. Also: checking a stored run, and making a baseline.
///
///   results/<name>/<run-id>/manifest.json, metrics.json, and what the experiment writes
///   (a sweep writes each point's files under <run-id>/<point name>/)
/// Exit codes: 0 success, 1 error (thrown), 3 a regression check failed.
#pragma once

#include <string>

#include "harness/experiment/experiment.h"

namespace sdf {

struct RunnerOptions {
    const ExperimentRegistry* experiments = nullptr;  ///< the kinds a config may name (required)
    std::string config_path;
    std::string output_root = "results";
    bool dry_run = false;
    bool no_cache = false;     ///< neither read nor fill the cache: sample everything again
    std::string cache_dir;     ///< "" = $SDF_CACHE_DIR or <repo>/cache
    bool check = false;        ///< compare the finished run with its baseline
    std::string baseline;      ///< "" = the config's "baseline", else <repo>/results/baselines/<name>.json
};

constexpr int kCheckFailedExitCode = 3;

/// Returns the process exit code; errors are thrown with messages naming file and key.
int run_experiment(const RunnerOptions& options);

/// Checks a stored run directory against a baseline ("" = the run config's baseline).
int check_stored_run(const std::string& run_dir, const std::string& baseline_path);

/// Writes a baseline from a stored run (refused for a dirty run, or over an existing
/// baseline unless `force`); "" = <repo>/results/baselines/<name>.json.
int write_baseline(const std::string& run_dir, const std::string& baseline_path, bool force);

}  // namespace sdf
