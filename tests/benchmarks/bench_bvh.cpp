// Google Benchmark of the BVH samplers: exact queries per second on the CC lattices of the
// bunny and the dragon (262k = 64^3 and 2,097k = 128^3 points).
//   CPU: 1 thread and all threads; kernels brick (16-point packets), seeded, unseeded; the build.
//   GPU (when a device is present): manual time from the sampler's CUDA events, the three
//   BVH kernels in float and double, and the tuned brute force beside them (issue 7's 100x).
//   Arbitrary points (issue 14): Sampler::query on 1M uniform-box and Gaussian-near-surface
//   points (core/sampling/point_sets.h), kernel brick (Morton-ordered packets of 16) against
//   seeded (one point at a time), 1 thread and all threads.
//   BM_CpuBvhPacketKernel: the dispatched packet search alone (plain float, certified float,
//   certified and re-ranked in double, plain double), 1 thread, CPU time.
//   SDF_DATA_PATH=... bench_bvh --benchmark_counters_tabular=true --benchmark_filter=Cpu
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <random>
#include <memory>
#include <sstream>
#include <type_traits>

#include "cpu_reference/bvh/bvh_cpu.h"
#include "cpu_reference/dispatch/cpu_kernels.h"
#include "core/sampling/certified_search.h"
#include "core/bvh/triangle_bvh.h"
#include "core/winding/winding_bvh.h"
#include "core/lattice/lattice_fitting.h"
#include "core/mesh/load_obj.h"
#include "core/parallel/parallel_for.h"
#include "core/sampling/point_sets.h"
#include "harness/build_config.h"
#include "harness/sampling/sampler_table.h"
#if SDF_HAVE_CUDA
#include "cuda/bvh/device_bvh_build.h"
#include "cuda/util/device_mesh.h"
#endif

namespace sdf {
namespace {

/// The path of bunny.obj / dragon.obj in SDF_DATA_PATH or the build's default data
/// directories; empty when none holds it.
std::string find_mesh_file(const std::string& file) {
    std::string dirs = std::getenv("SDF_DATA_PATH") ? std::getenv("SDF_DATA_PATH") : "";
    dirs += std::string(":") + SDF_DATA_DIR_DEFAULT;
    for (char& c : dirs) if (c == ';') c = ':';
    std::stringstream ss(dirs);
    for (std::string d; std::getline(ss, d, ':');)
        if (!d.empty() && std::ifstream(d + "/" + file).good()) return d + "/" + file;
    return {};
}

/// That mesh, prepared once.
std::shared_ptr<PreparedMesh> load(const std::string& file) {
    static std::map<std::string, std::shared_ptr<PreparedMesh>> cache;
    if (cache.count(file)) return cache[file];
    const std::string path = find_mesh_file(file);
    return cache[file] = path.empty() ? nullptr : std::make_shared<PreparedMesh>(prepare_mesh(load_obj(path)));
}

Lattice cubic_lattice(const PreparedMesh& mesh, int r) { return fit_lattice(LatticeType::CC, {r, r, r}, mesh.bounds(), 0.1); }

void set_counters(benchmark::State& state, const PreparedMesh& mesh, const Lattice& lattice, const SampledField& f) {
    const double points = double(lattice.num_points());
    state.counters["queries/s"] = benchmark::Counter(points * double(state.iterations()), benchmark::Counter::kIsRate);
    state.counters["points"] = points;
    state.counters["triangles"] = double(mesh.triangles().size());
    // Certified float search: the fraction of points re-ranked in double (several candidates).
    if (f.timings.certified_points > 0) {
        state.counters["reranked"] = double(f.timings.reranked_points) / double(f.timings.certified_points);
        state.counters["full_dbl"] = double(f.timings.full_double_points) / double(f.timings.certified_points);
    }
    if (f.sampler.details.contains("bvh") && f.sampler.details.at("bvh").contains("node_visits_per_point")) {
        state.counters["nodes/pt"] = f.sampler.details.at("bvh")["node_visits_per_point"].get<double>();
        state.counters["tris/pt"] = f.sampler.details.at("bvh")["point_triangle_tests_per_point"].get<double>();
    }
}

/// Kernels by argument: 0 brick (packets of 16 lattice points), 1 seeded, 2 unseeded, 3 warp (CUDA).
const char* const kKernels[] = {"brick", "seeded", "unseeded", "warp", "candidates"};  // warp, candidates: CUDA only

/// Args: resolution, threads (0 = all), kernel.
void BM_CpuBvh(benchmark::State& state, const std::string& file) {
    const auto mesh = load(file);
    if (!mesh) { state.SkipWithError((file + " not found: set SDF_DATA_PATH").c_str()); return; }
    const Lattice lattice = cubic_lattice(*mesh, int(state.range(0)));
    SamplerOptions o;
    o.method = "bvh";
    o.threads = int(state.range(1));
    o.kernel = kKernels[state.range(2)];
    o.progress = false;
    const auto sampler = make_cpu_bvh_sampler(o)->bind(mesh);  // the mesh's BVH (if not built yet) and sign data
    SampledField f = sampler->sample(lattice);
    for (auto _ : state) {
        f = sampler->sample(lattice);
        state.SetIterationTime(f.timings.kernel);
    }
    set_counters(state, *mesh, lattice, f);
    state.counters["threads"] = double(resolve_thread_count(o.threads));
}

/// Args: point set (0 uniform box, 1 Gaussian around the surface, sigma 0.01 of the diagonal),
/// threads (0 = all), kernel (0 brick = Morton packets, 1 seeded = per point). 2^20 points.
void BM_CpuBvhPointQuery(benchmark::State& state, const std::string& file) {
    const auto mesh = load(file);
    if (!mesh) { state.SkipWithError((file + " not found: set SDF_DATA_PATH").c_str()); return; }
    PointSetSpec spec;
    spec.kind = state.range(0) ? PointSetKind::GaussianSurface : PointSetKind::UniformBox;
    spec.count = int64_t(1) << 20;
    const std::vector<Vec3d> points = make_point_set(*mesh, spec);
    SamplerOptions o;
    o.method = "bvh";
    o.threads = int(state.range(1));
    o.kernel = kKernels[state.range(2)];
    o.progress = false;
    const auto sampler = make_cpu_bvh_sampler(o)->bind(mesh);  // the mesh's BVH (if not built yet) and sign data
    for (auto _ : state) benchmark::DoNotOptimize(sampler->query(points).data());
    state.counters["queries/s"] = benchmark::Counter(double(points.size()) * double(state.iterations()), benchmark::Counter::kIsRate);
    state.counters["points"] = double(points.size());
    state.counters["threads"] = double(resolve_thread_count(o.threads));
}

/// The dispatched packet search alone (cpu_reference/dispatch/cpu_kernels.h) on the lattice's
/// 4 x 2 x 2 bricks, 1 thread, each lane seeded by the brick before it along x, as the sampler
/// runs it; no exact evaluation or sign. Arg: 0 plain float, 1 certified float (candidates
/// kept, not re-ranked), 2 certified float and the re-ranking in double, 3 plain double.
/// CPU time; `reranked`: the share of lanes with more than one candidate.
void BM_CpuBvhPacketKernel(benchmark::State& state, const std::string& file) {
    const auto mesh = load(file);
    if (!mesh) { state.SkipWithError((file + " not found: set SDF_DATA_PATH").c_str()); return; }
    const Lattice lattice = cubic_lattice(*mesh, int(state.range(0)));
    const TriangleBvh bvh = build_triangle_bvh(*mesh);
    const int mode = int(state.range(1));
    const Int3 r = lattice.resolution;
    constexpr int K = kCpuPacketLanes;
    std::vector<Vec3d> lanes;  // K points per brick, brick by brick in x-major order
    for (int k = 0; k + 1 < r.z; k += 2)
        for (int j = 0; j + 1 < r.y; j += 2)
            for (int i = 0; i + 3 < r.x; i += 4)
                for (int l = 0; l < K; ++l)
                    lanes.push_back(lattice.position_of_coords({2 * (i + l % 4), 2 * (j + (l / 4) % 2), 2 * (k + l / 8)}));
    const int64_t bricks = int64_t(lanes.size()) / K;
    const SearchSlack<float> slack = make_search_slack(float_search_bound(*mesh), largest_lattice_coordinate(lattice));
    const CpuCertifiedKernels& certified = certified_cpu_kernels();
    int64_t reranked = 0, lanes_done = 0;
    auto run = [&](auto zero) {
        using T = decltype(zero);
        const BvhView<T> view = bvh.view<T>();
        const BvhView<double> exact = bvh.view<double>();
        int32_t seed[K];
        BvhStats stats;
        for (int64_t b = 0; b < bricks; ++b) {
            if (b % (r.x / 4) == 0) std::fill(seed, seed + K, -1);
            BvhPacket<T, K> pk;
            for (int l = 0; l < K; ++l) {
                const Vec3d& p = lanes[size_t(b * K + l)];
                pk.x[l] = T(p.x); pk.y[l] = T(p.y); pk.z[l] = T(p.z);
            }
            seed_packet(view, seed, pk);
            if constexpr (std::is_same_v<T, float>) {
                if (mode == 0) {
                    cpu_kernels<float>().closest_triangles_packet(view, pk, stats);
                } else {
                    CpuPacketCertifiedNear near;
                    near.slack = slack;
                    certified.closest_triangles_packet(view, pk, stats, near);
                    if (mode == 2)
                        for (int l = 0; l < K; ++l) {
                            const NearCandidates<float, kCpuNearCandidates>& c = near.near[l];
                            const Rerank rr = certified.rerank(exact.packed, view.triangle_index, lanes[size_t(b * K + l)],
                                                               pk.best_slot[l], slack.radius(pk.best_q[l]), c.slot, c.q,
                                                               c.count, c.dropped);
                            int winner = rr.slot;
                            benchmark::DoNotOptimize(winner);
                            reranked += rr.reranked;
                        }
                }
            } else {
                cpu_kernels<double>().closest_triangles_packet(view, pk, stats);
            }
            for (int l = 0; l < K; ++l) seed[l] = pk.best_slot[l];
            benchmark::DoNotOptimize(pk.best_slot);
        }
        lanes_done += bricks * K;
        state.counters["tris/pt"] = double(stats.triangles) / double(bricks * K);
    };
    for (auto _ : state) {
        if (mode == 3) run(0.0); else run(0.0f);
    }
    state.SetLabel(active_cpu_kernels().isa);
    state.counters["points"] = double(bricks * K);
    if (mode == 2) state.counters["reranked"] = double(reranked) / double(lanes_done);
}

void point_query_args(benchmark::internal::Benchmark* b) {
    for (int set : {0, 1})
        for (int threads : {1, 0})
            for (int kernel : {0, 1}) b->Args({set, threads, kernel});
    b->ArgNames({"gaussian", "threads", "kernel"})->UseRealTime()->Unit(benchmark::kMillisecond)->Iterations(1)->Repetitions(3)
        ->ReportAggregatesOnly(true);
}

/// The host SAH build on range(0) threads (0: all), wall time.
void BM_BvhBuild(benchmark::State& state, const std::string& file) {
    const auto mesh = load(file);
    if (!mesh) { state.SkipWithError((file + " not found: set SDF_DATA_PATH").c_str()); return; }
    BvhBuildOptions o;
    o.threads = int(state.range(0));
    for (auto _ : state) benchmark::DoNotOptimize(build_triangle_bvh(*mesh, o).nodes.data());
    state.counters["triangles"] = double(mesh->triangles().size());
}

/// prepare_mesh() of a loaded mesh on range(0) threads (0: all), wall time: welding,
/// adjacency, pseudonormals, both precisions' buffers, the BVH and the self-intersection test.
void BM_PrepareMesh(benchmark::State& state, const std::string& file) {
    const std::string path = find_mesh_file(file);
    if (path.empty()) { state.SkipWithError((file + " not found: set SDF_DATA_PATH").c_str()); return; }
    const TriangleMesh mesh = load_obj(path);
    MeshPreparationOptions o;
    o.threads = int(state.range(0));
    for (auto _ : state) benchmark::DoNotOptimize(prepare_mesh(mesh, o).triangles().data());
    state.counters["triangles"] = double(mesh.triangles.size());
}

/// The mesh of a GPU benchmark, or null after marking the benchmark skipped (no device, no file).
std::shared_ptr<PreparedMesh> load_for_cuda(benchmark::State& state, const std::string& file) {
    if (!cuda_backend_available()) {
        state.SkipWithError("no CUDA device");
        return nullptr;
    }
    auto mesh = load(file);
    if (!mesh) state.SkipWithError((file + " not found: set SDF_DATA_PATH").c_str());
    return mesh;
}

/// The CUDA BVH sampler's options with `kernel`.
SamplerOptions cuda_bvh_options(const std::string& kernel) {
    SamplerOptions o;
    o.backend = "cuda";
    o.method = "bvh";
    o.kernel = kernel;
    o.progress = false;
    return o;
}

void BM_CudaBvh(benchmark::State& state, const std::string& file) {
    const auto mesh = load_for_cuda(state, file);
    if (!mesh) return;
    const Lattice lattice = cubic_lattice(*mesh, int(state.range(0)));
    SamplerOptions o = cuda_bvh_options(kKernels[state.range(1)]);
    o.precision = state.range(2) ? Precision::Double : Precision::Float;
    const auto sampler = make_sampler(o)->bind(mesh);  // the BVH upload
    SampledField f = sampler->sample(lattice);  // warm-up: module load
    for (auto _ : state) {
        f = sampler->sample(lattice);
        state.SetIterationTime(f.timings.kernel);
    }
    set_counters(state, *mesh, lattice, f);
    if (f.sampler.details.contains("candidates"))
        state.counters["candidate_triangles"] = f.sampler.details.at("candidates")["mean_candidate_triangles"].get<double>();
}

/// `count` points for the point-query benchmarks (seed 7): uniform in the mesh's box, or
/// `near_surface`: on a random triangle plus a Gaussian of sigma 1% of the diagonal (an
/// area-weighted triangle would be the textbook draw; a uniform one is close on these evenly
/// tessellated scans and keeps set-up cheap).
std::vector<Vec3d> benchmark_points(const PreparedMesh& mesh, int64_t count, bool near_surface) {
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::normal_distribution<double> g(0.0, 0.01 * mesh.bounds().diagonal());
    std::vector<Vec3d> points(static_cast<size_t>(count));
    const Bounds3& box = mesh.bounds();
    for (Vec3d& p : points) {
        if (!near_surface) {
            p = box.min + component_mul(box.extent(), Vec3d{u(rng), u(rng), u(rng)});
        } else {
            const Int3 t = mesh.triangles()[size_t(rng() % mesh.triangles().size())];
            double a = u(rng), b = u(rng);
            if (a + b > 1) { a = 1 - a; b = 1 - b; }
            const Vec3d& v0 = mesh.vertices()[size_t(t.x)];
            p = v0 + (mesh.vertices()[size_t(t.y)] - v0) * a + (mesh.vertices()[size_t(t.z)] - v0) * b +
                Vec3d{g(rng), g(rng), g(rng)};
        }
    }
    return points;
}

/// Arbitrary points (issue 14): uniform in the mesh's box (kind 0) or Gaussian around
/// surface points, sigma = 1% of the diagonal (kind 1); the device time of the Morton sort,
/// search and finalize (BoundSampler::query's timings), float search.
void BM_CudaBvhPoints(benchmark::State& state, const std::string& file) {
    const auto mesh = load_for_cuda(state, file);
    if (!mesh) return;
    const int64_t n = state.range(0);
    const std::vector<Vec3d> points = benchmark_points(*mesh, n, state.range(1) != 0);
    const auto sampler = make_sampler(cuda_bvh_options(kKernels[state.range(2)]))->bind(mesh);  // the BVH upload
    SamplingTimings t;
    sampler->query(points, &t);  // warm-up: module load
    for (auto _ : state) {
        benchmark::DoNotOptimize(sampler->query(points, &t).data());
        state.SetIterationTime(t.kernel);
    }
    state.counters["points"] = double(n);
    state.counters["queries_per_second"] = t.kernel > 0 ? double(n) / t.kernel : 0.0;
    state.counters["end_to_end_seconds"] = t.total;
}

/// The narrow band on the lattice with the two kernels that skip the bricks outside it (3 warp,
/// 4 candidates): band half-width in lattice spacings.
void BM_CudaBvhBand(benchmark::State& state, const std::string& file) {
    const auto mesh = load_for_cuda(state, file);
    if (!mesh) return;
    const Lattice lattice = cubic_lattice(*mesh, int(state.range(0)));
    SamplerOptions o = cuda_bvh_options(kKernels[state.range(2)]);
    o.band_width = double(state.range(1)) * lattice.spacing;
    const auto sampler = make_sampler(o)->bind(mesh);
    SampledField f = sampler->sample(lattice);
    for (auto _ : state) {
        f = sampler->sample(lattice);
        state.SetIterationTime(f.timings.kernel);
    }
    set_counters(state, *mesh, lattice, f);
    int64_t in_band = 0;
    for (int32_t t : f.closest_triangle) in_band += t != kOutsideBandTriangle;
    state.counters["points_in_band"] = double(in_band);
}

/// The GPU sampler's BVH build (issue 23): arg 0 = on the host (binned SAH, the winding
/// moments, and the upload of nodes, packed constants in BVH order, slots and moments, as
/// the sampler does), 1 = on the device (cuda/bvh/device_bvh_build.h: PLOC with its moments, the
/// packed constants made there); arg 2: GpuBvhBuildOptions::ploc_tail_clusters. Wall time;
/// the double mesh, which both need on the device, is uploaded before the clock starts.
void BM_CudaBvhBuild(benchmark::State& state, const std::string& file) {
#if SDF_HAVE_CUDA
    const auto mesh = load_for_cuda(state, file);
    if (!mesh) return;
    const cuda::DeviceMesh<double> dmesh(mesh->buffers<double>());
    const bool device = state.range(0) == 1;
    BvhBuildStats stats;
    double device_ms = 0;
    for (auto _ : state) {
        const auto start = std::chrono::steady_clock::now();
        if (device) {
            GpuBvhBuildOptions options;
            options.ploc_tail_clusters = int(state.range(1));
            const auto built = cuda::build_lbvh_on_device(*mesh, dmesh.view().vertices, dmesh.view().triangles, options);
            stats = built->stats;
            device_ms = 1e3 * built->device_seconds;
        } else {
            const auto bvh = std::make_shared<const TriangleBvh>(build_triangle_bvh(*mesh));
            const WindingBvh moments = build_winding_bvh(*mesh, bvh);
            cuda::DeviceBuffer<BvhNode> nodes;
            cuda::DeviceBuffer<PackedTriangle<float>> pf;
            cuda::DeviceBuffer<PackedTriangle<double>> pd;
            cuda::DeviceBuffer<int32_t> slots;
            cuda::DeviceBuffer<WindingNode<double>> m;
            nodes.upload(bvh->nodes);
            pf.upload(bvh->packed_float);
            pd.upload(bvh->packed_double);
            slots.upload(bvh->triangle_index);
            m.upload(moments.moments);
            CUDA_CHECK(cudaStreamSynchronize(0));
            stats = bvh->stats;
        }
        state.SetIterationTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
    state.counters["triangles"] = double(mesh->triangles().size());
    state.counters["nodes"] = stats.nodes;
    state.counters["depth"] = stats.depth;
    state.counters["sah_cost"] = stats.sah_cost;
    if (device) state.counters["device_ms"] = device_ms;
#else
    state.SkipWithError("built without CUDA");
    (void)file;
#endif
}

/// What a user without a built tree waits for a first answer: a new CUDA BVH sampler's first
/// query of one point, wall time, after another sampler's first call loaded the kernels'
/// modules (as the peers experiment times our build against cuBQL's second build). Arg
/// device_tree 1: the device build, the mesh's upload, one search; 0: the mesh's host tree
/// (built by its preparation, not timed) uploaded, with the winding moments where the sign
/// is the winding number's (dragon-legacy), what "auto" does there.
void BM_CudaBvhFirstQuery(benchmark::State& state, const std::string& file) {
    const auto mesh = load_for_cuda(state, file);
    if (!mesh) return;
    SamplerOptions o = cuda_bvh_options("warp");
    o.bvh_build = state.range(0) ? BvhBuildSite::Device : BvhBuildSite::Host;
    const std::vector<Vec3d> one = {mesh->bounds().center()};
    make_sampler(o)->bind(mesh)->query(one);
    SamplingTimings last;
    double bind_seconds = 0;
    for (auto _ : state) {
        const auto start = std::chrono::steady_clock::now();
        const auto sampler = make_sampler(o)->bind(mesh);  // the mesh's upload and the build
        bind_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        benchmark::DoNotOptimize(sampler->query(one, &last).data());
        state.SetIterationTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
    state.counters["upload_and_build_ms"] = 1e3 * bind_seconds;  // the binding's wall time: the mesh's upload and the build
    state.counters["search_ms"] = 1e3 * last.kernel;
}

/// The query time on each tree (args: resolution, 0 = host-built SAH tree / 1 = device-built
/// LBVH), warp kernel, float: the device tree must keep the query speed.
void BM_CudaBvhOnTree(benchmark::State& state, const std::string& file) {
    const auto mesh = load_for_cuda(state, file);
    if (!mesh) return;
    const Lattice lattice = cubic_lattice(*mesh, int(state.range(0)));
    SamplerOptions o = cuda_bvh_options("warp");
    o.bvh_build = state.range(1) ? BvhBuildSite::Device : BvhBuildSite::Host;
    const auto sampler = make_sampler(o)->bind(mesh);
    SampledField f = sampler->sample(lattice);
    for (auto _ : state) {
        f = sampler->sample(lattice);
        state.SetIterationTime(f.timings.kernel);
    }
    set_counters(state, *mesh, lattice, f);
    state.counters["sah_cost"] = f.sampler.details["bvh"]["sah_cost"].get<double>();
}

/// Point queries on each tree (args: points, 0 uniform / 1 Gaussian near the surface as
/// BM_CudaBvhPoints draws them, 0 host / 1 device tree); manual time = the device time.
void BM_CudaBvhPointsOnTree(benchmark::State& state, const std::string& file) {
    const auto mesh = load_for_cuda(state, file);
    if (!mesh) return;
    const std::vector<Vec3d> points = benchmark_points(*mesh, state.range(0), state.range(1) != 0);
    SamplerOptions o = cuda_bvh_options("warp");
    o.bvh_build = state.range(2) ? BvhBuildSite::Device : BvhBuildSite::Host;
    const auto sampler = make_sampler(o)->bind(mesh);
    SamplingTimings t;
    sampler->query(points, &t);
    for (auto _ : state) {
        benchmark::DoNotOptimize(sampler->query(points, &t).data());
        state.SetIterationTime(t.kernel);
    }
    state.counters["points"] = double(points.size());
    state.counters["queries_per_second"] = double(points.size()) / t.kernel;
}

/// The tuned CUDA brute force on the same lattices (float), for the BVH's speedup.
void BM_CudaBrute(benchmark::State& state, const std::string& file) {
    if (!cuda_backend_available()) { state.SkipWithError("no CUDA device"); return; }
    const auto mesh = load(file);
    if (!mesh) { state.SkipWithError((file + " not found: set SDF_DATA_PATH").c_str()); return; }
    const Lattice lattice = cubic_lattice(*mesh, int(state.range(0)));
    SamplerOptions o;
    o.backend = "cuda";
    o.method = "brute_force";
    o.progress = false;
    const auto sampler = make_sampler(o)->bind(mesh);
    SampledField f = sampler->sample(lattice);  // warm-up
    for (auto _ : state) {
        f = sampler->sample(lattice);
        state.SetIterationTime(f.timings.kernel);
    }
    set_counters(state, *mesh, lattice, f);
}

void cpu_args(benchmark::internal::Benchmark* b) {
    for (int r : {64, 128})
        for (int threads : {1, 0})
            for (int kernel : {0, 1, 2}) b->Args({r, threads, kernel});
    b->ArgNames({"res", "threads", "kernel"})->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(1)->Repetitions(3)
        ->ReportAggregatesOnly(true);
}

void cuda_args(benchmark::internal::Benchmark* b) {
    for (int r : {64, 128})
        for (int kernel : {0, 1, 2, 3, 4})
            for (int dbl : {0, 1}) b->Args({r, kernel, dbl});
    for (int kernel : {3, 4}) b->Args({256, kernel, 0});
    b->ArgNames({"res", "kernel", "double"})->UseManualTime()->Unit(benchmark::kMillisecond)->MinTime(0.5);
}

BENCHMARK_CAPTURE(BM_BvhBuild, bunny, std::string("bunny.obj"))->Arg(1)->Arg(0)->ArgName("threads")->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_BvhBuild, dragon, std::string("dragon.obj"))->Arg(1)->Arg(0)->ArgName("threads")->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_BvhBuild, dragon_legacy, std::string("dragon-legacy.obj"))->Arg(1)->Arg(0)->ArgName("threads")->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_PrepareMesh, dragon_legacy, std::string("dragon-legacy.obj"))->Arg(1)->Arg(0)->ArgName("threads")->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_CpuBvh, bunny, std::string("bunny.obj"))->Apply(cpu_args);
BENCHMARK_CAPTURE(BM_CpuBvh, dragon, std::string("dragon.obj"))->Apply(cpu_args);
BENCHMARK_CAPTURE(BM_CpuBvh, dragon_legacy, std::string("dragon-legacy.obj"))->Apply(cpu_args);
BENCHMARK_CAPTURE(BM_CpuBvhPacketKernel, dragon, std::string("dragon.obj"))
    ->ArgsProduct({{64, 128}, {0, 1, 2, 3}})->ArgNames({"res", "mode"})->Unit(benchmark::kMillisecond)->Iterations(1)
    ->Repetitions(3)->ReportAggregatesOnly(true);
BENCHMARK_CAPTURE(BM_CpuBvhPointQuery, bunny, std::string("bunny.obj"))->Apply(point_query_args);
BENCHMARK_CAPTURE(BM_CpuBvhPointQuery, dragon, std::string("dragon.obj"))->Apply(point_query_args);
BENCHMARK_CAPTURE(BM_CudaBvh, bunny, std::string("bunny.obj"))->Apply(cuda_args);
BENCHMARK_CAPTURE(BM_CudaBvh, dragon, std::string("dragon.obj"))->Apply(cuda_args);
BENCHMARK_CAPTURE(BM_CudaBvhPoints, dragon, std::string("dragon.obj"))
    ->ArgsProduct({{1 << 20, 1 << 24}, {0, 1}, {3, 4}})
    ->ArgNames({"points", "gaussian", "kernel"})->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(5);  // each call also transfers and scatters on the host
BENCHMARK_CAPTURE(BM_CudaBvhBand, dragon, std::string("dragon.obj"))
    ->ArgsProduct({{256}, {2, 8}, {3, 4}})->ArgNames({"res", "band_spacings", "kernel"})->UseManualTime()->Unit(benchmark::kMillisecond)->MinTime(0.5);
BENCHMARK_CAPTURE(BM_CudaBvhBuild, bunny, std::string("bunny.obj"))->Args({0, 0})->Args({1, 4096})->ArgNames({"device", "tail"})
    ->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_CudaBvhBuild, dragon, std::string("dragon.obj"))
    ->Args({0, 0})->Args({1, 0})->Args({1, 2048})->Args({1, 4096})->Args({1, 6144})
    ->ArgNames({"device", "tail"})->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_CudaBvhFirstQuery, dragon, std::string("dragon.obj"))
    ->Arg(0)->Arg(1)->ArgName("device_tree")->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_CudaBvhFirstQuery, dragon_legacy_winding, std::string("dragon-legacy.obj"))
    ->Arg(0)->Arg(1)->ArgName("device_tree")->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_CudaBvhOnTree, dragon, std::string("dragon.obj"))
    ->ArgsProduct({{128, 256}, {0, 1}})->ArgNames({"res", "device_tree"})->UseManualTime()->Unit(benchmark::kMillisecond)->MinTime(0.5);
BENCHMARK_CAPTURE(BM_CudaBvhPointsOnTree, dragon, std::string("dragon.obj"))
    ->ArgsProduct({{1 << 20, 1 << 24}, {0, 1}, {0, 1}})->ArgNames({"points", "gaussian", "device_tree"})->UseManualTime()
    ->Unit(benchmark::kMillisecond)->MinTime(0.5);
BENCHMARK_CAPTURE(BM_CudaBrute, bunny, std::string("bunny.obj"))->Arg(64)->Arg(128)->ArgName("res")->UseManualTime()
    ->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK_CAPTURE(BM_CudaBrute, dragon, std::string("dragon.obj"))->Arg(64)->Arg(128)->ArgName("res")->UseManualTime()
    ->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace
}  // namespace sdf

BENCHMARK_MAIN();
