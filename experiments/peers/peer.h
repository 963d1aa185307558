/// @file peer.h
/// @brief The one interface of every method the "peers" experiment times: our samplers
/// (ours_peer.cpp: CPU brute force and BVH, CUDA brute force and BVH) and the peer libraries
/// (one adapter file each). The same points go in, distances (signed where the method signs
/// them), the sign it used and timings come out; the experiment runs every adapter through
/// one timing loop (repetitions, medians, CPU time, the check). The methods are one table
/// (method_table(), peer_registry.cpp): name, factory, where and on what it runs, exactness,
/// sign. A peer's file is built only when its Debian package (or, for FCPW and cuBQL, its
/// source snapshot in SDF_PEERS_DIR) is present (experiments/peers/CMakeLists.txt); its
/// factory then says why not.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/mesh/prepared_mesh.h"
#include "core/sampling/sampler_options.h"
#include "core/winding/sign_mode.h"
#include "kernels/lattice/lattice.h"

namespace sdf::peers {

/// Which sign a row's distances carry. Ours: the pseudonormal or the winding number's side;
/// peers: none, or their own rule (MethodKind::sign_method). `Mode` is a table row's only:
/// our sampler's sign mode, resolved per mesh ("auto") into Pseudonormal or Winding.
enum class SignKind { Pseudonormal, Winding, None, Own, Mode };
struct NamedSignKind {
    SignKind kind;
    const char* name;  ///< the rows' "sign"
};
inline constexpr NamedSignKind kSignKinds[] = {{SignKind::Pseudonormal, "pseudonormal"},
                                               {SignKind::Winding, "winding"},
                                               {SignKind::None, "none"},
                                               {SignKind::Own, "own"},
                                               {SignKind::Mode, "sign mode (pseudonormal or winding)"}};
const char* sign_kind_name(SignKind kind);

/// What one run samples.
struct PeerInput {
    std::shared_ptr<const PreparedMesh> mesh;
    /// Set when `points` are this lattice's points in storage order (lattice methods such as
    /// OpenVDB need it; our samplers then sample the lattice); null for point sets and subsets.
    const Lattice* lattice = nullptr;
    const std::vector<Vec3d>* points = nullptr;
    /// > 0: a narrow-band case (Inputs::Bands): the level set of half-width `band_width` (mesh
    /// units) on `lattice` (CC), the method's own active voxels out; `points` is null.
    double band_width = 0;
    int threads = 1;          ///< resolved (>= 1); GPU methods ignore it
    SignMode our_sign = SignMode::Auto;  ///< our samplers' sign in this case (peers ignore it)
};

/// What one run of a method returns; the timing loop adds repetitions, medians and the check.
struct PeerResult {
    std::vector<double> distance;   ///< one per point; signed (negative inside) unless sign is None
    SignKind sign = SignKind::None; ///< never Mode: ours say which the mode resolved to
    std::string sign_method;        ///< ours: the mode's reason; peers: empty (their table row says it)
    std::vector<uint8_t> in_band;   ///< narrow-band peers: 1 where the value was computed; empty = everywhere
    /// Band cases: the world position of every active voxel (`distance` holds their values);
    /// the loop checks them against the exact field there.
    std::vector<Vec3d> band_points;
    double build_seconds = 0;       ///< acceleration structure (BVH, tree, grid set-up, our build-once object)
    double query_seconds = 0;       ///< the distance queries (and signs) themselves
    double end_to_end_seconds = -1; ///< GPU methods: the query with the points' and results' transfers; < 0: none
    int threads = 1;                ///< threads the method actually used
    double cpu_seconds = -1;        ///< CPU time of build + query over all threads, if the adapter measures it (else the loop does)
    double build_cpu_seconds = 0;   ///< the build's part of cpu_seconds, where known (a strided row scales only the rest)
    std::string notes;              ///< what the row's times and reference mean (our rows)
    nlohmann::json details = nlohmann::json::object();  ///< band width, sign method, split times
    bool is_signed() const { return sign != SignKind::None; }
};

class PeerAdapter {
public:
    virtual ~PeerAdapter() = default;
    /// The library's version string ("" for ours: the run's provenance names our build).
    virtual std::string version() const = 0;
    /// Samples input.points with input.threads threads (GPU methods ignore it).
    virtual PeerResult run(const PeerInput& input) = 0;
};

/// Options the experiment passes to the factories that take them.
struct PeerOptions {
    double openvdb_band_voxels = 3.0;  ///< OpenVDB narrow band half-width, in voxels (each side)
    double band_voxels = 3.0;          ///< band cases: every method's half-width W, in voxels
    std::string python;                ///< interpreter with open3d; empty = look for one
    SignMode exact_sign = SignMode::Auto;  ///< our exact sign ("sign"): the reference's and the brute force's
    BvhBuildSite gpu_bvh_build = BvhBuildSite::Auto;  ///< where our GPU rows build their BVH
};

enum class By { Ours, Peer };
/// On which points a method runs: Bands, a narrow band (level set) on a CC lattice, the
/// method choosing its own active voxels (a case of "band_resolutions").
enum class Inputs { LatticesAndPointSets, Lattices, PointSets, Bands };
/// At which thread counts: each of the run's, all cores only, or once on the GPU (rows say "GPU").
enum class Threads { Each, AllCores, Gpu };

/// One row of the method table.
struct MethodKind {
    const char* name;  ///< the config's name and the rows' "method"
    By by;
    bool exact;        ///< every distance an exact point-triangle minimum (not a narrow band)
    Inputs inputs;
    Threads threads;
    /// Timed on the run's "brute_cpu_max_points" evenly strided points and scaled (it costs
    /// the same per point); its errors are checked there.
    bool strided;
    SignKind sign;            ///< the sign of its rows (ours: Mode)
    const char* sign_method;  ///< Own: the peer's rule, in words; else ""
    /// Makes the adapter; null with `why_not` set where it cannot run here ("not built: ...",
    /// "unavailable: ...").
    std::unique_ptr<PeerAdapter> (*make)(const PeerOptions& options, std::string& why_not);
};

/// Every method this build knows, ours first; names are unique.
const std::vector<MethodKind>& method_table();
/// The row named `name`; throws std::invalid_argument naming the known ones.
const MethodKind& method_kind(const std::string& name);
/// The names of the rows `by` ours or the peers, in table order.
std::vector<std::string> method_names(By by);

/// CPU time of this process, all threads (robust to other load on a shared machine).
double process_cpu_seconds();

}  // namespace sdf::peers
