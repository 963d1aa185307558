/// @file mpi_session.h
/// @brief This process's part in a distributed run: its rank, the other ranks' descriptions,
/// and what the root keeps between calls (the meshes it shares, the fields it sampled).
/// MPI-only part of sdf_distributed.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/mesh/triangle_mesh.h"
#include "core/sampling/sampler.h"
#include "harness/distributed/distributed.h"

namespace sdf::mpi {

/// This process's part in the run.
struct Session {
    bool started = false;   ///< MPI_Init was called here
    bool joined = false;    ///< MPI runs and this rank knows the others (join_ranks)
    /// Every rank runs the same code and calls sample_collectively (the Python module), so
    /// there is no workers' loop to end.
    bool collective = false;
    std::string started_by;  ///< collective: "sdf_lattices" or "another library"
    int rank = 0, size = 1;
    nlohmann::json self;    ///< rank, host, local_rank, local_size, threads, device, gpu
    nlohmann::json processes = nlohmann::json::array();  ///< root: every rank's `self`
    nlohmann::json fields = nlohmann::json::array();     ///< root: each distributed field
    std::map<std::string, TriangleMesh> meshes;          ///< root: by content SHA-256
    std::string mesh_sent;  ///< root: SHA-256 of the mesh the workers hold
    bool released = false;  ///< root: workers told to quit
    Distribution distribution = Distribution::LatticeSlabs;
    /// Root: the field the ranks sampled last, whose slabs the workers still hold for the
    /// parallel write (write_sampled_field); invalid once written or when another is sampled.
    struct HeldField {
        bool valid = false;
        Lattice lattice;
        std::vector<LatticeSlab> slabs;
        nlohmann::json record;             ///< the field's sampler.distributed
        const double* distance = nullptr;  ///< the field's storage (moving the field keeps it)
        size_t field_index = 0;            ///< its record in `fields`
    } held;
};

Session& session();

/// This rank's place among the ranks of a running MPI; the root collects every rank's
/// description (kTagHello). Collective.
void join_ranks();

/// This rank's sampler options: its GPU (the local rank modulo the devices, offset by the
/// configured device) and, for "all threads", its share of the host's cores.
SamplerOptions options_for_this_rank(SamplerOptions options);

/// Set by mpirun / mpiexec (Open MPI, MPICH's hydra) or srun (PMI, PMIx).
bool launched_by_mpi();

}  // namespace sdf::mpi
