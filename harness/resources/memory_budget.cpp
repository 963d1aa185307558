#include "harness/resources/memory_budget.h"

#include "core/lattice/lattice_fitting.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

namespace sdf {

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
