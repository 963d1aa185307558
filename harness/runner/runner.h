/// @file runner.h
/// @brief Runs one experiment config end to end: validate, plan, stage a run directory,
/// run, write metrics and the provenance manifest, and move the directory into place.
#pragma once

#include <string>

namespace sdf {

struct RunnerOptions {
    std::string config_path;
    std::string output_root = "results";
    bool dry_run = false;
};

/// Returns the process exit code; errors are thrown with messages naming file and key.
int run_experiment(const RunnerOptions& options);

}  // namespace sdf
