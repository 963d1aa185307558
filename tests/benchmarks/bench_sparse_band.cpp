// The sparse narrow band against the dense one (issue 35), on the CPU BVH or the CUDA BVH:
// one line of JSON per run, so that each run's peak resident memory is its own process's.
//   bench_sparse_band sparse|sparse-no-gradient|sparse-distance|dense|check MESH RES [BAND_SPACINGS=3] [cc|bcc] [cpu|cuda] [KERNEL]
// sparse: sample_band_sparse(); sparse-no-gradient: the same without the gradient channel;
// sparse-distance: with the distance alone (no gradient, no closest triangle); dense: the whole lattice with band_width, slab by slab (64
// z-planes at a time, each slab dropped once sampled, so that lattices whose dense field does
// not fit in memory are timed too); check: both, densified and compared byte for byte.
// Threads: every core (SDF_THREADS overrides). Wall and process CPU seconds are reported; the
// mesh's load and preparation (load_s, prepare_s) and the sampler's binding (bind_s: on the
// GPU the tree's build and upload) apart, and "sparse_wall_with_load_s" with them. On the GPU,
// the sparse band's kernel time (CUDA events) and the device memory in use at its peak.
#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <string>

#include <nlohmann/json.hpp>

#include "core/lattice/lattice_fitting.h"
#include "core/mesh/load_mesh.h"
#include "core/parallel/parallel_for.h"
#include "harness/sampling/sampler_table.h"
#include "tests/test_util/shared_mesh.h"

namespace {

double cpu_seconds() { return double(std::clock()) / CLOCKS_PER_SEC; }
double peak_rss_mib() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return double(u.ru_maxrss) / 1024.0;
}

}  // namespace

int main(int argc, char** argv) {
    using namespace sdf;
    if (argc < 4) {
        std::fprintf(stderr,
                     "usage: %s sparse|sparse-no-gradient|sparse-distance|dense|check MESH RES [BAND_SPACINGS=3] [cc|bcc] "
                     "[cpu|cuda] [KERNEL]\n",
                     argv[0]);
        return 2;
    }
    const std::string mode = argv[1];
    const int res = std::atoi(argv[3]);
    const double band = argc > 4 ? std::atof(argv[4]) : 3.0;
    const LatticeType type = argc > 5 ? lattice_type_named(argv[5]) : LatticeType::CC;
    const auto since = [](std::chrono::steady_clock::time_point t) {
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
    };
    auto t_load = std::chrono::steady_clock::now();
    TriangleMesh loaded = load_mesh_file(argv[2]);
    const double load_s = since(t_load);
    auto t_prepare = std::chrono::steady_clock::now();
    const auto mesh = std::make_shared<const PreparedMesh>(prepare_mesh(std::move(loaded)));
    const double prepare_s = since(t_prepare);
    const bool dense_mode = mode == "dense" || mode == "check";
    const Lattice lattice = fit_lattice(type, {res, res, res}, mesh->bounds(), 0.1,
                                        dense_mode ? LatticeStorage::Dense : LatticeStorage::SparseBand);
    const double w = band * lattice.spacing;
    SamplerOptions o;
    o.backend = argc > 6 ? argv[6] : "cpu";
    o.method = "bvh";
    if (argc > 7) o.kernel = argv[7];
    o.progress = false;
    o.threads = std::getenv("SDF_THREADS") ? std::atoi(std::getenv("SDF_THREADS")) : 0;
    nlohmann::json out = {{"mode", mode}, {"mesh", mesh->name()}, {"triangles", mesh->triangles().size()},
                          {"lattice", lattice_notation(lattice)}, {"band_spacings", band},
                          {"threads", resolve_thread_count(o.threads)}, {"load_s", load_s}, {"prepare_s", prepare_s}};
    auto t_bind = std::chrono::steady_clock::now();
    const auto bound_sparse = make_sampler(o)->bind(mesh);
    const double bind_s = since(t_bind);
    out["bind_s"] = bind_s;
    out["sampler"] = bound_sparse->name();
    o.band_width = w;
    const auto bound_dense = make_sampler(o)->bind(mesh);
    out["sign"] = sign_mode_name(bound_sparse->sign().mode);
    const double rss_bound = peak_rss_mib();
    auto t0 = std::chrono::steady_clock::now();
    double c0 = cpu_seconds();
    auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
    if (mode == "sparse" || mode == "sparse-no-gradient" || mode == "sparse-distance" || mode == "check") {
        BandChannels channels;
        channels.gradient = mode != "sparse-no-gradient" && mode != "sparse-distance";
        channels.closest_triangle = mode != "sparse-distance";
        const SparseBandField sparse = bound_sparse->sample_band_sparse(lattice, w, channels);
        out["sparse_wall_s"] = elapsed();
        out["sparse_cpu_s"] = cpu_seconds() - c0;
        out["sparse_wall_with_load_s"] = load_s + prepare_s + bind_s + out["sparse_wall_s"].get<double>();
        out["sparse_kernel_s"] = sparse.timings.kernel;
        out["sparse_upload_s"] = sparse.timings.upload;
        out["sparse_download_s"] = sparse.timings.download;
        out["sparse"] = sparse.sampler.details["sparse_band"];
        if (sparse.sampler.details.contains("band_blocks_on_device"))  // the GPU's stages, batches and memory
            out["on_device"] = sparse.sampler.details["band_blocks_on_device"];
        if (sparse.sampler.details.contains("band_blocks_on_host"))  // the CPU's bounded search and flood
            out["on_host"] = sparse.sampler.details["band_blocks_on_host"];
        if (sparse.sampler.details.contains("band_blocks_on_device"))
            out["band_blocks_on_device"] = sparse.sampler.details["band_blocks_on_device"];
        out["active_blocks"] = int64_t(sparse.active.size());
        out["band_points"] = sparse.sampler.band->points_in_band;
        if (mode == "check") {
            const SampledField dense = bound_dense->sample(lattice);
            const SampledField densified = sparse.densify();
            const bool same = dense.distance.size() == densified.distance.size() &&
                              std::memcmp(dense.distance.data(), densified.distance.data(), dense.distance.size() * 8) == 0 &&
                              std::memcmp(dense.gradient.data(), densified.gradient.data(), dense.gradient.size() * 24) == 0 &&
                              std::memcmp(dense.closest_triangle.data(), densified.closest_triangle.data(),
                                          dense.closest_triangle.size() * 4) == 0;
            out["densified_equals_dense"] = same;
            if (!same) {
                std::printf("%s\n", out.dump().c_str());
                return 1;
            }
        }
    } else if (mode == "dense") {
        int64_t in_band = 0;
        for (int z = 0; z < lattice.resolution.z; z += 64) {
            const SampledField slab = bound_dense->sample_slab(lattice, {z, std::min(z + 64, lattice.resolution.z)});
            in_band += slab.sampler.band->points_in_band;
        }
        out["dense_wall_s"] = elapsed();
        out["dense_cpu_s"] = cpu_seconds() - c0;
        out["band_points"] = in_band;
    } else {
        std::fprintf(stderr, "unknown mode %s\n", mode.c_str());
        return 2;
    }
    out["peak_rss_MiB"] = peak_rss_mib();
    out["rss_after_binding_MiB"] = rss_bound;
    std::printf("%s\n", out.dump().c_str());
    return 0;
}
