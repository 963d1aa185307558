/// @file peer.h
/// @brief The small interface every peer library adapter implements for the "peers"
/// experiment: the same lattice points go in, distances (signed where the peer signs them)
/// and timings come out. One file per peer; each is built only when its Debian package (or,
/// for FCPW and cuBQL, its source snapshot in SDF_PEERS_DIR) is present
/// (experiments/peers/CMakeLists.txt), and peer_registry.cpp lists them.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/mesh/prepared_mesh.h"
#include "kernels/lattice/lattice.h"

namespace sdf::peers {

/// What one run of a peer returns.
struct PeerResult {
    std::vector<double> distance;   ///< one per point; signed (negative inside) when `is_signed`
    bool is_signed = false;
    std::vector<uint8_t> in_band;   ///< narrow-band peers: 1 where the value was computed; empty = everywhere
    double build_seconds = 0;       ///< acceleration structure (BVH, tree, grid set-up)
    double query_seconds = 0;       ///< the distance queries (and signs) themselves
    int threads = 1;                ///< threads the peer actually used
    double cpu_seconds = -1;        ///< CPU time of build + query over all threads, if the adapter measures it (else the experiment does)
    nlohmann::json details = nlohmann::json::object();  ///< band width, sign method, split times
};

class PeerAdapter {
public:
    virtual ~PeerAdapter() = default;
    virtual std::string name() const = 0;     ///< "cgal", "embree", "open3d", "openvdb", "fcpw", "cubql"
    virtual std::string version() const = 0;  ///< the library's version string
    /// True when every returned distance is an exact point-triangle minimum (not narrow band).
    virtual bool exact() const = 0;
    /// A GPU library: run once per case (not per thread count), its rows say "GPU".
    virtual bool on_gpu() const { return false; }
    /// Samples `points` (the lattice's points in storage order, or a point set) with
    /// `threads` threads (GPU peers ignore it).
    virtual PeerResult run(const PreparedMesh& mesh, const Lattice& lattice, const std::vector<Vec3d>& points,
                           int threads) = 0;
};

/// Options the experiment passes to the adapters that take them.
struct PeerOptions {
    double openvdb_band_voxels = 3.0;  ///< OpenVDB narrow band half-width, in voxels (each side)
    std::string python;                ///< interpreter with open3d; empty = look for one
};

/// Every peer this build knows; `available` tells which can run here, `reason` why not.
struct PeerEntry {
    std::string name;
    bool available = false;
    std::string reason;
    std::unique_ptr<PeerAdapter> adapter;
};
std::vector<PeerEntry> make_peers(const PeerOptions& options);

}  // namespace sdf::peers
