/// @file slab_exchange.h
/// @brief One field sampled by every rank, each its slab (slab_plan.h), and gathered by the
/// root: what the root's sampler (root_sampler.cpp) and the collective path of the Python
/// module (collective.cpp) share. MPI-only part of sdf_distributed.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/sampling/sampler.h"
#include "harness/sampling/slab_plan.h"

namespace sdf::mpi {

/// Samples `slab` with `sampler`, bound to its mesh (nothing for an empty slab).
SampledField sample_part(const BoundSampler& sampler, const Lattice& lattice, const LatticeSlab& slab);

/// What a rank reports of its slab (the manifest's distributed.slabs[i]).
nlohmann::json describe_part(const SampledField& part, int rank, const std::string& host, const LatticeSlab& slab,
                             double wall_seconds);

/// Worker: its part to the root, per channel its primary points, then its secondary ones.
void send_part(const SampledField& part, const Lattice& lattice, const LatticeSlab& slab);

struct RankFailure {
    int rank;
    std::string host, error;
    bool setup = false;  ///< before sampling: the caller's arguments (collective sampling)
};

/// What the root gathers of one field: every rank's slab, described; the sampler's report,
/// every rank's merged in rank order (SamplerReport::merge: the counters summed, the details
/// the root's, or the first worker's when the root's slab is empty); and the ranks that
/// failed.
struct Gathered {
    nlohmann::json parts = nlohmann::json::array();
    SamplerReport sampler;
    std::vector<RankFailure> failures;
};

/// Root: every worker's answer, its status and, when it sampled its slab, the slab into
/// `field` (null: the root failed first; the answers are read and dropped). Every worker
/// answers, failed or not, so the exchange ends in step on every rank.
void receive_answers(Gathered& g, SampledField* field, const Lattice& lattice, const std::vector<LatticeSlab>& slabs);

/// Root: samples slab 0 (`sample_mine`) into `field` while the workers sample theirs, then
/// gathers their answers.
Gathered sample_and_gather(const std::function<SampledField(const LatticeSlab&)>& sample_mine, const Lattice& lattice,
                           const SlabPlan& plan, SampledField& field);

/// "distributed sampling of 11x9x13 failed on 1 of 2 ranks: rank 1 (host vm): ..."
std::string failure_message(const std::string& lattice, const std::vector<RankFailure>& failures);

/// The field's provenance: the gathered report (the whole lattice's counters), and as a
/// detail "distributed" (the slabs, per-rank seconds, the load balance), which it returns.
nlohmann::json finish_provenance(SampledField& field, const SamplerOptions& options, const SlabPlan& plan,
                                 const Gathered& gathered, double total_seconds, double sampling_seconds);

}  // namespace sdf::mpi
