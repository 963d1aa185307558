/// @file bvh_cpu_points.h
/// @brief The CPU BVH sampler's point lists (kernel "brick"): Morton-ordered packets of 16
/// points, each one packet traversal, the results written back in input order.
#pragma once

#include <cstdint>
#include <vector>

#include "core/sampling/host_query.h"
#include "cpu_reference/bvh/bvh_cpu_search.h"

namespace sdf::cpu_bvh {

/// Points per packet of an arbitrary point list: 16, as lattice bricks (8 and 32 measured
/// slower on the dragon's uniform and near-surface sets: tests/benchmarks/bench_bvh.cpp).
constexpr int kPointPacket = kBrick;

/// Morton order of arbitrary points (a vector, or the caller's arrays): the indices of
/// `points` sorted by the Morton key of their cell in the points' bounding box (2^10 cells per
/// axis: finer cells change nothing for packets of 16), ties in input order. An LSD radix sort over the 30 key bits (four
/// 8-bit passes) on `threads` threads, stable, so the order is deterministic.
std::vector<uint32_t> morton_order(const std::vector<Vec3d>& points, int threads);
std::vector<uint32_t> morton_order(const HostPoints& points, int threads);

/// Evaluates arbitrary points (`Points`: a vector or the caller's arrays, host_query.h's
/// point_count/point_at) as Morton-ordered packets: the points are sorted by Morton key,
/// runs of kPointPacket consecutive sorted points share one packet traversal (as lattice bricks
/// do), and each result is written back at its input index. The packet search returns every
/// lane's own brute-force minimum with the same tie rule (closest_triangles_packet.h), and
/// the winner is evaluated exactly as the per-point path does, so the samples are bit for bit
/// those of evaluate_points; only the work shared between neighbours changes.
template <typename T, typename Points, typename EmitFn>
void evaluate_point_packets(const PreparedMesh& mesh, const TriangleBvh& bvh, const SamplerSign& sign, const Points& points,
                            int threads, bool progress, double point_coordinate, QueryCounters& counters, EmitFn emit) {
    const BvhView<T> view = bvh.view<T>();
    const MeshView<double> exact = mesh.buffers<double>().view();
    const int64_t n = point_count(points);
    if (n == 0) return;
    const Certifier<T> certifier(mesh, bvh, point_coordinate);
    const std::vector<uint32_t> order = morton_order(points, threads);
    const int64_t packets = (n + kPointPacket - 1) / kPointPacket;
    ProgressReporter reporter("querying " + mesh.name() + " (bvh)", n, progress);
    parallel_for(packets, kBrickChunk, threads, [&](int64_t begin, int64_t end) {
        BvhStats stats;
        LocalCertificate certified;
        int32_t seed[kPointPacket];
        for (int k = 0; k < kPointPacket; ++k) seed[k] = -1;
        PacketSign packet_sign(sign);
        int64_t done = 0;
        for (int64_t b = begin; b < end; ++b) {
            const int64_t first = b * kPointPacket;
            const int count = int(std::min<int64_t>(kPointPacket, n - first));
            BvhPacket<T, kPointPacket> pk;
            Vec3d position[kPointPacket];
            for (int k = 0; k < kPointPacket; ++k) {
                position[k] = point_at(points, order[size_t(first + (k < count ? k : 0))]);  // spare lanes repeat lane 0
                pk.x[k] = T(position[k].x);
                pk.y[k] = T(position[k].y);
                pk.z[k] = T(position[k].z);
            }
            seed_packet(view, seed, pk);
            int32_t slot[kPointPacket];
            LaneNear near[kPointPacket];
            search_packet(view, certifier, position, count, pk, stats, certified, slot, near);
            SignedDistanceSample<double> sample[kPointPacket];
            for (int k = 0; k < count; ++k) sample[k] = signed_distance_to_triangle(exact, position[k], view.triangle_index[slot[k]]);
            packet_sign.prepare(position, sample, near, count);
            for (int k = 0; k < count; ++k) emit(int64_t(order[size_t(first + k)]), packet_sign.apply(sample[k], k, position[k]));
            for (int k = 0; k < kPointPacket; ++k) seed[k] = pk.best_slot[k];
            done += count;
        }
        certified.add_to(counters.certificate);
        packet_sign.add_to(counters.winding);
        counters.nodes += stats.nodes;
        counters.triangles += stats.triangles;
        reporter.advance(done);
    });
}

}  // namespace sdf::cpu_bvh
