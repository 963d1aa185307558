#include "harness/resources/memory_budget.h"

#include "core/lattice/lattice_fitting.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

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

uint64_t parse_byte_size(const std::string& text, const std::string& what) {
    const auto fail = [&](const std::string& why) {
        return std::invalid_argument(what + ": " + why + ", got \"" + text +
                                     "\"; expected a positive size such as 8GiB, 512MiB or 1000000 (bytes)");
    };
    if (!text.empty() && text.front() == '-') throw fail("a negative size");
    size_t i = 0;
    while (i < text.size() && (std::isdigit(static_cast<unsigned char>(text[i])) || text[i] == '.')) ++i;
    const std::string number = text.substr(0, i);
    if (number.empty() || number.find_first_of("0123456789") == std::string::npos) throw fail("no number");
    if (number.find('.') != number.rfind('.')) throw fail("not a number");
    std::string unit = text.substr(i);
    if (!unit.empty() && unit.front() == ' ') unit.erase(0, 1);
    for (char& c : unit) c = char(std::tolower(static_cast<unsigned char>(c)));
    static const std::pair<const char*, double> units[] = {
        {"", 1.0},           {"b", 1.0},          {"k", 0x1p10},       {"kib", 0x1p10}, {"m", 0x1p20},
        {"mib", 0x1p20},     {"g", 0x1p30},       {"gib", 0x1p30},     {"t", 0x1p40},   {"tib", 0x1p40},
        {"kb", 1e3},         {"mb", 1e6},         {"gb", 1e9},         {"tb", 1e12}};
    double scale = 0;
    for (const auto& [name, factor] : units)
        if (unit == name) scale = factor;
    if (scale == 0) throw fail("unknown unit \"" + text.substr(i) + "\" (B, KiB, MiB, GiB, TiB, KB, MB, GB, TB)");
    const double bytes = std::strtod(number.c_str(), nullptr) * scale;
    if (!(bytes >= 1)) throw fail("not a positive size");
    if (!(bytes <= 0x1p62)) throw fail("beyond 2^62 bytes");
    return uint64_t(bytes);
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

void require_plan_fits_machine(uint64_t peak, uint64_t budget, const std::string& what) {
    const uint64_t available = host_memory_available();
    if (available == 0 || peak <= available) return;
    const uint64_t physical = host_memory_physical();
    throw std::runtime_error(what + ": the plan's estimated peak, " + format_bytes(peak) + " (budget " + format_bytes(budget) +
                             "), exceeds the " + format_bytes(available) + " of memory available to this process" +
                             (physical ? " (the machine has " + format_bytes(physical) + ")" : std::string()) +
                             "; give a budget of at most " + format_bytes(available) +
                             " (SDF_MEMORY_AVAILABLE overrides the figure, in bytes)");
}

std::string out_of_memory_message(const std::string& what, uint64_t bytes) {
    const uint64_t available = host_memory_available();
    return "out of memory while " + what + (bytes ? " (about " + format_bytes(bytes) + ")" : std::string()) + ": this process holds " +
           format_bytes(current_resident_bytes()) + " (peak " + format_bytes(peak_resident_bytes()) + "); " +
           (available ? format_bytes(available) + " available" : std::string("available memory unknown")) +
           ". Use a smaller lattice (or a smaller budget), or a machine with more memory";
}

std::string describe_memory_need(const MemoryNeed& need) {
    if (need.host_bytes == 0) return "not estimated";
    const uint64_t available = host_memory_available();
    std::string text = "about " + format_bytes(need.host_bytes) + " of host memory for " + need.what + "; " +
                       (available ? format_bytes(available) + " available" : "available memory unknown");
    if (available && need.host_bytes > available) text += " (the run would be refused)";
    return text;
}

MemoryNeed whole_lattice_sampling_need(const Lattice& lattice, const std::string& mesh) {
    const uint64_t points = uint64_t(lattice.num_points());
    const uint64_t most = (~uint64_t(0) - kBaseBytes) / kSamplingBytesPerPoint;
    MemoryNeed need;
    need.host_bytes = kBaseBytes + std::min(points, most) * kSamplingBytesPerPoint;
    need.what = "sampling " + mesh + " on " + lattice_notation(lattice) + " (" + std::to_string(points) + " points)";
    return need;
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
