/// @file fault_injection.h
/// @brief The failure tests' hook (tests/distributed/mpi_runs.sh): the environment names a
/// rank that fails at one stage, so the failure paths run on a healthy machine.
///   SDF_MPI_FAIL_RANK=r   rank r fails
///   SDF_MPI_FAIL_STAGE    "sample" (unset), "write" (its part of the parallel write) or
///                         "open" (it cannot open the files of the parallel write, as on a node
///                         without the shared file system)
///   SDF_MPI_FAIL_MODE     "kill": it dies (SIGKILL) instead of throwing, as a crashed or
///                         OOM-killed process would
/// Nothing happens unless SDF_MPI_FAIL_RANK is set. MPI-only part of sdf_distributed.
#pragma once

#include <string>

namespace sdf::mpi {

/// Whether the tests ask rank `rank` to fail at `stage`.
bool failure_asked(int rank, const std::string& stage);

/// Throws (or dies, SDF_MPI_FAIL_MODE=kill) when failure_asked(rank, stage).
void maybe_inject_failure(int rank, const std::string& stage = "sample");

}  // namespace sdf::mpi
