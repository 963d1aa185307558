/// @file kernel_table.h
/// @brief One table per sampler naming its kernels: the backend's constructor parses its
/// option with it, and the sampler table (harness/sampling/sampler_table.h) lists the same
/// array in configs, tools and error messages. The first entry is the sampler's default.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/quoted_alternatives.h"

namespace sdf {

template <typename Kernel>
struct NamedKernel {
    const char* name;
    Kernel kernel;
};

template <typename Kernel, size_t N>
std::vector<std::string> kernel_names(const NamedKernel<Kernel> (&table)[N]) {
    std::vector<std::string> names;
    for (const NamedKernel<Kernel>& k : table) names.emplace_back(k.name);
    return names;
}

/// The kernel `name` names ("" = the default, the table's first entry); throws naming the
/// sampler ("CPU BVH", ...) and the alternatives otherwise.
template <typename Kernel, size_t N>
Kernel kernel_from_name(const NamedKernel<Kernel> (&table)[N], const std::string& name, const std::string& sampler) {
    if (name.empty()) return table[0].kernel;
    for (const NamedKernel<Kernel>& k : table)
        if (name == k.name) return k.kernel;
    throw std::invalid_argument("sampler.kernel: unknown " + sampler + " kernel '" + name + "'; expected " +
                                quoted_alternatives(kernel_names(table)));
}

template <typename Kernel, size_t N>
const char* kernel_name(const NamedKernel<Kernel> (&table)[N], Kernel kernel) {
    for (const NamedKernel<Kernel>& k : table)
        if (k.kernel == kernel) return k.name;
    throw std::logic_error("kernel without a name in its sampler's kernel table");
}

}  // namespace sdf
