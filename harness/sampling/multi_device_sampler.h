/// @file multi_device_sampler.h
/// @brief One process driving several GPUs (SamplerOptions::devices; issue 36): one bound
/// sampler per device, bound on its own host thread, and one host thread per device for each
/// call. A lattice slab is cut into z-slabs of about equal estimated cost (slab_plan.h, the
/// plan MPI uses) and a point list into contiguous pieces; every point is computed by one
/// device exactly as one device computes it alone (kernels/lattice/lattice_slab.h: a slab's
/// blocks start at the lattice's own integer coordinates), so the field is one device's bit
/// for bit. A job is split only where splitting can pay: the devices used get on average at
/// least SamplerOptions::min_points_per_device points (the split threshold; its default and why
/// in core/sampling/sampler_options.h and docs/distributed.md), and a lattice at least one
/// z-plane; a smaller job runs on the first device, or on fewer devices, and the report says
/// why (plan_device_split).
///
/// Report: the parts' SamplerReports merged (SamplerReport::merge) plus details "devices":
///   {"count" (requested), "used", "split", "min_points_per_device",
///    "why_not" (unsplit) | "why_fewer" (split over fewer than requested), "cost_estimate" (lattices),
///    "parts": [{"device": {index, name, pci_bus_id, ...}, "z_planes" | "rows", "points",
///               "seconds", "kernel_seconds", "upload_seconds", "download_seconds"}]}
/// Timings: kernel, upload and download are the largest part's (the devices run at once),
/// total the call's wall clock, pairs summed.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/sampling/sampler.h"

namespace sdf {

/// Rows [begin, begin + count) of a point list.
struct PointRange {
    int64_t begin = 0;
    int64_t count = 0;
};

/// How a job goes over the devices of a multi-device sampler: the decision and its reason.
struct DeviceSplit {
    int requested = 1;                 ///< devices the sampler drives
    int used = 1;                      ///< devices this job runs on: the first `used`
    int64_t points = 0;
    int64_t min_points_per_device = 0; ///< the split threshold it was decided with
    std::string why;                   ///< why fewer than requested are used ("" when all are)
    bool split() const { return used > 1; }
    /// {"count", "used", "split", "min_points_per_device", "why_not" | "why_fewer"}.
    nlohmann::json to_json() const;
};

/// The split of a job of `points` points over `devices` devices: at most one part a device,
/// each of at least `min_points_per_device` points (0 counts as 1) and, for a lattice
/// (`planes` >= 0 z-planes; -1 for a point list), at least one z-plane. A job below the
/// threshold runs on one device, with `why` saying so: "2 devices requested, 1 used:
/// 4194304 points, fewer than 2 x 8388608 (min_points_per_device: the fewest points a device
/// is given)".
DeviceSplit plan_device_split(int64_t points, int planes, int devices, int64_t min_points_per_device);

/// Cuts planes [slab.z_begin, slab.z_end) into `parts` contiguous slabs of about equal
/// `plane_cost` (indexed by the lattice's planes), each at least one plane; fewer parts when
/// the slab has fewer planes.
std::vector<LatticeSlab> split_slab(const std::vector<double>& plane_cost, const LatticeSlab& slab, int parts);

/// Cuts n rows into `parts` contiguous ranges of equal size (the first n % parts one longer).
std::vector<PointRange> split_points(int64_t n, int parts);

/// Where part `sub` of slab `slab` lies in the slab's compact storage: its primary points
/// (part 0) and secondary points (part 1), as StorageRanges relative to the slab's first point.
StorageRange sub_slab_storage(const Lattice& lattice, const LatticeSlab& slab, const LatticeSlab& sub, int part);

/// Makes the sampler of one device from options naming it (device = d, devices default).
using DeviceSamplerFactory = std::function<std::unique_ptr<Sampler>(const SamplerOptions&)>;
/// A device's description for the report (index, name, PCI bus id).
using DeviceDescriber = std::function<nlohmann::json(int device)>;

/// The sampler over `devices` (at least one): `make_one` is called once per device with
/// `options` naming that device; jobs are split by options.min_points_per_device.
std::unique_ptr<Sampler> make_multi_device_sampler(const SamplerOptions& options, std::vector<int> devices,
                                                   DeviceSamplerFactory make_one, DeviceDescriber describe);

}  // namespace sdf
