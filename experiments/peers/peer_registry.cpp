// The method table of the peers experiment: our samplers (ours_peer.cpp) and the peer
// libraries this build has. Each peer's file is compiled only when its package was found
// (SDF_HAVE_<PEER>, set in experiments/peers/CMakeLists.txt); its factory here otherwise says
// why not. Open3D is looked for at run time (a Python module). FCPW and cuBQL are source
// snapshots (SDF_PEERS_DIR), NanoVDB headers (SDF_NANOVDB_DIR): their "not built" reason
// comes from CMake (snapshot or headers not found, or no CUDA backend).
#include <time.h>

#include <stdexcept>

#include "experiments/peers/ours_peer.h"

namespace sdf::peers {

#if SDF_HAVE_CGAL
std::unique_ptr<PeerAdapter> make_cgal_peer();
#endif
#if SDF_HAVE_EMBREE
std::unique_ptr<PeerAdapter> make_embree_peer();
#endif
#if SDF_HAVE_OPENVDB
std::unique_ptr<PeerAdapter> make_openvdb_peer(double band_voxels);
std::unique_ptr<PeerAdapter> make_openvdb_band_peer();
#endif
#if SDF_HAVE_FCPW
std::unique_ptr<PeerAdapter> make_fcpw_peer();
#endif
#if SDF_HAVE_CUBQL
std::unique_ptr<PeerAdapter> make_cubql_peer(std::string& reason);
#endif
#if SDF_HAVE_NANOVDB_PEER
std::unique_ptr<PeerAdapter> make_nanovdb_peer(std::string& reason);
#endif
std::unique_ptr<PeerAdapter> make_open3d_peer(const std::string& python, std::string& reason);

namespace {

[[maybe_unused]] std::unique_ptr<PeerAdapter> not_built(const std::string& what, std::string& why_not) {
    why_not = "not built: " + what;
    return nullptr;
}
[[maybe_unused]] std::string package_missing(const std::string& package) {
    return package + " was not found at configure time (scripts/install-deps peers)";
}

// Our samplers (ours_peer.h): what each row runs and what its query time is.
constexpr OurSampler kBvhCpuExactSign{"cpu", "bvh", "", false,
                                      "Sampler::query (Morton packets) with the exact sign (\"sign\"), at all cores: the "
                                      "point sets' reference where point_set_sign differs"};
constexpr OurSampler kBvhCpu{"cpu", "bvh", "", true,
                             "lattices: the lattice's sampling (kernel time); point sets: Sampler::query, Morton-ordered "
                             "packets of 16"};
constexpr OurSampler kBvhCpuPerPoint{"cpu", "bvh", "seeded", true,
                                     "Sampler::query, kernel \"seeded\": one point at a time, seeded with the previous "
                                     "point's triangle"};
constexpr OurSampler kBruteCpu{"cpu", "brute_force", "", false, "every triangle per point, with the exact sign"};
constexpr OurSampler kBruteGpu{"cuda", "brute_force", "", false, "CUDA-event time of the search and the double finalize"};
constexpr OurSampler kBvhGpu{"cuda", "bvh", "", false,
                             "CUDA-event time of the (Morton sort,) search and double finalize, with the exact sign; "
                             "end_to_end_seconds: the whole call (uploads, downloads, scatter into input order)"};
constexpr OurSampler kBandCpu{"cpu", "bvh", "", false,
                              "the sparse band (MeshSdf::sample_band), wall time, with the exact sign; its band points "
                              "(|d| <= W) are the active voxels"};
constexpr OurSampler kBandGpu{"cuda", "bvh", "", false,
                              "the sparse band (MeshSdf::sample_band), CUDA-event time of its kernels, with the exact sign; "
                              "end_to_end_seconds: the whole call (uploads, downloads); its band points are the active voxels"};

template <const OurSampler* Sampler>
std::unique_ptr<PeerAdapter> ours(const PeerOptions& o, std::string& why_not) {
    return make_our_peer(*Sampler, o, why_not);
}

std::unique_ptr<PeerAdapter> cgal(const PeerOptions&, std::string& why_not) {
#if SDF_HAVE_CGAL
    (void)why_not;
    return make_cgal_peer();
#else
    return not_built(package_missing("libcgal-dev"), why_not);
#endif
}

std::unique_ptr<PeerAdapter> embree(const PeerOptions&, std::string& why_not) {
#if SDF_HAVE_EMBREE
    (void)why_not;
    return make_embree_peer();
#else
    return not_built(package_missing("libembree-dev"), why_not);
#endif
}

std::unique_ptr<PeerAdapter> open3d(const PeerOptions& o, std::string& why_not) { return make_open3d_peer(o.python, why_not); }

std::unique_ptr<PeerAdapter> openvdb(const PeerOptions& o, std::string& why_not) {
#if SDF_HAVE_OPENVDB
    (void)why_not;
    return make_openvdb_peer(o.openvdb_band_voxels);
#else
    (void)o;
    return not_built(package_missing("libopenvdb-dev"), why_not);
#endif
}

std::unique_ptr<PeerAdapter> openvdb_band(const PeerOptions&, std::string& why_not) {
#if SDF_HAVE_OPENVDB
    (void)why_not;
    return make_openvdb_band_peer();
#else
    return not_built(package_missing("libopenvdb-dev"), why_not);
#endif
}

std::unique_ptr<PeerAdapter> nanovdb(const PeerOptions&, std::string& why_not) {
#if SDF_HAVE_NANOVDB_PEER
    return make_nanovdb_peer(why_not);
#else
    return not_built(SDF_PEERS_WHY_NOT_NANOVDB, why_not);
#endif
}

std::unique_ptr<PeerAdapter> fcpw(const PeerOptions&, std::string& why_not) {
#if SDF_HAVE_FCPW
    (void)why_not;
    return make_fcpw_peer();
#else
    return not_built(SDF_PEERS_WHY_NOT_FCPW, why_not);
#endif
}

std::unique_ptr<PeerAdapter> cubql(const PeerOptions&, std::string& why_not) {
#if SDF_HAVE_CUBQL
    return make_cubql_peer(why_not);
#else
    return not_built(SDF_PEERS_WHY_NOT_CUBQL, why_not);
#endif
}

}  // namespace

const char* sign_kind_name(SignKind kind) {
    for (const NamedSignKind& k : kSignKinds)
        if (k.kind == kind) return k.name;
    return "?";
}

const std::vector<MethodKind>& method_table() {
    using I = Inputs;
    using T = Threads;
    static const std::vector<MethodKind> table = {
        // name                 by        exact  inputs                     threads       strided sign
        {"bvh_cpu_exact_sign",      By::Ours, true,  I::PointSets,              T::AllCores,  false,  SignKind::Mode, "", ours<&kBvhCpuExactSign>},
        {"bvh_cpu",               By::Ours, true,  I::LatticesAndPointSets,   T::Each,      false,  SignKind::Mode, "", ours<&kBvhCpu>},
        {"bvh_cpu_per_point",       By::Ours, true,  I::PointSets,              T::Each,      false,  SignKind::Mode, "", ours<&kBvhCpuPerPoint>},
        {"brute_cpu",             By::Ours, true,  I::LatticesAndPointSets,   T::Each,      true,   SignKind::Mode, "", ours<&kBruteCpu>},
        {"brute_gpu",             By::Ours, true,  I::Lattices,               T::Gpu,       false,  SignKind::Mode, "", ours<&kBruteGpu>},
        {"bvh_gpu",               By::Ours, true,  I::LatticesAndPointSets,   T::Gpu,       false,  SignKind::Mode, "", ours<&kBvhGpu>},
        {"band_cpu",              By::Ours, true,  I::Bands,                  T::Each,      false,  SignKind::Mode, "", ours<&kBandCpu>},
        {"band_gpu",              By::Ours, true,  I::Bands,                  T::Gpu,       false,  SignKind::Mode, "", ours<&kBandGpu>},
        {"cgal",                By::Peer, true,  I::LatticesAndPointSets,   T::Each,      false,
         SignKind::Own, "Side_of_triangle_mesh (ray casting)", cgal},
        {"embree",              By::Peer, true,  I::LatticesAndPointSets,   T::Each,      false,  SignKind::None, "", embree},
        {"open3d",              By::Peer, true,  I::LatticesAndPointSets,   T::Each,      false,
         SignKind::Own, "ray intersection count (compute_signed_distance)", open3d},
        {"openvdb",             By::Peer, false, I::Lattices,               T::Each,      false,
         SignKind::Own, "flood fill of the narrow band", openvdb},
        {"fcpw",                By::Peer, true,  I::LatticesAndPointSets,   T::Each,      false,  SignKind::None, "", fcpw},
        {"cubql",               By::Peer, true,  I::LatticesAndPointSets,   T::Gpu,       false,  SignKind::None, "", cubql},
        {"openvdb_band",        By::Peer, false, I::Bands,                  T::Each,      false,
         SignKind::Own, "flood fill of the narrow band (meshToLevelSet)", openvdb_band},
        {"nanovdb",             By::Peer, false, I::Bands,                  T::Gpu,       false,  SignKind::None, "", nanovdb},
    };
    return table;
}

const MethodKind& method_kind(const std::string& name) {
    std::string known;
    for (const MethodKind& m : method_table()) {
        if (name == m.name) return m;
        known += (known.empty() ? "" : ", ") + std::string(m.name);
    }
    throw std::invalid_argument("unknown method \"" + name + "\"; expected one of " + known);
}

std::vector<std::string> method_names(By by) {
    std::vector<std::string> names;
    for (const MethodKind& m : method_table())
        if (m.by == by) names.emplace_back(m.name);
    return names;
}

double process_cpu_seconds() {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

}  // namespace sdf::peers
