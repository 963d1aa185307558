/// @file multi_device_sampler.h
/// @brief One process driving several GPUs (SamplerOptions::devices; issue 36): one bound
/// sampler per device, bound on its own host thread, and one host thread per device for each
/// call. A lattice slab is cut into z-slabs of about equal estimated cost (slab_plan.h, the
/// plan MPI uses) and a point list into contiguous pieces; every point is computed by one
/// device exactly as one device computes it alone (kernels/lattice/lattice_slab.h: a slab's
/// blocks start at the lattice's own integer coordinates), so the field is one device's bit
/// for bit. A job too small to split (fewer than kMinPointsPerDevice points a device, or one
/// z-plane) runs on the first device, and the report says why.
///
/// Report: the parts' SamplerReports merged (SamplerReport::merge) plus details "devices":
///   {"count", "split", "why_not" (unsplit only), "cost_estimate" (lattices),
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

/// Fewest points a device is given: below this, a GPU's launch, transfer and thread start
/// cost more than the share of work it takes off the others (a 64^3 lattice is 262,144).
inline constexpr int64_t kMinPointsPerDevice = int64_t(1) << 18;

/// Rows [begin, begin + count) of a point list.
struct PointRange {
    int64_t begin = 0;
    int64_t count = 0;
};

/// How many parts `points` points go into over `devices` devices: at most one a device, each
/// at least `min_points`; 1 with `why_not` set when the job is not split.
int device_parts(int64_t points, int devices, int64_t min_points, std::string& why_not);

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
/// `options` naming that device. `min_points` is kMinPointsPerDevice but for tests.
std::unique_ptr<Sampler> make_multi_device_sampler(const SamplerOptions& options, std::vector<int> devices,
                                                   DeviceSamplerFactory make_one, DeviceDescriber describe,
                                                   int64_t min_points = kMinPointsPerDevice);

}  // namespace sdf
