#include "core/host_memory.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <utility>

#include <sys/mman.h>
#include <sys/resource.h>
#include <unistd.h>

namespace sdf {

std::string format_bytes(uint64_t bytes) {
    static const char* const units[] = {"B", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
    double v = double(bytes);
    int u = 0;
    while (v >= 1024 && u < 6) {
        v /= 1024;
        ++u;
    }
    char text[32];
    std::snprintf(text, sizeof text, u == 0 ? "%.0f %s" : "%.3g %s", v, units[u]);
    return text;
}

uint64_t peak_resident_bytes() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return uint64_t(usage.ru_maxrss) * 1024;  // kilobytes on Linux
}

uint64_t current_resident_bytes() {
    std::ifstream statm("/proc/self/statm");
    uint64_t size = 0, resident = 0;
    if (!(statm >> size >> resident)) return 0;
    return resident * uint64_t(sysconf(_SC_PAGESIZE));
}

namespace {

/// The first number in the file at `path`; 0 when it is missing or not a number ("max").
uint64_t number_in(const char* path) {
    std::ifstream in(path);
    uint64_t v = 0;
    return in >> v ? v : 0;
}

/// What this process's memory limits leave: the cgroup's (v2, else v1) limit less its usage,
/// and the address-space limit (ulimit -v) less the address space in use; ~0 when unlimited.
uint64_t memory_left_by_limits() {
    uint64_t left = ~uint64_t(0);
    for (const auto& [limit_file, usage_file] : {std::pair{"/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory.current"},
                                                 std::pair{"/sys/fs/cgroup/memory/memory.limit_in_bytes",
                                                           "/sys/fs/cgroup/memory/memory.usage_in_bytes"}}) {
        const uint64_t limit = number_in(limit_file);
        if (limit == 0 || limit >= (uint64_t(1) << 60)) continue;  // none, "max", or v1's "unlimited"
        const uint64_t used = number_in(usage_file);
        left = std::min(left, limit > used ? limit - used : 0);
    }
    rlimit as{};
    if (getrlimit(RLIMIT_AS, &as) == 0 && as.rlim_cur != RLIM_INFINITY) {
        std::ifstream statm("/proc/self/statm");
        uint64_t pages = 0;
        statm >> pages;
        const uint64_t used = pages * uint64_t(sysconf(_SC_PAGESIZE));
        left = std::min<uint64_t>(left, as.rlim_cur > used ? as.rlim_cur - used : 0);
    }
    return left;
}

}  // namespace

uint64_t host_memory_available() {
    if (const char* env = std::getenv("SDF_MEMORY_AVAILABLE"); env && *env) {
        char* end = nullptr;
        const unsigned long long v = std::strtoull(env, &end, 10);
        if (end == env || *end != '\0')
            throw std::runtime_error(std::string("SDF_MEMORY_AVAILABLE: expected a number of bytes, got \"") + env + "\"");
        return v;
    }
    uint64_t available = 0;
    std::ifstream meminfo("/proc/meminfo");
    for (std::string line; std::getline(meminfo, line);) {
        std::istringstream fields(line);
        std::string name;
        uint64_t kib = 0;
        if (fields >> name >> kib && name == "MemAvailable:") available = kib * 1024;
    }
    const uint64_t limited = memory_left_by_limits();
    return available == 0 ? (limited == ~uint64_t(0) ? 0 : limited) : std::min(available, limited);
}

uint64_t host_memory_physical() {
    const long pages = sysconf(_SC_PHYS_PAGES), size = sysconf(_SC_PAGESIZE);
    return pages > 0 && size > 0 ? uint64_t(pages) * uint64_t(size) : 0;
}

void require_host_bytes(uint64_t bytes, const std::string& what) {
    const uint64_t available = host_memory_available();
    if (available == 0 || bytes <= available) return;
    const uint64_t physical = host_memory_physical();
    throw std::runtime_error(what + " needs " + format_bytes(bytes) + " of host memory, more than the " +
                             format_bytes(available) + " available to this process" +
                             (physical ? " (the machine has " + format_bytes(physical) + ")" : std::string()) +
                             " (SDF_MEMORY_AVAILABLE overrides the figure, in bytes)");
}

void advise_huge_pages(void* data, uint64_t bytes) {
#if defined(MADV_HUGEPAGE)
    constexpr uint64_t kHugePage = uint64_t(2) << 20;
    const uint64_t begin = (uint64_t(reinterpret_cast<uintptr_t>(data)) + kHugePage - 1) / kHugePage * kHugePage;
    const uint64_t end = (uint64_t(reinterpret_cast<uintptr_t>(data)) + bytes) / kHugePage * kHugePage;
    if (end > begin) madvise(reinterpret_cast<void*>(uintptr_t(begin)), size_t(end - begin), MADV_HUGEPAGE);
#else
    (void)data;
    (void)bytes;
#endif
}

}  // namespace sdf
