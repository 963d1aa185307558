/// @file experiment.h
/// @brief An experiment kind: reads its part of a config, then runs and writes results.
///
/// Adding a kind is one file that defines the class and one registration line in
/// experiment_registry.cpp. The runner (harness/runner) owns the run directory, the
/// manifest and the checks; an experiment only reads its keys, computes, and reports.
#pragma once

#include <functional>
#include <iosfwd>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "harness/config/json_reader.h"

namespace sdf {

struct RunContext {
    std::string config_path;  ///< as given on the command line
    std::string config_dir;   ///< for relative paths in the config
    std::string output_dir;   ///< the (staged) run directory to write into
    nlohmann::json metrics;   ///< results; the runner writes it to metrics.json
    std::ostream* log = nullptr;  ///< human-readable summary (stdout)
};

class Experiment {
public:
    virtual ~Experiment() = default;
    /// Reads every key this kind understands from the root config (the runner rejects the
    /// rest afterwards), before any expensive work, so that config errors come first.
    virtual void configure(JsonReader& config, const RunContext& context) = 0;
    /// A human-readable plan (for --dry-run): what will be computed.
    virtual std::vector<std::string> plan() const = 0;
    /// Does the work; writes files under context.output_dir and results into context.metrics.
    virtual void run(RunContext& context) = 0;
};

/// Creates the experiment registered under `kind`; throws naming the known kinds.
std::unique_ptr<Experiment> make_experiment(const std::string& kind);
std::vector<std::string> experiment_kinds();

}  // namespace sdf
