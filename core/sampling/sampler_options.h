/// @file sampler_options.h
/// @brief What a sampler is asked to do (SamplerOptions), with the one table of its fields.
///
/// The defaults below are the defaults of every config, tool and Python call (docs/harness.md,
/// "Defaults"): the exact BVH search on the backend "auto" (cuda when this build has the CUDA
/// backend and a GPU is present, else cpu; resolved once, by resolve_sampler_backend in
/// harness/sampling/sampler_table.h). Brute force runs only where it is named.
///
/// for_each_sampler_option() visits every field with its name and role. The JSON codec
/// (harness/config/sampler_spec.h: configs, the tools' options, the MPI wire, the Python
/// module's keywords) and the field cache's key (harness/cache/field_cache.h) are generated
/// from it, so a new option is read, written and keyed once it has its row; the codec
/// refuses to compile while SamplerOptions has a field the table does not visit.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "core/sampling/sampled_field.h"
#include "core/winding/sign_mode.h"
#include "kernels/lattice/sampling_grid.h"

namespace sdf {

/// Where a GPU sampler's BVH is built (SamplerOptions::bvh_build).
enum class BvhBuildSite { Auto, Host, Device };

/// The GPUs one process drives (SamplerOptions::devices; docs/distributed.md): by default the
/// one of SamplerOptions::device, as before; "all" every visible device; or these ordinals.
/// Several devices split a lattice into z-slabs and a point list into pieces, one host thread
/// and one bound sampler per device (harness/sampling/multi_device_sampler.h); every point's
/// result is the one device's, bit for bit.
struct DeviceSelection {
    bool all = false;
    std::vector<int> list;  ///< empty (and not all): the one SamplerOptions::device
    bool is_default() const { return !all && list.empty(); }
    bool operator==(const DeviceSelection& o) const { return all == o.all && list == o.list; }
};

/// SamplerOptions::min_points_per_device's default, 2^23. Measured on two H200s (docs/
/// distributed.md): 4.19M query points (2.1M a device) took longer on two GPUs than on one
/// (0.078 s against 0.058 s), a CC 512^3 lattice (67M points a device) half the kernel time
/// (0.117 s against 0.216 s); 2^23 lies between, with a factor 4 of margin on the loss.
inline constexpr int64_t kDefaultMinPointsPerDevice = int64_t(1) << 23;

struct SamplerOptions {
    std::string backend = "auto";  ///< "auto", or a backend of the sampler table ("cpu", "cuda")
    std::string method = "bvh";    ///< a method of the sampler table ("bvh", "brute_force")
    std::string kernel;            ///< backend-specific variant; empty = the row's default
    Precision precision = Precision::Float;
    /// How the sign is decided (core/winding/sign_mode.h); auto is resolved per mesh by the
    /// sampler from the mesh's report (core/sampling/sampler_sign.h).
    SignMode sign = SignMode::Auto;
    int threads = 0;               ///< CPU threads; 0 = all
    BccStrategy bcc_strategy = BccStrategy::TwoGrids;
    bool progress = true;
    int device = 0;                ///< CUDA device ordinal (with the default `devices`)
    DeviceSelection devices;       ///< several GPUs in this process ("all", a list); default: `device`
    // GPU work sizes; 0 = chosen from the device's memory and multiprocessor count.
    int64_t max_points_per_piece = 0;  ///< lattice points per GPU piece (memory split)
    int max_triangles_per_chunk = 0;   ///< triangles resident on the GPU at a time
    int points_per_thread = 0;         ///< tuned kernel: points per thread (1, 2, 4, 8)
    /// Narrow band (issue 14): when > 0, only points with |d| <= band_width get exact values;
    /// every other point gets distance +-band_width with its correct sign, gradient (0,0,0)
    /// and closest_triangle kOutsideBandTriangle (core/sampling/sampled_field.h). The result
    /// is a function of the exact field alone, so it is the same for every sampler and split.
    double band_width = 0;
    /// Where the CUDA BVH sampler builds its BVH (docs/bvh.md, "Build on the GPU"): auto =
    /// on the device where that gives the same field as the host build (pseudonormal sign),
    /// else on the host; host and device force one. The CPU samplers always build on the host.
    BvhBuildSite bvh_build = BvhBuildSite::Auto;
    /// Several devices (`devices`): the fewest points each device must get before a lattice
    /// or point list is split over them; a smaller job runs on the first device and the
    /// report says why (harness/sampling/multi_device_sampler.h; docs/distributed.md, "When a
    /// job is split"). 0 or 1 splits whatever can be split (tests).
    int64_t min_points_per_device = kDefaultMinPointsPerDevice;
};

/// Whether a field decides the sampled values.
enum class OptionRole {
    Result,     ///< changes the field: part of the field cache key
    Execution,  ///< where and how fast only (every backend computes the same field): not keyed
};

/// What values a field takes; the codec validates each kind once.
enum class OptionDomain {
    Backend,          ///< "auto" or a backend of the sampler table
    Method,           ///< a method of the sampler table
    Kernel,           ///< "" or a kernel of the (backend, method) row
    Named,            ///< an enum, read and written by its name
    Count,            ///< an integer >= 0 (0 = automatic / all)
    PointsPerThread,  ///< 0, 1, 2, 4 or 8
    Flag,             ///< true or false
    Width,            ///< a finite length >= 0 in mesh units
    Devices,          ///< "all", or a list of distinct device ordinals ([] = the one `device`)
};

struct OptionField {
    const char* name;      ///< the JSON key (configs, wire, Python keyword)
    OptionRole role;
    OptionDomain domain;
    const char* expected;  ///< for messages and help texts: "a thread count (0 = all cores)"
};

/// The number of rows below; the codec checks it against the struct's field count.
inline constexpr std::size_t kSamplerOptionFields = 16;

/// Calls f(OptionField, member) for every field of `o`, in the order above. `O` is
/// SamplerOptions or const SamplerOptions.
template <class O, class F>
void for_each_sampler_option(O& o, F&& f) {
    using R = OptionRole;
    using D = OptionDomain;
    f(OptionField{"backend", R::Execution, D::Backend, "a backend"}, o.backend);
    f(OptionField{"method", R::Result, D::Method, "a method"}, o.method);
    f(OptionField{"kernel", R::Result, D::Kernel, "a kernel name"}, o.kernel);
    f(OptionField{"precision", R::Result, D::Named, "a precision"}, o.precision);
    f(OptionField{"sign", R::Result, D::Named, "a sign mode"}, o.sign);
    f(OptionField{"threads", R::Execution, D::Count, "a thread count (0 = all cores)"}, o.threads);
    f(OptionField{"bcc_strategy", R::Result, D::Named, "a BCC strategy"}, o.bcc_strategy);
    f(OptionField{"progress", R::Execution, D::Flag, "true or false"}, o.progress);
    f(OptionField{"device", R::Execution, D::Count, "a CUDA device ordinal"}, o.device);
    f(OptionField{"devices", R::Execution, D::Devices, "\"all\" or a list of distinct CUDA device ordinals such as [0, 1]"},
      o.devices);
    f(OptionField{"max_points_per_piece", R::Execution, D::Count, "a point count (0 = automatic)"},
      o.max_points_per_piece);
    f(OptionField{"max_triangles_per_chunk", R::Execution, D::Count, "a triangle count (0 = automatic)"},
      o.max_triangles_per_chunk);
    f(OptionField{"points_per_thread", R::Execution, D::PointsPerThread, "1, 2, 4 or 8 (0 = automatic)"},
      o.points_per_thread);
    f(OptionField{"band_width", R::Result, D::Width, "a band width in mesh units (0 = no band)"}, o.band_width);
    f(OptionField{"bvh_build", R::Execution, D::Named, "where the GPU BVH is built"}, o.bvh_build);
    f(OptionField{"min_points_per_device", R::Execution, D::Count,
                  "a point count: the fewest points a device gets before a job is split over several"},
      o.min_points_per_device);
}

/// Names of the enums a sampler option takes (the first is the default of a new struct).
struct NamedPrecision {
    const char* name;
    Precision value;
};
inline constexpr NamedPrecision kPrecisions[] = {{"float", Precision::Float}, {"double", Precision::Double}};

struct NamedBccStrategy {
    const char* name;
    BccStrategy value;
};
inline constexpr NamedBccStrategy kBccStrategies[] = {{"two_grids", BccStrategy::TwoGrids},
                                                      {"double_resolution", BccStrategy::DoubleResolution}};

struct NamedBvhBuildSite {
    const char* name;
    BvhBuildSite value;
};
inline constexpr NamedBvhBuildSite kBvhBuildSites[] = {
    {"auto", BvhBuildSite::Auto}, {"host", BvhBuildSite::Host}, {"device", BvhBuildSite::Device}};

/// Names a BVH build site as in configs ("auto" / "host" / "device").
inline const char* bvh_build_site_name(BvhBuildSite s) {
    for (const NamedBvhBuildSite& b : kBvhBuildSites)
        if (b.value == s) return b.name;
    return "auto";
}

/// Names a BCC strategy as in configs ("two_grids" / "double_resolution").
const char* bcc_strategy_name(BccStrategy s);

}  // namespace sdf
