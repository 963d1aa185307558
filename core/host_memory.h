/// @file host_memory.h
/// @brief This process's host memory: what it holds, what a new allocation can get, and sizes
/// as text. Below every layer that allocates by the lattice or the band, so that a size is
/// checked against the machine before it is allocated (harness/resources/memory_budget.h
/// builds the runs' memory plans on it).
#pragma once

#include <cstdint>
#include <string>

namespace sdf {

/// "1.5 GiB", "512 MiB", "12 KiB", "300 B".
std::string format_bytes(uint64_t bytes);

/// The peak resident memory of this process so far (getrusage), in bytes.
uint64_t peak_resident_bytes();
/// The resident memory of this process now (/proc/self/statm), in bytes; 0 when unknown.
uint64_t current_resident_bytes();

/// Host memory a new allocation can get: $SDF_MEMORY_AVAILABLE (bytes; for tests and to
/// leave room for other work), else MemAvailable of /proc/meminfo, lowered to what this
/// process's limits leave (a cgroup's memory limit, `ulimit -v`); 0 when unknown.
uint64_t host_memory_available();
/// The machine's physical memory (sysconf); 0 when unknown.
uint64_t host_memory_physical();

/// Refuses (std::runtime_error: `what` needs `bytes`, the memory available and the
/// machine's) an allocation of `bytes` beyond host_memory_available(); lets it through when
/// the figure is unknown.
void require_host_bytes(uint64_t bytes, const std::string& what);

/// Asks Linux for transparent huge pages (madvise) on the 2 MiB pages wholly inside
/// [data, data + bytes), before their first touch: a large buffer filled on every core then
/// faults one page in 512 (DefaultInitVector does the same for its own arrays). Advice only:
/// refused or ignored, the pages stay small.
void advise_huge_pages(void* data, uint64_t bytes);

}  // namespace sdf
