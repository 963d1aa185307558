#include "harness/resources/memory_budget.h"

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

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

uint64_t host_memory_available() {
    if (const char* env = std::getenv("SDF_MEMORY_AVAILABLE"); env && *env) {
        char* end = nullptr;
        const unsigned long long v = std::strtoull(env, &end, 10);
        if (end == env || *end != '\0')
            throw std::runtime_error(std::string("SDF_MEMORY_AVAILABLE: expected a number of bytes, got \"") + env + "\"");
        return v;
    }
    std::ifstream meminfo("/proc/meminfo");
    for (std::string line; std::getline(meminfo, line);) {
        std::istringstream fields(line);
        std::string name;
        uint64_t kib = 0;
        if (fields >> name >> kib && name == "MemAvailable:") return kib * 1024;
    }
    return 0;
}

std::string describe_memory_need(const MemoryNeed& need) {
    if (need.host_bytes == 0) return "not estimated";
    const uint64_t available = host_memory_available();
    std::string text = "about " + format_bytes(need.host_bytes) + " of host memory for " + need.what + "; " +
                       (available ? format_bytes(available) + " available" : "available memory unknown");
    if (available && need.host_bytes > available) text += " (the run would be refused)";
    return text;
}

void require_host_memory(const MemoryNeed& need, const std::string& where) {
    const uint64_t available = host_memory_available();
    if (need.host_bytes == 0 || available == 0 || need.host_bytes <= available) return;
    throw std::runtime_error((where.empty() ? "" : where + ": ") + need.what + " needs about " + format_bytes(need.host_bytes) +
                             " of host memory, and " + format_bytes(available) +
                             " is available; nothing was computed. Use a smaller lattice (or image), or a machine "
                             "with more memory (SDF_MEMORY_AVAILABLE overrides the figure, in bytes)");
}

}  // namespace sdf
