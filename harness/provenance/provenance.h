/// @file provenance.h
/// @brief Everything needed to say how a result was made, so that a number can be traced and
/// made again: git commit and dirty flag, build type and flags, CPU and GPU model, driver and
/// CUDA versions, time.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

namespace sdf {

struct GitState {
    std::string commit = "unknown";
    bool dirty = true;  ///< unknown counts as dirty: such a run never becomes a baseline
    /// "git", or where the tree has no .git (a copy sent to a GPU machine) the commit passed
    /// in: "SDF_SOURCE_COMMIT" (environment at run time, then the CMake variable at configure
    /// time); "none" when neither is known.
    std::string source = "none";
};

/// The commit of this build's source tree (git_state_of(SDF_SOURCE_DIR)).
GitState git_state();
/// The commit of the tree at `source_dir`: the commit passed in when there is one
/// (SDF_SOURCE_COMMIT, see GitState::source: a copy of the tree may hold a stale .git), else
/// git's.
GitState git_state_of(const std::string& source_dir);
std::string cpu_model();
/// Build type, compiler and flags baked in at configure time.
nlohmann::json build_info();
/// The GPU (name, driver, runtime) when the CUDA backend and a device are present, else null.
nlohmann::json gpu_info();
/// "2026-11-21T13:45:01Z"
std::string utc_timestamp();
/// "20261121T134501.123Z" (for run ids: UTC, milliseconds)
std::string compact_utc_timestamp();
/// The machine a result was measured on, from a provenance object (machine_and_build()):
/// {"cpu": model, "gpu": name or null, "cpu_target": -march, "cpu_kernels": the ISA level of
/// the dispatched CPU kernels, where recorded}. Timings are comparable only between equal kinds.
nlohmann::json machine_kind(const nlohmann::json& provenance);
/// The 1-, 5- and 15-minute load averages (/proc/loadavg), or null where unknown: timings
/// taken on a loaded machine are not comparable.
nlohmann::json load_average();
/// Host name, CPU model and hardware threads, GPU; build; git.
nlohmann::json machine_and_build();

}  // namespace sdf
