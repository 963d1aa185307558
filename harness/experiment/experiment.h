/// @file experiment.h
/// @brief An experiment kind: reads its part of a config, plans, then runs and reports.
///
/// Adding a kind is one file under experiments/ that defines the class and one line in
/// experiments/experiment_registry.cpp. The runner (harness/runner) is handed that registry
/// by its caller (apps/run_experiment_main.cpp), so the harness never reaches up into
/// experiments/; it owns the config (inheritance,
/// sweeps), the run directory, the manifest and the checks; an experiment only reads its
/// keys, computes, and reports into RunContext::metrics:
///   metrics["regression"] = {"<key>": {"value": v, "kind": "error" | "speedup" | "exact"}}
/// lists the figures the regression check compares (harness/check/regression_check.h), and
/// RunContext::inputs what the manifest records as inputs (mesh hashes, cache keys).
#pragma once

#include <functional>
#include <iosfwd>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "harness/config/json_reader.h"
#include "harness/resources/memory_budget.h"

namespace sdf {

class FieldCache;
class ContentCache;

struct RunContext {
    std::string config_path;  ///< as given on the command line
    std::string config_dir;   ///< absolute: the base of relative paths in the config
    std::string run_name;     ///< the config's name, or the sweep point's
    std::string output_dir;   ///< the (staged) directory to write into
    std::string run_id;       ///< "<name>/<run-id>": the run's final name, for files' metadata
                              ///< (output_dir is a staging directory until the run is complete)
    nlohmann::json metrics = nlohmann::json::object();  ///< results; written to metrics.json
    nlohmann::json inputs = nlohmann::json::object();   ///< input hashes for the manifest
    std::ostream* log = nullptr;        ///< human-readable progress and summary (stdout)
    const FieldCache* fields = nullptr; ///< sampled-field cache; null = --no-cache
    const ContentCache* cache = nullptr;  ///< other cached results (probes); null = --no-cache
};

class Experiment {
public:
    virtual ~Experiment() = default;
    /// Reads every key this kind understands from the root config (the runner rejects the
    /// rest afterwards) and validates it, before any expensive work, so that config errors
    /// come first and a dry run finds what the run would.
    virtual void configure(JsonReader& config, const RunContext& context) = 0;
    /// The plan for --dry-run: one line per step, with the cache's hits and misses (this may
    /// load the mesh to place the lattices), and TODO lines for what is not built yet.
    virtual std::vector<std::string> plan(const RunContext& context) const = 0;
    /// The host memory its largest step needs (memory_budget.h): the runner refuses a run
    /// that does not fit before anything is computed, and --dry-run shows it. Known from the
    /// configuration alone (no mesh loaded). Default: not estimated.
    virtual MemoryNeed memory_need(const RunContext&) const { return {}; }
    /// Does the work; writes files under context.output_dir, results into context.metrics.
    virtual void run(RunContext& context) = 0;
};

/// One experiment kind: its config name ("kind": "...") and its factory.
struct ExperimentKind {
    const char* name;
    std::unique_ptr<Experiment> (*make)();
};

/// The kinds a runner can run, in the order the tools list them.
using ExperimentRegistry = std::vector<ExperimentKind>;

/// The kinds' names, for config validation and messages.
std::vector<std::string> experiment_kind_names(const ExperimentRegistry& registry);

/// Creates the experiment registered under `kind`; throws naming the known kinds.
std::unique_ptr<Experiment> make_experiment(const ExperimentRegistry& registry, const std::string& kind);

}  // namespace sdf
