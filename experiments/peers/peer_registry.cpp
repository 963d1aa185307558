// The peers this build has: each adapter file is compiled only when its package was found
// (SDF_HAVE_<PEER>, set in experiments/peers/CMakeLists.txt); Open3D is looked for at run
// time (a Python module). FCPW and cuBQL are source snapshots (SDF_PEERS_DIR): their
// "not built" reason comes from CMake (snapshot not found, or no CUDA backend).
#include "experiments/peers/peer.h"

namespace sdf::peers {

#if SDF_HAVE_CGAL
std::unique_ptr<PeerAdapter> make_cgal_peer();
#endif
#if SDF_HAVE_EMBREE
std::unique_ptr<PeerAdapter> make_embree_peer();
#endif
#if SDF_HAVE_OPENVDB
std::unique_ptr<PeerAdapter> make_openvdb_peer(double band_voxels);
#endif
#if SDF_HAVE_FCPW
std::unique_ptr<PeerAdapter> make_fcpw_peer();
#endif
#if SDF_HAVE_CUBQL
std::unique_ptr<PeerAdapter> make_cubql_peer(std::string& reason);
#endif
std::unique_ptr<PeerAdapter> make_open3d_peer(const std::string& python, std::string& reason);

namespace {

PeerEntry entry(const std::string& name, std::unique_ptr<PeerAdapter> adapter, const std::string& reason) {
    PeerEntry e;
    e.name = name;
    e.available = adapter != nullptr;
    e.reason = e.available ? "" : reason;
    e.adapter = std::move(adapter);
    return e;
}

[[maybe_unused]] std::string not_built(const std::string& package) {
    return "not built: " + package + " was not found at configure time (scripts/install-deps peers)";
}

}  // namespace

std::vector<PeerEntry> make_peers(const PeerOptions& options) {
    std::vector<PeerEntry> peers;
#if SDF_HAVE_CGAL
    peers.push_back(entry("cgal", make_cgal_peer(), ""));
#else
    peers.push_back(entry("cgal", nullptr, not_built("libcgal-dev")));
#endif
#if SDF_HAVE_EMBREE
    peers.push_back(entry("embree", make_embree_peer(), ""));
#else
    peers.push_back(entry("embree", nullptr, not_built("libembree-dev")));
#endif
    std::string reason;
    std::unique_ptr<PeerAdapter> open3d = make_open3d_peer(options.python, reason);
    peers.push_back(entry("open3d", std::move(open3d), reason));
#if SDF_HAVE_OPENVDB
    peers.push_back(entry("openvdb", make_openvdb_peer(options.openvdb_band_voxels), ""));
#else
    peers.push_back(entry("openvdb", nullptr, not_built("libopenvdb-dev")));
#endif
#if SDF_HAVE_FCPW
    peers.push_back(entry("fcpw", make_fcpw_peer(), ""));
#else
    peers.push_back(entry("fcpw", nullptr, std::string("not built: ") + SDF_PEERS_WHY_NOT_FCPW));
#endif
#if SDF_HAVE_CUBQL
    std::string cubql_reason;
    std::unique_ptr<PeerAdapter> cubql = make_cubql_peer(cubql_reason);
    peers.push_back(entry("cubql", std::move(cubql), cubql_reason));
#else
    peers.push_back(entry("cubql", nullptr, std::string("not built: ") + SDF_PEERS_WHY_NOT_CUBQL));
#endif
    return peers;
}

}  // namespace sdf::peers
