/// @file sampler_table.h
/// @brief The one table of samplers: {backend, method, kernels (the first is the default),
/// factory, properties}. The factory (make_sampler), the options codec
/// (harness/config/sampler_spec), the tools' option checks and every message about backends,
/// methods and kernels read it; each row's kernel names are the backend's own table
/// (core/sampling/kernel_table.h), which its constructor parses with. What callers need to
/// know of a sampler (does it run on the GPU, its host bytes per streamed point, how the slab
/// planner estimates its cost) is a property of its row, never a comparison of names.
/// Adding a sampler is one row here plus its backend files.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/sampling/sampler.h"

namespace sdf {

/// How the slab planner of a distributed run (harness/sampling/slab_plan.h) estimates the
/// cost of a lattice plane.
enum class CostModel {
    PerPoint,   ///< every point costs the same (brute force: every triangle per point)
    BvhVisits,  ///< the BVH nodes a probe's search visits (near the surface costs more)
};

struct SamplerKind {
    const char* backend;                 ///< "cpu", "cuda"
    const char* method;                  ///< "brute_force", "bvh"
    std::vector<std::string> kernels;    ///< the first is the default
    std::unique_ptr<Sampler> (*make)(const SamplerOptions&);  ///< null: not in this build
    bool on_gpu;                         ///< needs a CUDA device (one per rank under mpirun)
    uint64_t stream_bytes_per_point;     ///< host bytes per point of a slab being sampled
    CostModel cost;                      ///< the slab planner's estimate
};

const std::vector<SamplerKind>& sampler_table();

/// The one place "auto" is resolved: "cuda" when this build has the CUDA backend and a GPU is
/// present, else "cpu"; any other name is returned unchanged.
std::string resolve_sampler_backend(const std::string& backend);

/// The backend names options accept: "auto" first, then the table's.
std::vector<std::string> sampler_backend_choices();

/// The backends and methods of the table, each once, in table order.
std::vector<std::string> sampler_backends();
std::vector<std::string> sampler_methods();

/// The row of (backend, method); throws naming the alternatives when there is none.
const SamplerKind& sampler_kind(const std::string& backend, const std::string& method);
/// The row of the options ("auto" resolved first).
const SamplerKind& sampler_kind(const SamplerOptions& options);

/// Checks options.kernel against its row ("" = the default is always fine); throws
/// "sampler.kernel: unknown cuda bvh kernel ...; expected ..." otherwise.
void check_sampler_kernel(const SamplerOptions& options);

/// Creates the sampler the options name ("auto" resolved); throws naming the known ones
/// otherwise, or why a known one cannot run here (no CUDA backend in this build, no GPU).
std::unique_ptr<Sampler> make_sampler(const SamplerOptions& options);

/// True when this build has the CUDA backend and a GPU is present.
bool cuda_backend_available();

/// How many devices the sampler make_sampler(options) makes drives: 1 on the CPU or with the
/// default `devices`, else the selection's visible devices (resolve_devices); what a point
/// query's split is decided over (plan_device_split, multi_device_sampler.h).
int sampler_device_count(const SamplerOptions& options);

}  // namespace sdf
