/// @file peer_rows.h
/// @brief The rows of the peers experiment (metrics.json "rows" and "summary", docs/bvh-peers.md):
/// each method's errors against the reference, its check, and the summary that compares only
/// rows that pass their own checks. Plain functions of JSON rows, so the summary's rules are
/// tested without running a method (tests/harness/peer_rows_test.cpp).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace sdf::peers {

/// The check's tolerance on |distance error|, relative to the mesh's bounding-box diagonal:
/// float peers round coordinates to 2^-24 relative (6e-8), so 1e-5 passes every correct float
/// search and fails any wrong triangle or lost sign farther than that from the surface.
constexpr double kCheckTolerance = 1e-5;

/// Errors of `d` against the reference at the same points.
struct Errors {
    double max_abs = 0;          ///< max |d - ref| (unsigned rows: max ||d| - |ref||)
    double max_abs_unsigned = 0; ///< max ||d| - |ref||: the distance alone, whatever the sign
    double sum_abs = 0;          ///< for the mean
    int64_t sign_disagreements = 0;
    int64_t sign_disagreements_beyond_tolerance = 0;  ///< where |ref| > the check's tolerance
    int64_t compared = 0;
    double mean_abs() const { return compared > 0 ? sum_abs / double(compared) : 0.0; }
};

/// Errors of d[k] against ref[index[k]] (index empty: ref[k]); with `mask`, only the points
/// whose mask equals `mask_value`. Sign disagreements count where |ref| > `tolerance`.
Errors compare(const std::vector<double>& d, const std::vector<double>& ref, const std::vector<int64_t>& index,
               bool is_signed, double tolerance, const std::vector<uint8_t>* mask = nullptr, bool mask_value = true);

/// The error keys of a row: max_abs_error, max_abs_error_unsigned, mean_abs_error,
/// compared_points, sign_disagreements ("n/a (unsigned)" for unsigned rows), ..._beyond_tolerance.
void set_errors(nlohmann::json& row, const Errors& e, bool is_signed);

/// The check of every row: "passes_check", "check" (why not, or "exact, signed"/"exact,
/// unsigned ..."), "signed", "check_tolerance". The unsigned distance first, then the signs.
void set_check(nlohmann::json& row, const Errors& e, bool is_signed, bool exact, double tolerance);

/// A row's sign in words: "pseudonormal", "winding", "unsigned", "own: <how>"; rows of runs
/// from before "sign" was recorded: "signed" or "unsigned".
std::string sign_label(const nlohmann::json& row);

/// The summary of one case (mesh `label`, points `resolution`) at each of `thread_keys` (a
/// thread count, or "GPU"): the fastest of our rows that pass their check (and were timed on
/// every point) against the fastest peer that passes, query and build + query, the fastest
/// signed peer beside it, every side's sign, and our rows that fail their check ("excluded":
/// never the basis of a ratio). Where no row of ours passes, the entry has no ratios and says
/// so ("not_compared"), as where no peer passes. Keys with no row of ours or no peer row are
/// left out. `goal` is the speedup the case aims at.
std::vector<nlohmann::json> summarise_case(const nlohmann::json& rows, const std::string& label, const std::string& resolution,
                                           const std::vector<nlohmann::json>& thread_keys, double goal);

/// The log lines of a summary entry ("    => ...").
std::string summary_text(const nlohmann::json& entry);

/// The log line of a row.
std::string row_text(const nlohmann::json& row);

}  // namespace sdf::peers
