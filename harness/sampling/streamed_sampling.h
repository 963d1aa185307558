/// @file streamed_sampling.h
/// @brief Sampling a lattice larger than memory (issue 14, `sdf-sample`): z-slab by z-slab
/// (kernels/lattice/lattice_slab.h), each slab written at its storage offsets into the
/// channel files of the project's field file (harness/io/field_file.h) while the next one is
/// sampled, so that the host holds two slabs at a time whatever the lattice's size.
///
/// A slab's samples are the whole lattice's, bit for bit, and each slab's points go to the
/// same byte offsets the in-memory writer gives them (the offsets of harness/distributed's
/// MPI-IO write, with pwrite), so the channel files equal write_field()'s byte for byte.
/// Every target is checked before sampling. Channel files are written under temporary names
/// beside their final ones and renamed at the end to names the old header does not use; the
/// header's rename then replaces the old field in one step (harness/io/field_replacement.h):
/// the header describes the old field whole or the new one whole at every instant, and
/// nothing is overwritten without Overwrite::Allow.
///
/// Memory: the plan takes the budget, subtracts the fixed part (what the process holds
/// before sampling, measured, plus the BVH and the write buffers, estimated) and divides the
/// rest by two slabs' bytes per z-plane (StreamOptions::bytes_per_point); a budget that cannot
/// hold two single-plane slabs is refused with the figure it would need.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/mesh/prepared_mesh.h"
#include "core/sampling/narrow_band.h"
#include "core/sampling/sampler.h"
#include "harness/io/field_file.h"

namespace sdf {

/// Host bytes per lattice point of a slab being sampled on the CPU: the field's arrays
/// (distance, gradient, closest triangle: 36 bytes) and a sampler's results, as measured for
/// kSamplingBytesPerPoint (harness/resources/memory_budget.h).
constexpr uint64_t kStreamBytesPerPoint = 64;
/// The same for the CUDA samplers, estimated (not measured): the field's 36 bytes and the
/// host copy of a GPU piece's results (distance, gradient, triangle, output index: 44 bytes),
/// which may be as large as the slab, with headroom.
constexpr uint64_t kStreamBytesPerPointCuda = 96;
/// Points converted and written per pwrite (bounds the conversion buffer: 24 bytes a point).
constexpr int64_t kStreamWriteChunk = int64_t(1) << 18;
/// Threads that convert and write a slab's chunks (each with its own buffer).
constexpr int kStreamWriteThreads = 4;
/// Host bytes of the BVH and the winding sign per triangle (generous: nodes, packed float and
/// double triangles, moments).
constexpr uint64_t kStreamBvhBytesPerTriangle = 512;

struct StreamOptions {
    std::string header_path;      ///< NAME.json; the channels are NAME.<channel>.raw beside it
    FieldWriteOptions write;      ///< dtype, overwrite, closest_triangle channel
    bool gradient = true;         ///< write the gradient channel
    uint64_t memory_budget = 0;   ///< bytes the whole process may hold (peak resident)
    uint64_t fixed_bytes = 0;     ///< the part that does not grow with the lattice (estimate_fixed_bytes)
    uint64_t bytes_per_point = kStreamBytesPerPoint;  ///< host bytes per point of a slab being sampled
    int max_planes_per_slab = 0;  ///< > 0: at most this many z-planes per slab (tests)
    bool progress = true;         ///< one line per slab on stderr
    /// Also a narrow-band OpenVDB file (harness/io/volume_grids.h: VdbNarrowBandBuilder) built
    /// as the slabs arrive: points with |d| < vdb_band (world units) active; "" = none.
    std::string vdb_path;
    double vdb_band = 0;
};

/// What the process holds before sampling: its resident memory now (libraries, the mesh)
/// plus the BVH and winding sign of `mesh` and the write buffers, estimated.
uint64_t estimate_fixed_bytes(const PreparedMesh& mesh);

struct StreamPlan {
    Lattice lattice;
    int64_t points = 0;
    int planes_per_slab = 0;
    int slabs = 0;
    uint64_t slab_bytes = 0;       ///< host bytes of the largest slab while sampled
    uint64_t bytes_per_point = 0;  ///< of a slab while sampled
    uint64_t memory_budget = 0, fixed_bytes = 0;
    uint64_t peak_estimate = 0;    ///< fixed + two slabs
    uint64_t output_bytes = 0;     ///< of the channel files
    std::vector<FieldChannelFile> channels;
    std::vector<LatticeSlab> slab_list() const;
    nlohmann::json to_json() const;
    /// Several lines for --dry-run and the log: lattice, slabs, memory, output.
    std::string describe() const;
};

/// The plan for `lattice` under `options`; throws std::runtime_error when the budget cannot
/// hold two one-plane slabs (naming the budget, the fixed part and the least budget that works).
StreamPlan plan_streamed_sampling(const Lattice& lattice, const StreamOptions& options);

struct StreamResult {
    StreamPlan plan;
    SampledField header;  ///< lattice and provenance as written to the header; no arrays
    double seconds = 0;   ///< end to end: sampling, writing, fsync, renames
    double write_wait_seconds = 0;  ///< time the sampler waited for the writer
    uint64_t peak_resident_bytes = 0;
    NarrowBandCounts band;
    int64_t vdb_active_points = 0;  ///< of the .vdb output, when asked for
};

/// Samples `lattice` slab by slab with `sampler` (bound to its mesh) and writes the field file of
/// options.header_path. `mesh_provenance` becomes the header's "mesh". With
/// options.band_width > 0 in the sampler, each slab is banded (apply_narrow_band, which leaves
/// a sampler's own band alone). Refuses existing targets first unless overwriting, and a band
/// the output's dtype cannot hold (require_representable_band).
StreamResult sample_streamed(const BoundSampler& sampler, const SamplerOptions& sampler_options, const Lattice& lattice,
                             const StreamOptions& options, const MeshProvenance& mesh_provenance);

}  // namespace sdf
