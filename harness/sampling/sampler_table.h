/// @file sampler_table.h
/// @brief The one table of samplers: {backend, method, kernels (the first is the default),
/// factory}. The factory (make_sampler), the config parser (harness/config/sampler_spec), the
/// tools' option checks and every message about backends, methods and kernels read it;
/// each row's kernel names are the backend's own table (core/sampling/kernel_table.h), which
/// its constructor parses with. Adding a sampler is one row here plus its backend files.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/sampling/sampler.h"

namespace sdf {

struct SamplerKind {
    const char* backend;                 ///< "cpu", "cuda"
    const char* method;                  ///< "brute_force", "bvh"
    std::vector<std::string> kernels;    ///< the first is the default
    std::unique_ptr<Sampler> (*make)(const SamplerOptions&);  ///< null: not in this build
};

const std::vector<SamplerKind>& sampler_table();

/// The backends and methods of the table, each once, in table order.
std::vector<std::string> sampler_backends();
std::vector<std::string> sampler_methods();

/// The row of (backend, method); throws naming the alternatives when there is none.
const SamplerKind& sampler_kind(const std::string& backend, const std::string& method);

/// Checks options.kernel against its row ("" = the default is always fine); throws
/// "sampler.kernel: unknown cuda bvh kernel ...; expected ..." otherwise.
void check_sampler_kernel(const SamplerOptions& options);

/// Creates the sampler the options name; throws naming the known ones otherwise, or why a
/// known one cannot run here (no CUDA backend in this build, no GPU).
std::unique_ptr<Sampler> make_sampler(const SamplerOptions& options);

/// True when this build has the CUDA backend and a GPU is present.
bool cuda_backend_available();

}  // namespace sdf
