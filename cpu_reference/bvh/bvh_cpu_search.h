/// @file bvh_cpu_search.h
/// @brief The CPU BVH sampler's searches (bvh_cpu.h), shared by its lattice bricks
/// (bvh_cpu_bricks.h) and its point packets (bvh_cpu_points.h): the certified float search's
/// context, the sign of a packet's lanes, the one-point path and the packet search. Included
/// by the sampler's translation units only.
#pragma once

#include <atomic>
#include <cmath>
#include <type_traits>

#include "core/bvh/triangle_bvh.h"
#include "core/parallel/parallel_for.h"
#include "core/parallel/progress.h"
#include "core/sampling/certified_search.h"
#include "core/sampling/sampler_sign.h"
#include "cpu_reference/bvh/bvh_cpu.h"
#include "cpu_reference/dispatch/cpu_kernels.h"
#include "kernels/distance/signed_distance.h"

namespace sdf::cpu_bvh {

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

/// A run's search counts, summed over threads: BVH nodes visited, point-triangle tests, the
/// certificate's counts (the run's own, certified_search.h) and the winding sign's.
struct QueryCounters {
    QueryCounters(CertificateCounters& c, SharedWindingCounts& w) : certificate(c), winding(w) {}
    std::atomic<int64_t> nodes{0}, triangles{0};
    CertificateCounters& certificate;
    SharedWindingCounts& winding;
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

/// A point's candidates for the winding sign's nearest_side() (surface_side.h), from
/// Certifier::certify: the triangles the certified search could not rule out, and the squared
/// distance every other triangle exceeds. count 0: unknown (double searches, overflows).
struct LaneNear {
    int32_t triangle[kCpuNearCandidates + 1];
    int count = 0;
    double beyond_squared = 0;
    NearTriangles view() const { return {triangle, count, beyond_squared}; }
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
    /// candidates; counts what it took. `lane` receives the candidates' triangles and a
    /// squared distance X that every other triangle exceeds in exact arithmetic
    /// (beyond_candidates_squared, search_certificate.h).
    int32_t certify(const BvhView<float>& view, const Vec3d& p, int32_t winner, float best_q,
                    const NearCandidates<float, kCpuNearCandidates>& near, LocalCertificate& counters, LaneNear& lane) const {
        const float radius = slack.radius(best_q);
        Rerank r = kernels.rerank(exact.packed, view.triangle_index, p, winner, radius, near.slot, near.q, near.count,
                                  near.dropped);
        lane.count = 0;
        if (!r.overflow) {
            lane.triangle[lane.count++] = view.triangle_index[winner];
            for (int i = 0; i < near.count; ++i)
                if (near.slot[i] != winner && near.q[i] <= radius) lane.triangle[lane.count++] = view.triangle_index[near.slot[i]];
            lane.beyond_squared = beyond_candidates_squared(slack, best_q);
        } else {  // more candidates than kept (a vertex of many triangles): the lane knows none
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

/// The sign of a packet's lanes. With the samplers' winding sign (certified: the exact side)
/// a lane whose closest triangle the mesh's table vouches for takes its side from it
/// (surface_side.h); the sides of the other lanes come from one traversal per stage of the
/// certified ladder (certified_winding_packet.h), each lane's side and stage what
/// WindingSign::side() gives its point; uncertified (measurements), the fast winding numbers
/// of all kCpuPacketLanes lanes come from one traversal (fast_winding_packet.h), each lane's
/// value the bits WindingSign::side() computes; otherwise each point gets
/// SamplerSign::apply(). The points are counted by stage here, and added to the run's
/// counters by add_to() (once per chunk).
class PacketSign {
public:
    explicit PacketSign(const SamplerSign& sign) : sign_(sign), surface_(sign.surface_view()) {
        winding_ = sign.winding() ? sign.winding_sign() : nullptr;
    }

    /// Evaluates the sides of the packet's points `position`, whose samples (pseudonormal
    /// sign; triangle -1 where there is none) are `sample`: the first `count` lanes are
    /// points (counted), the others spare. `near[k]`: lane k's candidates (Certifier::certify).
    void prepare(const Vec3d* position, const SignedDistanceSample<double>* sample, const LaneNear* near, int count) {
        if (winding_ == nullptr) return;
        const WindingSignOptions& o = winding_->options();
        if (o.certify && surface_.front_winding == nullptr) {  // no table: every lane takes the ladder
            WindingSide side[kCpuPacketLanes];
            certified_kernel_(winding_->view(), position, count, o.accuracy, o.certification, side);
            for (int k = 0; k < count; ++k) {
                inside_[k] = side[k].inside;
                counts_.add(side[k].stage);
            }
            return;
        }
        if (o.certify) {
            Vec3d ladder_position[kCpuPacketLanes];
            int ladder_lane[kCpuPacketLanes];
            int ladder = 0;
            for (int k = 0; k < count; ++k) {
                if (o.nearest_sides && nearest_side(surface_, winding_->view(), position[k], sample[k].triangle, sample[k].distance,
                                                    sample[k].closest_point, near[k].view(), inside_[k])) {
                    counts_.add(WindingStage::Nearest);
                    continue;
                }
                if (surface_side(surface_, winding_->view(), position[k], sample[k].triangle, sample[k].distance, inside_[k])) {
                    counts_.add(WindingStage::Surface);
                    continue;
                }
                ladder_lane[ladder] = k;
                ladder_position[ladder++] = position[k];
            }
            if (ladder == 0) return;
            for (int j = ladder; j < kCpuPacketLanes; ++j) ladder_position[j] = ladder_position[0];  // spare lanes
            WindingSide side[kCpuPacketLanes];
            certified_kernel_(winding_->view(), ladder_position, ladder, o.accuracy, o.certification, side);
            for (int j = 0; j < ladder; ++j) {
                inside_[ladder_lane[j]] = side[j].inside;
                counts_.add(side[j].stage);
            }
            return;
        }
        double px[kCpuPacketLanes], py[kCpuPacketLanes], pz[kCpuPacketLanes], w[kCpuPacketLanes];
        for (int k = 0; k < kCpuPacketLanes; ++k) {
            px[k] = position[k].x;
            py[k] = position[k].y;
            pz[k] = position[k].z;
        }
        kernel_(winding_->view(), px, py, pz, o.accuracy, w);
        for (int k = 0; k < kCpuPacketLanes; ++k) inside_[k] = w[k] > 0.5;  // WindingSign::side()
        counts_.add(WindingStage::Fast, count);
    }

    /// Lane k's sample `s` at p with its sign (after prepare() of its packet).
    SignedDistanceSample<double> apply(const SignedDistanceSample<double>& s, int k, const Vec3d& p) {
        return winding_ != nullptr ? with_sign(s, inside_[k]) : sign_.apply(s, p, counts_);
    }

    /// The side of a ball without surface around `centre` (a narrow band's probe, `distance`
    /// from the surface, `triangle` its nearest), uncounted; false where the table cannot
    /// decide. With a table the mesh is closed, so the winding number is one integer in the
    /// ball and the centre's side is every point's.
    bool ball_side(const Vec3d& centre, int triangle, double distance, bool& inside) const {
        return winding_->options().certify && surface_side(surface_, winding_->view(), centre, triangle, distance, inside);
    }
    /// Counts n points whose side the table gave (a ball's).
    void count_surface(int n) { counts_.add(WindingStage::Surface, n); }

    /// The side of one point outside the packets (a narrow band's skipped brick), counted:
    /// by the table from `triangle` (any triangle gives the exact side, surface_side.h; a
    /// nearby one keeps the segment short), `distance` a lower bound on p's distance to the
    /// surface; else by the ladder.
    bool inside(const Vec3d& p, int triangle, double distance) {
        bool in = false;
        if (winding_->options().certify && surface_side(surface_, winding_->view(), p, triangle, distance, in)) {
            counts_.add(WindingStage::Surface);
            return in;
        }
        const WindingSide side = winding_->side(p);
        counts_.add(side.stage);
        return side.inside;
    }

    /// Adds the points counted so far to `run` and starts again.
    void add_to(SharedWindingCounts& run) {
        run.add(counts_);
        counts_ = {};
    }

private:
    const SamplerSign& sign_;
    SurfaceSideView surface_;
    const WindingSign* winding_ = nullptr;  ///< non-null: packets of winding numbers
    WindingPacketFn kernel_ = active_cpu_kernels().winding_numbers_packet;
    CertifiedWindingPacketFn certified_kernel_ = active_cpu_kernels().winding_sides_packet;
    bool inside_[kCpuPacketLanes] = {};
    WindingSignCounts counts_;
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
        WindingSignCounts signed_points;
        int32_t previous = -1;
        for (int64_t i = begin; i < end; ++i) {
            const Vec3d p = pos(i);
            LaneNear lane;
            const Vec3<T> pt(p);
            const BvhHit<T> seed = seeded ? seed_hit(view, previous, pt) : BvhHit<T>{};
            int32_t slot;
            if constexpr (Certifier<T>::kActive) {
                CpuCertifiedNear near{certifier.slack, {}};
                const BvhHit<float> hit = certifier.kernels.closest_triangle(view, pt, seed, stats, near);
                previous = hit.slot;  // the float winner seeds best (its Q is the float search's)
                certifier.prefetch(near.near);
                slot = certifier.certify(view, p, hit.slot, hit.distance_squared, near.near, certified, lane);
            } else {
                slot = previous = closest_triangle(view, pt, seed, stats).slot;
            }
            emit(i, sign.apply(signed_distance_to_triangle(exact, p, view.triangle_index[slot]), p, signed_points, lane.view()));
        }
        certified.add_to(counters.certificate);
        counters.winding.add(signed_points);
        counters.nodes += stats.nodes;
        counters.triangles += stats.triangles;
        reporter.advance(end - begin);
    });
}

/// One packet search (closest_triangles_packet.h): `slot` receives the winner of each of the
/// first `count` lanes, certified for float (`position`: the lanes' exact points), and `near`
/// the lane's candidates (Certifier::certify; none for double, whose search has no
/// certificate).
template <typename T>
void search_packet(const BvhView<T>& view, const Certifier<T>& certifier, const Vec3d* position, int count,
                   BvhPacket<T, kCpuPacketLanes>& pk, BvhStats& stats, LocalCertificate& counters, int32_t* slot, LaneNear* lanes) {
    if constexpr (Certifier<T>::kActive) {
        CpuPacketCertifiedNear near;
        near.slack = certifier.slack;
        certifier.kernels.closest_triangles_packet(view, pk, stats, near);
        for (int k = 0; k < count; ++k) certifier.prefetch(near.near[k]);
        for (int k = 0; k < count; ++k) {  // a lane of a bounded search may have found nothing (-1)
            lanes[k].count = 0;
            slot[k] = pk.best_slot[k] < 0 ? -1
                                          : certifier.certify(view, position[k], pk.best_slot[k], pk.best_q[k], near.near[k], counters, lanes[k]);
        }
    } else {
        cpu_kernels<T>().closest_triangles_packet(view, pk, stats);
        for (int k = 0; k < count; ++k) {
            slot[k] = pk.best_slot[k];
            lanes[k].count = 0;
        }
    }
}

}  // namespace sdf::cpu_bvh
