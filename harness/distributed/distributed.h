/// @file distributed.h
/// @brief Distributed runs with MPI (docs/distributed.md): `mpirun -np N run-experiment CONFIG`.
///
/// Rank 0 (the root) runs the experiment as a single process would: it reads the config,
/// writes the run directory, the fields, the manifest and the cache. Each field it samples
/// is cut into one slab per rank (slab_plan.h); every rank samples its slab with the
/// configured sampler on its CPU threads or its GPU (the local rank picks the device) and
/// sends the points back; the root places them at their offsets, so the field, its files
/// and its cache entry are those of a single-process run, bit for bit. A sampling run's
/// field files are then written by every rank, each its own slab, with MPI-IO
/// (write_sampled_field). The other ranks
/// (workers) only serve these requests: they receive the mesh once, prepare it as the root
/// did, and sample. A rank that fails answers with its error; the root then fails the run
/// naming every failed rank and its host, and nothing is published (the run's staging
/// directory is removed, the cache is filled only by complete fields). A rank that dies is
/// reported by mpirun ("process rank 2 ... on node N exited on signal 9"), which ends every
/// rank.
///
/// The Python module runs the other way round: every rank runs the same script and calls
/// sample_collectively(), which returns the whole field on every rank (below).
///
/// Without MPI in the build, or when not started by mpirun, every function here describes
/// a single process: distributed_active() is false and nothing changes.
#pragma once

#include <functional>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "core/mesh/triangle_mesh.h"
#include "core/sampling/sampler.h"
#include "harness/io/field_file.h"

namespace sdf {

/// MPI for the life of main(): started when the build has MPI and this process was launched
/// by an MPI launcher (its environment says so), finished (workers released) at the end.
class DistributedScope {
public:
    DistributedScope(int& argc, char**& argv);
    ~DistributedScope();
    DistributedScope(const DistributedScope&) = delete;
    DistributedScope& operator=(const DistributedScope&) = delete;
};

/// How a distributed run shares its work: every sampled lattice cut into slabs over the ranks
/// (the default), or whole runs of a sweep per rank (run-experiment --distribute runs).
enum class Distribution { LatticeSlabs, Runs };
void set_distribution(Distribution d);
Distribution distribution();

/// True when MPI runs with more than one rank.
bool distributed_active();
int distributed_rank();  ///< 0 without MPI
int distributed_size();  ///< 1 without MPI

/// Every rank's `settings` (a JSON object: what its command line and environment chose)
/// compared with rank 0's before any work, so that ranks started with different options stop
/// instead of waiting for messages that never come. Collective: every rank calls it right
/// after DistributedScope. Where any key differs, every rank throws std::runtime_error naming
/// each differing key, rank 0's value and the ranks that have another (and theirs); the root
/// then ends the run without the workers' loop. Does nothing without a distributed run.
void require_same_settings_on_every_rank(const nlohmann::json& settings);

/// A worker's life (rank > 0): serve the root's sampling requests until it ends the run.
/// Returns the process exit code.
int serve_distributed_requests();

/// The root's sampler for fields: bound to a mesh, it splits every lattice over the ranks
/// (the workers prepare the mesh the root shared with them, share_mesh_with_workers); its
/// query() runs on the root alone. Without a distributed run: make_sampler(options).
std::unique_ptr<Sampler> make_field_sampler(const SamplerOptions& options);

/// Keeps the mesh as loaded (before preparation) for the workers, who prepare it the same
/// way; call before sampling it. Does nothing without a distributed run.
void share_mesh_with_workers(const TriangleMesh& mesh);

/// Writes `field`'s files at `header_path` as write_field does. When `field` is the one the
/// ranks of a distributed run have just sampled (they still hold their slabs), the root
/// creates the channel files at their final size under temporary names, every rank writes its
/// own slabs' bytes of every channel with MPI-IO at their offsets, and the root then renames
/// them into place and writes the header last; the bytes are write_field's. Otherwise the
/// root writes alone (write_field). Returns "mpi-io" or "root".
std::string write_sampled_field(const std::string& header_path, const SampledField& field,
                                const FieldWriteOptions& options);

/// For the manifest: ranks, hosts, local ranks, GPUs, threads, and per sampled field the
/// slabs, per-rank timings and load balance. Null without a distributed run.
nlohmann::json distributed_description();

/// Runs mode: the root's `text` on every rank (the root passes it; the others' argument is
/// ignored).
std::string broadcast_from_root(const std::string& text);
/// Runs mode: every rank's `mine`, in rank order, on the root; an empty array elsewhere.
nlohmann::json gather_to_root(const nlohmann::json& mine);
/// SDF_MPI_FAIL_RANK=r makes rank r fail (throw) here, or die with SDF_MPI_FAIL_MODE=kill:
/// the failure tests' hook (tests/distributed/mpi_runs.sh); SDF_MPI_FAIL_STAGE=write moves
/// the failure to the parallel write of the field files. Does nothing otherwise.
void fail_here_if_asked();
/// This rank: rank, host, local_rank, local_size, threads, GPU.
nlohmann::json this_process();

/// Whether this build can run distributed (MPI found by CMake).
bool distributed_build();

// ---- The collective entry (the Python module: every rank runs the same script) ------------
//
// Under `mpirun -np N python3 script.py` there is no root that drives and no workers that
// serve: every rank calls sample() with the same arguments. The root plans the slabs as
// above, every rank samples its own and returns, and every rank gets the whole field.

/// Starts MPI for a process in which every rank runs the same code: uses MPI when another
/// library (mpi4py) started it, else starts it (MPI_THREAD_SERIALIZED) when an MPI launcher's
/// environment is present. Collective: every rank calls it (describing the ranks is).
/// Returns who started MPI: "sdf_lattices", "another library", or "" (no MPI: one process).
std::string start_collective_distribution();
/// MPI_Finalize when start_collective_distribution() started MPI and it still runs (at exit).
void finish_collective_distribution();

/// Ends every rank (MPI_Abort) when this one runs distributed: a rank that gives up outside
/// a collective call (an uncaught Python exception) must not leave the others waiting for it.
void abort_distributed(int code);

/// What a rank samples: the lattice and the sampler, built from its caller's arguments.
struct SamplingRequest {
    Lattice lattice;
    SamplerOptions options;
};

/// Collective sampling: every rank calls it with the same mesh (same content SHA-256 and
/// prepared counts) and the same request, which `setup` builds on each rank (an exception
/// there is that rank's failure). Rank 0 plans the slabs (plan_slabs), every rank samples its
/// own, rank 0 gathers them and broadcasts the whole field: every rank returns the same
/// field, bit for bit the one make_sampler(options)->bind(mesh)->sample(lattice) gives, with
/// sampler.distributed recording the slabs, hosts and per-rank seconds. A failure on any rank
/// (setup, sampling, arguments that differ from rank 0's) makes every rank throw: the
/// failing ranks' own exception where every rank failed in setup with the same message
/// (a bad argument: its type is kept), else std::runtime_error naming each failed rank and
/// its host. Without a distributed run: setup(), then sample_once(*make_sampler(options), ...).
SampledField sample_collectively(const std::shared_ptr<const PreparedMesh>& mesh, const std::function<SamplingRequest()>& setup);

/// This process for the Python module's distributed(): mpi (the build has it), started_by
/// (see start_collective_distribution), rank, size, host, local rank and size, threads,
/// GPU, and on rank 0 of a distributed run every rank's description (processes).
nlohmann::json distributed_info();

}  // namespace sdf
