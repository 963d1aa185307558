#include "cpu_reference/bvh/bvh_cpu.h"
#include "cpu_reference/bvh/packet_sign.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <chrono>
#include <stdexcept>
#include <type_traits>
#include <vector>

#include "core/bvh/triangle_bvh.h"
#include "core/parallel/parallel_for.h"
#include "core/parallel/progress.h"
#include "cpu_reference/dispatch/cpu_kernels.h"
#include "core/sampling/certified_search.h"
#include "core/sampling/narrow_band.h"
#include "core/sampling/sampler_results.h"
#include "kernels/core/morton.h"
#include "kernels/distance/signed_distance.h"

namespace sdf {
namespace {

/// Points per parallel_for chunk: long enough that most seeds come from the x-neighbour.
constexpr int64_t kBvhChunk = 256;

/// Lattice bricks of 4 x 2 x 2 points share one packet traversal (kCpuPacketLanes).
constexpr int kBrickX = 4, kBrickY = 2, kBrickZ = 2, kBrick = kBrickX * kBrickY * kBrickZ;
static_assert(kBrick == kCpuPacketLanes, "a brick is one packet of the dispatched kernel");
/// Packets of arbitrary points per parallel_for chunk.
constexpr int64_t kBrickChunk = 16;
/// Rows of lattice bricks (along x) per parallel_for chunk: a row's first brick is seeded by
/// the first brick of the row before it, and a narrow band's probes are shared along x and y.
constexpr int64_t kChunkRows = 8;

using BvhKernel = CpuBvhKernel;

struct QueryCounters {
    std::atomic<int64_t> nodes{0}, triangles{0};
    CertificateCounters certificate;
};

/// A thread's counts of certified points, added to the run's CertificateCounters at the end.
struct LocalCertificate {
    int64_t points = 0, reranked = 0, full_double = 0;
    void add_to(CertificateCounters& c) const {
        c.points += points;
        c.reranked += reranked;
        c.full_double += full_double;
    }
};

/// The certified float search's context (search_certificate.h): the slack of every point of
/// the run, the double constants for re-ranking and the kernels of the widest ISA the CPU
/// has (cpu_kernels.h). `T` double: the search is the reference.
template <typename T>
struct Certifier {
    static constexpr bool kActive = std::is_same_v<T, float>;
    SearchSlack<float> slack;
    BvhView<double> exact;
    const CpuCertifiedKernels& kernels = certified_cpu_kernels();

    Certifier(const PreparedMesh& mesh, const TriangleBvh& bvh, double point_coordinate) : exact(bvh.view<double>()) {
        if constexpr (kActive)
            slack = make_search_slack(bvh.float_bound ? *bvh.float_bound : float_search_bound(mesh), point_coordinate);
    }

    /// Starts loading the double constants of the candidates (three cache lines each, in an
    /// array apart from the float ones): a packet's lanes then wait for memory together.
    template <int N>
    void prefetch(const NearCandidates<float, N>& near) const {
        for (int i = 0; i < near.count; ++i) {
            const char* at = reinterpret_cast<const char*>(exact.packed + near.slot[i]);
            __builtin_prefetch(at);
            __builtin_prefetch(at + 64);
            __builtin_prefetch(at + 128);
        }
    }

    /// The double search's winner (BVH slot) at p from the float search's winner and its
    /// candidates; counts what it took.
    int32_t certify(const BvhView<float>& view, const Vec3d& p, int32_t winner, float best_q,
                    const NearCandidates<float, kCpuNearCandidates>& near, LocalCertificate& counters) const {
        Rerank r = kernels.rerank(exact.packed, view.triangle_index, p, winner, slack.radius(best_q), near.slot, near.q,
                                  near.count, near.dropped);
        if (r.overflow) {
            AllNear all{slack, {}, {}};
            const Vec3f pt(p);
            BvhStats uncounted;
            const BvhHit<float> hit = kernels.closest_triangle_all(view, pt, seed_hit(view, winner, pt), uncounted, all);
            r = kernels.rerank(exact.packed, view.triangle_index, p, hit.slot, slack.radius(hit.distance_squared),
                               all.slot.data(), all.q.data(), int(all.slot.size()), NAN);
            r.reranked = true;
            ++counters.full_double;
        }
        ++counters.points;
        counters.reranked += r.reranked;
        return r.slot;
    }
};

/// Evaluates n points in order: pos(i) gives the position, emit(i, sample) takes the result.
/// In a chunk, point i is seeded with point i-1's triangle when `seeded` (any triangle is
/// a valid seed: its distance only bounds the search radius).
template <typename T, typename PositionFn, typename EmitFn>
void evaluate_points(const PreparedMesh& mesh, const TriangleBvh& bvh, const SamplerSign& sign, bool seeded, int threads, bool progress,
                     int64_t n, double point_coordinate, QueryCounters& counters, PositionFn pos, EmitFn emit) {
    const BvhView<T> view = bvh.view<T>();
    const MeshView<double> exact = mesh.buffers<double>().view();
    const Certifier<T> certifier(mesh, bvh, point_coordinate);
    const auto closest_triangle = cpu_kernels<T>().closest_triangle;  // the widest ISA the CPU has
    ProgressReporter reporter("sampling " + mesh.name() + " (bvh)", n, progress);
    parallel_for(n, kBvhChunk, threads, [&](int64_t begin, int64_t end) {
        BvhStats stats;
        LocalCertificate certified;
        int32_t previous = -1;
        for (int64_t i = begin; i < end; ++i) {
            const Vec3d p = pos(i);
            const Vec3<T> pt(p);
            const BvhHit<T> seed = seeded ? seed_hit(view, previous, pt) : BvhHit<T>{};
            int32_t slot;
            if constexpr (Certifier<T>::kActive) {
                CpuCertifiedNear near{certifier.slack, {}};
                const BvhHit<float> hit = certifier.kernels.closest_triangle(view, pt, seed, stats, near);
                previous = hit.slot;  // the float winner seeds best (its Q is the float search's)
                certifier.prefetch(near.near);
                slot = certifier.certify(view, p, hit.slot, hit.distance_squared, near.near, certified);
            } else {
                slot = previous = closest_triangle(view, pt, seed, stats).slot;
            }
            emit(i, sign.apply(signed_distance_to_triangle(exact, p, view.triangle_index[slot]), p));
        }
        certified.add_to(counters.certificate);
        counters.nodes += stats.nodes;
        counters.triangles += stats.triangles;
        reporter.advance(end - begin);
    });
}

/// One packet search (closest_triangles_packet.h): `slot` receives the winner of each of the
/// first `count` lanes, certified for float (`position`: the lanes' exact points).
template <typename T>
void search_packet(const BvhView<T>& view, const Certifier<T>& certifier, const Vec3d* position, int count,
                   BvhPacket<T, kCpuPacketLanes>& pk, BvhStats& stats, LocalCertificate& counters, int32_t* slot) {
    if constexpr (Certifier<T>::kActive) {
        CpuPacketCertifiedNear near;
        near.slack = certifier.slack;
        certifier.kernels.closest_triangles_packet(view, pk, stats, near);
        for (int k = 0; k < count; ++k) certifier.prefetch(near.near[k]);
        for (int k = 0; k < count; ++k)
            slot[k] = certifier.certify(view, position[k], pk.best_slot[k], pk.best_q[k], near.near[k], counters);
    } else {
        cpu_kernels<T>().closest_triangles_packet(view, pk, stats);
        for (int k = 0; k < count; ++k) slot[k] = pk.best_slot[k];
    }
}

/// The points of one brick of `block`: block-local indices and positions; lanes beyond
/// `count` repeat lane 0.
struct Brick {
    int64_t local[kBrick];
    Vec3d position[kBrick];
    int count = 0;
};

Brick brick_points(const Lattice& lattice, const GridBlock& block, const Int3& bricks, int64_t b) {
    const Int3 r = block.resolution;
    const int bi = int(b % bricks.x), bj = int((b / bricks.x) % bricks.y), bk = int(b / (int64_t(bricks.x) * bricks.y));
    Brick out;
    for (int k = 0; k < kBrick; ++k) {
        const int i = bi * kBrickX + k % kBrickX, j = bj * kBrickY + (k / kBrickX) % kBrickY, l = bk * kBrickZ + k / (kBrickX * kBrickY);
        if (i >= r.x || j >= r.y || l >= r.z) continue;
        out.local[out.count] = i + int64_t(r.x) * (j + int64_t(r.y) * l);
        out.position[out.count] = lattice.position_of_coords(block.coords(out.local[out.count]));
        ++out.count;
    }
    for (int k = out.count; k < kBrick; ++k) {
        out.local[k] = out.local[0];
        out.position[k] = out.position[0];
    }
    return out;
}

/// Seeds each lane of `pk` (seeded by seed_packet()) with the winner of the nearest lane of
/// the brick before it in y, `below` (that brick's winners; -1: none), where that triangle is
/// nearer: a tighter first radius. Any triangle is a valid seed (its distance only bounds the
/// search), so the result does not change.
template <typename T>
void improve_seeds_from_below(const BvhView<T>& view, const int32_t* below, BvhPacket<T, kBrick>& pk) {
    for (int k = 0; k < kBrick; ++k) {
        const int i = k % kBrickX, l = k / (kBrickX * kBrickY);
        const int32_t s = below[i + kBrickX * (kBrickY - 1) + kBrickX * kBrickY * l];
        if (s < 0 || s == pk.best_slot[k]) continue;
        const T q = squared_distance(view.packed[s], pk.x[k], pk.y[k], pk.z[k]);
        if (q < pk.best_q[k]) {
            pk.best_q[k] = pk.radius[k] = q;
            pk.best_slot[k] = s;
            pk.best_triangle[k] = view.triangle_index[s];
        }
    }
}

/// The narrow band's brick skip (SamplerOptions::band_width). The exact distance is
/// 1-Lipschitz: a probe at c with exact distance D proves |d(p)| >= D - |p - c| for every p,
/// so every point of a brick within D - w - margin of c lies outside the band and needs no
/// nearest-triangle search. The margin covers the search's near-ties (D is the distance to
/// the triangle the T search chose, which may exceed the true minimum by a few ulps of T).
struct BandSkip {
    double width = 0;  ///< 0: no band, every brick computed
    /// The pseudonormal sign of a solid (closed, manifold, oriented, one shell, no
    /// self-intersections: choose_sign_mode's conditions) is the side of the solid, constant on
    /// a ball that does not reach the surface: the probe's sign is every point's there.
    bool probe_sign = false;
    /// Winding mode: each skipped point gets its own winding number's side, as the full run.
    const WindingSign* winding = nullptr;
    double relative_margin = 0;  ///< of D + the coordinates' magnitude
    double coordinate_scale = 0; ///< largest |coordinate| of the mesh's box
    bool enabled() const { return width > 0 && (probe_sign || winding != nullptr); }
};

struct BandCounters {
    std::atomic<int64_t> probes{0}, bricks_skipped{0}, points_skipped{0};
};

/// The ball of the last probe of a chunk: points within `clear` of `centre` are outside the band.
struct ProbeBall {
    Vec3d centre{};
    double clear = -1;  ///< D - w - margin; < 0: no ball
    bool negative = false;
};

bool brick_in_ball(const Brick& br, const ProbeBall& ball) {
    if (!(ball.clear > 0)) return false;
    for (int k = 0; k < br.count; ++k)
        if (!(length(br.position[k] - ball.centre) < ball.clear)) return false;
    return true;
}

/// Evaluates every point of `block` brick by brick (closest_triangles_packet.h); each lane
/// is seeded with the triangle of the same lane of the previous brick along x. With a band,
/// a brick that a probe proves outside it is handed to emit_outside(local, negative) point
/// by point without a search.
template <typename T, typename EmitFn, typename OutsideFn>
void evaluate_bricks(const PreparedMesh& mesh, const TriangleBvh& bvh, const SamplerSign& sign, const Lattice& lattice, const GridBlock& block,
                     int threads, bool progress, const BandSkip& band, QueryCounters& counters, BandCounters& band_counters,
                     EmitFn emit, OutsideFn emit_outside) {
    const BvhView<T> view = bvh.view<T>();
    const MeshView<double> exact = mesh.buffers<double>().view();
    const Certifier<T> certifier(mesh, bvh, largest_lattice_coordinate(lattice));
    const auto closest_triangle = cpu_kernels<T>().closest_triangle;  // the probes': plain, the widest ISA
    const Int3 r = block.resolution;
    const Int3 bricks{(r.x + kBrickX - 1) / kBrickX, (r.y + kBrickY - 1) / kBrickY, (r.z + kBrickZ - 1) / kBrickZ};
    const int64_t n = int64_t(bricks.x) * bricks.y * bricks.z;
    ProgressReporter reporter("sampling " + mesh.name() + " (bvh)", block.count(), progress);
    // Chunks are whole rows of bricks, so that a brick can take its seeds from the brick
    // before it in x or, first in its row, from the first brick of the row before (2 spacings
    // away in y, not the end of that row), and reuse the probe of the brick beside it in x
    // and of the one below it in y (column_ball).
    const int64_t chunk = int64_t(bricks.x) * kChunkRows;
    parallel_for(n, chunk, threads, [&](int64_t begin, int64_t end) {
        BvhStats stats;
        LocalCertificate certified;
        int32_t seed[kBrick], row_seed[kBrick];
        for (int k = 0; k < kBrick; ++k) seed[k] = row_seed[k] = -1;
        int32_t probe_seed = -1;
        ProbeBall ball;
        std::vector<ProbeBall> column_ball(band.enabled() ? size_t(bricks.x) : 0);
        std::vector<int32_t> below(size_t(bricks.x) * kBrick, -1);  // each column's winners in the row before
        PacketSign packet_sign(sign);
        int64_t done = 0, probes = 0, skipped_bricks = 0, skipped_points = 0;
        for (int64_t b = begin; b < end; ++b) {
            const Brick br = brick_points(lattice, block, bricks, b);
            done += br.count;
            const bool row_start = b % bricks.x == 0;
            if (row_start)
                for (int k = 0; k < kBrick; ++k) seed[k] = row_seed[k];
            if (band.enabled()) {
                ProbeBall& below = column_ball[size_t(b % bricks.x)];
                if (!brick_in_ball(br, ball) && brick_in_ball(br, below)) ball = below;
                if (!brick_in_ball(br, ball)) {  // probe at the brick's centre
                    Vec3d c(0.0);
                    for (int k = 0; k < br.count; ++k) c = c + br.position[k];
                    c = c * (1.0 / br.count);
                    const Vec3<T> pt(c);
                    const BvhHit<T> hit = closest_triangle(view, pt, seed_hit(view, probe_seed, pt), stats);
                    probe_seed = hit.slot;
                    // The probe needs only a distance bound, which its margin covers: not certified.
                    const SignedDistanceSample<double> s = signed_distance_to_triangle(exact, c, view.triangle_index[hit.slot]);
                    const double d = std::abs(s.distance);
                    const double margin = band.relative_margin * (d + band.coordinate_scale + std::abs(c.x) + std::abs(c.y) + std::abs(c.z));
                    ball = {c, d - band.width - margin, s.distance < 0};
                    below = ball;
                    ++probes;
                }
                bool skip = brick_in_ball(br, ball);
                // A solid's inside never leaves its box: a point outside the box in an "inside"
                // ball means the mesh is not the solid assumed, so the brick is computed.
                if (skip && band.winding == nullptr && ball.negative)
                    for (int k = 0; k < br.count; ++k) skip = skip && !exact.outside_box(br.position[k]);
                if (skip) {
                    for (int k = 0; k < br.count; ++k)
                        emit_outside(br.local[k], band.winding ? band.winding->inside(br.position[k]) : ball.negative);
                    ++skipped_bricks;
                    skipped_points += br.count;
                    continue;
                }
            }
            BvhPacket<T, kBrick> pk;
            for (int k = 0; k < kBrick; ++k) {
                pk.x[k] = T(br.position[k].x);
                pk.y[k] = T(br.position[k].y);
                pk.z[k] = T(br.position[k].z);
            }
            seed_packet(view, seed, pk);
            int32_t* column_below = &below[size_t(b % bricks.x) * kBrick];
            improve_seeds_from_below(view, column_below, pk);
            int32_t slot[kBrick];
            search_packet(view, certifier, br.position, br.count, pk, stats, certified, slot);
            for (int k = 0; k < kBrick; ++k) column_below[k] = pk.best_slot[k];
            packet_sign.prepare(br.position, br.count);
            for (int k = 0; k < br.count; ++k)
                emit(br.local[k], packet_sign.apply(signed_distance_to_triangle(exact, br.position[k],
                                                                                view.triangle_index[slot[k]]),
                                                    k, br.position[k]));
            // The next brick's lanes start from this brick's last column in x, (1 to 4
            // spacings away rather than 4): a tighter first radius.
            for (int k = 0; k < kBrick; ++k) seed[k] = pk.best_slot[k - k % kBrickX + kBrickX - 1];
            if (row_start)
                for (int k = 0; k < kBrick; ++k) row_seed[k] = pk.best_slot[k];
        }
        certified.add_to(counters.certificate);
        counters.nodes += stats.nodes;
        counters.triangles += stats.triangles;
        band_counters.probes += probes;
        band_counters.bricks_skipped += skipped_bricks;
        band_counters.points_skipped += skipped_points;
        reporter.advance(done);
    });
}

/// Points per packet of an arbitrary point list: 16, as lattice bricks (8 and 32 measured
/// slower on the dragon's uniform and near-surface sets: tests/benchmarks/bench_bvh.cpp).
constexpr int kPointPacket = kBrick;

/// Morton order of arbitrary points: the indices of `points` sorted by the Morton key of
/// their cell in the points' bounding box (2^10 cells per axis: finer cells change nothing
/// for packets of 16), ties in input order. An LSD radix sort over the 30 key bits (four
/// 8-bit passes), stable, so the order is deterministic.
std::vector<uint32_t> morton_order(const std::vector<Vec3d>& points, int threads) {
    const size_t n = points.size();
    Vec3d lo = points[0], hi = points[0];
    for (const Vec3d& p : points) {
        lo = component_min(lo, p);
        hi = component_max(hi, p);
    }
    const double extent = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
    const double inv_extent = extent > 0 ? 1.0 / extent : 0.0;
    // key (top 30 of 63 bits) << 32 | index: sorting the word sorts by key, then by index.
    std::vector<uint64_t> items(n), scratch(n);
    parallel_for(int64_t(n), 1 << 14, threads, [&](int64_t b, int64_t e) {
        for (int64_t i = b; i < e; ++i) {
            const Vec3d& p = points[size_t(i)];
            const uint64_t key = morton_key_of_point(p.x, p.y, p.z, lo.x, lo.y, lo.z, inv_extent) >> 33;
            items[size_t(i)] = key << 32 | uint64_t(i);
        }
    });
    for (int pass = 0; pass < 4; ++pass) {
        const int shift = 32 + 8 * pass;
        size_t count[257] = {};
        for (uint64_t v : items) ++count[((v >> shift) & 0xff) + 1];
        for (int d = 0; d < 256; ++d) count[d + 1] += count[d];
        for (uint64_t v : items) scratch[count[(v >> shift) & 0xff]++] = v;
        items.swap(scratch);
    }
    std::vector<uint32_t> order(n);
    for (size_t i = 0; i < n; ++i) order[i] = uint32_t(items[i]);
    return order;
}

/// Evaluates arbitrary points as Morton-ordered packets: the points are sorted by Morton key,
/// runs of kPointPacket consecutive sorted points share one packet traversal (as lattice bricks
/// do), and each result is written back at its input index. The packet search returns every
/// lane's own brute-force minimum with the same tie rule (closest_triangles_packet.h), and
/// the winner is evaluated exactly as the per-point path does, so the samples are bit for bit
/// those of evaluate_points; only the work shared between neighbours changes.
template <typename T, typename EmitFn>
void evaluate_point_packets(const PreparedMesh& mesh, const TriangleBvh& bvh, const SamplerSign& sign, const std::vector<Vec3d>& points,
                            int threads, bool progress, double point_coordinate, QueryCounters& counters, EmitFn emit) {
    const BvhView<T> view = bvh.view<T>();
    const MeshView<double> exact = mesh.buffers<double>().view();
    const int64_t n = int64_t(points.size());
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
                position[k] = points[order[size_t(first + (k < count ? k : 0))]];  // spare lanes repeat lane 0
                pk.x[k] = T(position[k].x);
                pk.y[k] = T(position[k].y);
                pk.z[k] = T(position[k].z);
            }
            seed_packet(view, seed, pk);
            int32_t slot[kPointPacket];
            search_packet(view, certifier, position, count, pk, stats, certified, slot);
            packet_sign.prepare(position, count);
            for (int k = 0; k < count; ++k) {
                const int64_t i = int64_t(order[size_t(first + k)]);
                const Vec3d& p = points[size_t(i)];
                emit(i, packet_sign.apply(signed_distance_to_triangle(exact, p, view.triangle_index[slot[k]]), k, p));
            }
            for (int k = 0; k < kPointPacket; ++k) seed[k] = pk.best_slot[k];
            done += count;
        }
        certified.add_to(counters.certificate);
        counters.nodes += stats.nodes;
        counters.triangles += stats.triangles;
        reporter.advance(done);
    });
}

class CpuBvhSampler final : public Sampler {
public:
    explicit CpuBvhSampler(const SamplerOptions& options) : options_(options), sign_(options.sign) {
        kernel_ = kernel_from_name(kCpuBvhKernels, options.kernel, "CPU BVH");
        active_cpu_kernels();  // a bad SDF_CPU_ISA is reported here, before any work
    }

    std::string name() const override { return std::string("cpu/bvh/") + kernel_name(); }

    SampledField sample_slab(const PreparedMesh& mesh, const Lattice& lattice, const LatticeSlab& slab) override {
        return options_.precision == Precision::Float ? sample_as<float>(mesh, lattice, slab)
                                                      : sample_as<double>(mesh, lattice, slab);
    }

    std::vector<PointSample> query(const PreparedMesh& mesh, const std::vector<Vec3d>& points) override {
        require_search_range(mesh, points, options_.precision);
        std::vector<PointSample> out(points.size());
        const auto bvh = mesh.bvh();
        sign_.prepare(mesh);
        QueryCounters counters;
        auto run = [&](auto zero) {
            using T = decltype(zero);
            auto emit = [&](int64_t i, const SignedDistanceSample<double>& s) {
                out[size_t(i)] = point_sample(mesh, s.distance, s.gradient, s.triangle);
            };
            const double coordinate = largest_coordinate(points, options_.threads);
            if (kernel_ == BvhKernel::Brick && points.size() < (size_t(1) << 32))  // 32-bit indices in the sort
                evaluate_point_packets<T>(mesh, *bvh, sign_, points, options_.threads, options_.progress, coordinate, counters, emit);
            else
                evaluate_points<T>(mesh, *bvh, sign_, seeded(), options_.threads, options_.progress, int64_t(points.size()),
                                   coordinate, counters, [&](int64_t i) { return points[size_t(i)]; }, emit);
        };
        if (options_.precision == Precision::Float) run(0.0f); else run(0.0);
        record_certificate(query_timings_, counters.certificate);
        return out;
    }

private:
    const char* kernel_name() const { return sdf::kernel_name(kCpuBvhKernels, kernel_); }
    /// "seeded" queries point lists one by one, each seeded with the previous point's
    /// triangle; "brick" sorts them into Morton-ordered packets (evaluate_point_packets).
    bool seeded() const { return kernel_ != BvhKernel::Unseeded; }

    template <typename T>
    SampledField sample_as(const PreparedMesh& mesh, const Lattice& lattice, const LatticeSlab& slab) {
        const auto start = std::chrono::steady_clock::now();
        bool built = false;
        const auto bvh = mesh.bvh(&built);  // the mesh's own, built once
        sign_.prepare(mesh);  // over the same BVH: only the winding moments are added
        const auto query_start = std::chrono::steady_clock::now();
        SampledField field = unfilled_field(mesh, lattice, slab, options_.precision);
        GridBlock blocks[kMaxSamplingBlocks];
        const int nblocks = slab_sampling_blocks(lattice, options_.bcc_strategy, slab, blocks);
        const double w = options_.band_width;
        const BandSkip band = band_skip(mesh, w);
        int64_t computed = 0;
        QueryCounters counters;
        BandCounters band_counters;
        for (int b = 0; b < nblocks; ++b) {
            const GridBlock block = blocks[b];
            auto emit = [&](int64_t i, const SignedDistanceSample<double>& s) {
                const int64_t out = block.output_index(lattice, i);
                if (out < 0) return;  // strategy A: not a BCC point
                if (outside_band(s.distance, w)) store_outside_band(field, out, std::signbit(s.distance), w);
                else store_sample(field, out, mesh, s.distance, s.gradient, s.triangle);
            };
            auto emit_outside = [&](int64_t i, bool negative) {
                const int64_t out = block.output_index(lattice, i);
                if (out >= 0) store_outside_band(field, out, negative, w);
            };
            if (kernel_ == BvhKernel::Brick)
                evaluate_bricks<T>(mesh, *bvh, sign_, lattice, block, options_.threads, options_.progress, band, counters,
                                   band_counters, emit, emit_outside);
            else
                evaluate_points<T>(mesh, *bvh, sign_, seeded(), options_.threads, options_.progress, block.count(),
                                   largest_lattice_coordinate(lattice), counters,
                                   [&](int64_t i) { return lattice.position_of_coords(block.coords(i)); }, emit);
            computed += block.count();
        }
        computed -= band_counters.points_skipped;
        const auto now = std::chrono::steady_clock::now();
        field.timings.total = std::chrono::duration<double>(now - start).count();
        field.timings.kernel = std::chrono::duration<double>(now - query_start).count();
        // Brute-force-equivalent pairs, so pairs/s compares with the brute-force samplers.
        field.timings.point_triangle_pairs = double(computed) * double(mesh.triangles().size());
        nlohmann::json bvh_info = bvh->stats.to_json();
        bvh_info["built_by_this_call"] = built;
        bvh_info["node_visits_per_point"] = computed > 0 ? double(counters.nodes) / double(computed) : 0.0;
        bvh_info["point_triangle_tests_per_point"] = computed > 0 ? double(counters.triangles) / double(computed) : 0.0;
        field.sampler = sampler_provenance("cpu", "bvh", kernel_name(), options_, lattice, computed, sign_);
        field.sampler.details["threads"] = resolve_thread_count(options_.threads);
        field.sampler.details["bvh"] = bvh_info;
        record_certificate(field.timings, counters.certificate);
        field.sampler.search_certificate =
            certificate_provenance(options_.precision == Precision::Float, true, counters.certificate);
        if (w > 0) {
            BandReport info = narrow_band_provenance(
                w, count_narrow_band(field), band.enabled() ? "bricks skipped by the distance bound" : "post-processed");
            info.counts_skips = true;
            info.probes = band_counters.probes.load();
            info.bricks_skipped = band_counters.bricks_skipped.load();
            info.points_skipped = band_counters.points_skipped.load();
            field.sampler.band = info;
        }
        return field;
    }

    /// The brick skip of a band of width w: with the winding sign (each point's own), or
    /// with the pseudonormal sign where the mesh is the solid that makes it one side per
    /// ball; a pseudonormal sign requested on any other mesh computes every point (and
    /// bands them afterwards), as does the "seeded"/"unseeded" kernel.
    BandSkip band_skip(const PreparedMesh& mesh, double w) const {
        require_band_width(w, "sampler band_width");
        BandSkip band;
        band.width = w;
        if (w <= 0) return band;
        band.winding = sign_.winding() ? sign_.winding_sign() : nullptr;
        band.probe_sign = !sign_.winding() && choose_sign_mode(mesh.report(), SignMode::Auto).mode == SignMode::Pseudonormal;
        // Float searches choose among triangles within a few ulps (2^-24) of the minimum.
        band.relative_margin = options_.precision == Precision::Float ? 1e-5 : 1e-12;
        const MeshView<double> exact = mesh.buffers<double>().view();
        for (const Vec3d& v : {exact.box_lo, exact.box_hi})
            band.coordinate_scale = std::max({band.coordinate_scale, std::abs(v.x), std::abs(v.y), std::abs(v.z)});
        return band;
    }

    SamplerOptions options_;
    BvhKernel kernel_ = BvhKernel::Brick;
    SamplerSign sign_;
};

}  // namespace

std::unique_ptr<Sampler> make_cpu_bvh_sampler(const SamplerOptions& options) {
    return std::make_unique<CpuBvhSampler>(options);
}

}  // namespace sdf
