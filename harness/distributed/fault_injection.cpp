// The failure tests' hook (fault_injection.h).
#include "harness/distributed/fault_injection.h"

#include <csignal>
#include <cstdlib>
#include <stdexcept>

#include "harness/distributed/distributed.h"

namespace sdf {
namespace mpi {

bool failure_asked(int rank, const std::string& stage) {
    const char* target = std::getenv("SDF_MPI_FAIL_RANK");
    if (target == nullptr || std::atoi(target) != rank) return false;
    const char* wanted = std::getenv("SDF_MPI_FAIL_STAGE");
    return stage == (wanted != nullptr ? wanted : "sample");
}

void maybe_inject_failure(int rank, const std::string& stage) {
    if (!failure_asked(rank, stage)) return;
    const std::string target = std::getenv("SDF_MPI_FAIL_RANK");
    const char* mode = std::getenv("SDF_MPI_FAIL_MODE");
    if (mode != nullptr && std::string(mode) == "kill") std::raise(SIGKILL);
    if (stage == "sample") throw std::runtime_error("injected failure (SDF_MPI_FAIL_RANK=" + std::string(target) + ")");
    throw std::runtime_error("injected failure at the " + stage + " stage (SDF_MPI_FAIL_RANK=" + std::string(target) + ")");
}

}  // namespace mpi

void fail_here_if_asked() { mpi::maybe_inject_failure(distributed_rank()); }

}  // namespace sdf
