/// @file memory_budget.h
/// @brief What a run will need in host memory, estimated before anything is allocated, and a
/// refusal with the figures when the machine does not have it (instead of std::bad_alloc, or
/// the kernel's OOM killer, after minutes of sampling).
///
/// Estimates are affine in the points a step holds at once: a fixed part (libraries, the
/// mesh, threads) plus bytes per lattice point, with constants measured as peak resident
/// memory of the tools at two sizes (docs/harness.md, "Memory"). They are meant to be
/// generous, not exact: a run that fits by a small margin is let through, a run several
/// times too large is refused up front with what it needs and what is available. GPU memory
/// is not estimated: the CUDA samplers cut lattices into pieces sized to free device memory.
#pragma once

#include <cstdint>
#include <string>

#include "core/host_memory.h"  // format_bytes, host_memory_available, ...
#include "kernels/lattice/lattice.h"

namespace sdf {

struct MemoryNeed {
    uint64_t host_bytes = 0;  ///< 0: not estimated
    std::string what;         ///< the step that needs it, e.g. "sampling cc 80x80x80 (512,000 points)"
};

/// Measured peak resident bytes per lattice point (sphere mesh, CPU BVH, CC 48^3 and 96^3),
/// rounded up with headroom: a sampling step holds the field (distance, gradient, closest
/// triangle in double/int32) and the sampler's float results; a reconstruction step also
/// holds the reconstructions' coefficient arrays and derivative fields.
constexpr uint64_t kSamplingBytesPerPoint = 64;
constexpr uint64_t kReconstructionBytesPerPoint = 256;
/// The fixed part: libraries, thread stacks, a mesh of up to a few 100k triangles and its BVH.
constexpr uint64_t kBaseBytes = 512ull << 20;


/// A size as users write it: a positive number with an optional unit, B, KiB, MiB, GiB, TiB
/// (powers of 1024; K, M, G, T mean the same) or KB, MB, GB, TB (powers of 1000), any case,
/// with or without a space: "8GiB", "256 MiB", "1.5G", "1000000". Throws
/// std::invalid_argument naming `what`, the text and what was expected, for anything else:
/// no number, a negative, zero or non-finite one, an unknown unit, or a size beyond 2^62 bytes.
uint64_t parse_byte_size(const std::string& text, const std::string& what);


/// Refuses (std::runtime_error naming `what`, the peak, the budget, the memory available and
/// the machine's) a memory plan whose estimated peak exceeds host_memory_available(): a
/// budget beyond the machine is not trusted.
void require_plan_fits_machine(uint64_t peak, uint64_t budget, const std::string& what);

/// The message for a std::bad_alloc caught while doing `what` ("sampling MESH on LATTICE"):
/// `what`, the size being allocated when known (bytes > 0), this process's resident memory and
/// the memory available.
std::string out_of_memory_message(const std::string& what, uint64_t bytes);

/// "about 1.2 GiB of host memory for sampling cc ...; 20 GiB available" (or "unknown").
std::string describe_memory_need(const MemoryNeed& need);

/// What sampling all of `lattice` at once needs (the module's sample(), as run-experiment's
/// plan counts it): kBaseBytes plus kSamplingBytesPerPoint a point, saturating.
MemoryNeed whole_lattice_sampling_need(const Lattice& lattice, const std::string& mesh);

/// Throws std::runtime_error naming `where` (when not empty), the step, what it needs and what is available,
/// when the need is known and exceeds what is available.
void require_host_memory(const MemoryNeed& need, const std::string& where);

}  // namespace sdf
