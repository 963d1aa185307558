/// @file regression_check.h
/// @brief Regression checks: a run's metrics against a committed baseline
/// (results/baselines/<name>.json), and making a baseline from a clean run.
///
/// An experiment lists the figures worth checking in metrics.json under "regression":
///   "regression": {"cc-80x80x80/catmull_rom/fd/domain_rms": {"value": 1.2e-4, "kind": "error"}, ...}
/// kinds: "error" (a reconstruction error: compared with a tolerance), "speedup" (a ratio of
/// times measured side by side in one run: compared with a floor, and only on the machine
/// kind that made the baseline), "exact" (a count that must not change).
///
/// A baseline holds, per metric, the value and its tolerance:
///   "error":   |run - baseline| <= absolute + relative * |baseline|   (either direction: an
///              error that drops far below the baseline is a change to look at, too)
///   "speedup": run >= floor, when the run's machine kind (CPU model and GPU name) equals the
///              baseline's; elsewhere the metric is reported as not comparable, not failed
///   "exact":   run == baseline
/// The tolerances are written with defaults by make_baseline() and may be edited by hand.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace sdf {

struct BaselineDefaults {
    double error_relative = 0.01;   ///< 1 %: float sampling and FMA differences stay far below
    double error_absolute = 1e-12;
    double speedup_floor_fraction = 0.8;  ///< floor = 0.8 x the baseline's speedup (timing noise)
};

/// A baseline from a finished run (its manifest.json and metrics.json). Throws when the run
/// was made from a dirty or unknown git state, or has nothing to check.
nlohmann::json make_baseline(const nlohmann::json& manifest, const nlohmann::json& metrics,
                             const BaselineDefaults& defaults = {});

struct CheckResult {
    int ok = 0, failed = 0, not_comparable = 0, missing = 0, added = 0;
    std::vector<std::string> lines;  ///< one readable line per finding, then a summary
    bool passed() const { return failed == 0 && missing == 0; }
    std::string text() const;
};

/// Compares a run with a baseline; `baseline_label` names the baseline in the messages.
CheckResult check_run(const nlohmann::json& manifest, const nlohmann::json& metrics, const nlohmann::json& baseline,
                      const std::string& baseline_label);

}  // namespace sdf
