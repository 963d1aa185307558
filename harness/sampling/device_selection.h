/// @file device_selection.h
/// @brief Which CUDA devices a process, or an MPI rank, drives (SamplerOptions::device and
/// ::devices; docs/distributed.md, "What runs where"). Pure functions of the counts, so the
/// CPU tests check the mapping that the GPU runs use.
#pragma once

#include <string>
#include <vector>

#include "core/sampling/sampler_options.h"

namespace sdf {

/// The devices one process drives for `options` when `visible` CUDA devices are visible
/// (CUDA_VISIBLE_DEVICES already applied by the driver: Slurm's --gpus-per-task=1 leaves
/// one, device 0): the default selection is {options.device}; "all" is 0 .. visible - 1; a
/// list is itself. Throws std::invalid_argument naming the key ("sampler.devices",
/// "sampler.device") when a device is not visible or none is.
std::vector<int> resolve_devices(const SamplerOptions& options, int visible);

/// The options of MPI rank `local_rank` of the `local_size` ranks on its host (MPI's shared-
/// memory communicator), `visible` devices visible to it. Every rank is sent the root's
/// options, so the share is decided here, the same on every rank:
/// - the default selection: device (options.device + local_rank) % visible, one GPU per rank
///   while there are as many GPUs as ranks (several ranks share one when there are fewer);
/// - "all" or a list: the selection's devices are dealt to the host's ranks, the i-th to
///   rank i % local_size, so a rank may drive several GPUs (4 GPUs, 2 ranks: {0, 2}, {1, 3});
///   a rank left without one (more ranks than GPUs) shares one, i % count.
/// A rank's single device is written as `device` with the default selection. Options of
/// other backends, and hosts without a visible device, are returned unchanged.
SamplerOptions place_rank_on_devices(SamplerOptions options, int local_rank, int local_size, int visible);

/// "CUDA_VISIBLE_DEVICES=..." or "CUDA_VISIBLE_DEVICES unset", for messages.
std::string visible_devices_note();

}  // namespace sdf
