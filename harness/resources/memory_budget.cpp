#include "harness/resources/memory_budget.h"

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
