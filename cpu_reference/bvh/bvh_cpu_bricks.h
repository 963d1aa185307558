/// @file bvh_cpu_bricks.h
/// @brief The CPU BVH sampler's lattice path (kernel "brick"): the lattice in bricks of
/// 4 x 2 x 2 points, each one packet traversal seeded by its neighbours, and the narrow
/// band's brick skip (a probe's distance proves a brick outside the band).
#pragma once

#include <algorithm>
#include <vector>

#include "cpu_reference/bvh/bvh_cpu_search.h"
#include "kernels/lattice/band_sides.h"
#include "kernels/lattice/sampling_grid.h"

namespace sdf::cpu_bvh {

/// The points of one brick of `block`: block-local indices and positions; lanes beyond
/// `count` repeat lane 0.
struct Brick {
    int64_t local[kBrick];
    Vec3d position[kBrick];
    int count = 0;
};

inline Brick brick_points(const Lattice& lattice, const GridBlock& block, const Int3& bricks, int64_t b) {
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
    /// The search's nearest triangle may be a sliver's neighbour up to this much farther than
    /// the true nearest (FloatSearchBound::sliver_reach_*): the probe's D is lowered by it.
    double sliver_reach = 0;
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
    int triangle = -1;  ///< the probe's nearest (prepared-mesh index): the winding table's start
    double distance = 0;  ///< the probe's |distance| to it
    int side = -1;        ///< winding sign: the ball's side (1 inside, 0 outside); -1 not asked, -2 undecided
};

inline bool brick_in_ball(const Brick& br, const ProbeBall& ball) {
    if (!(ball.clear > 0)) return false;
    for (int k = 0; k < br.count; ++k)
        if (!(length(br.position[k] - ball.centre) < ball.clear)) return false;
    return true;
}

/// Evaluates every point of `block` brick by brick (closest_triangles_packet.h); each lane
/// is seeded with the triangle of the same lane of the previous brick along x. With a band,
/// a brick that a probe proves outside it is handed to emit_outside(local, side) point by
/// point without a search (side: kBandSideInside or kBandSideOutside).
template <typename T, typename EmitFn, typename OutsideFn>
void evaluate_bricks(const PreparedMesh& mesh, const TriangleBvh& bvh, const SamplerSign& sign, const Lattice& lattice, const GridBlock& block,
                     int threads, bool progress, const BandSkip& band, QueryCounters& counters, BandCounters& band_counters,
                     EmitFn emit, OutsideFn emit_outside) {
    const BvhView<T> view = bvh.view<T>();
    const MeshView<double> exact = mesh.buffers<double>().view();
    const Certifier<T> certifier(mesh, bvh, largest_lattice_coordinate(lattice));
    const auto closest_triangle = cpu_kernels<T>().closest_triangle;  // the probes': plain, the widest ISA
    const BvhView<double> exact_view = bvh.view<double>();
    const auto closest_double = cpu_kernels<double>().closest_triangle;  // the probes' side
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
                    // The distance needs only a bound, which the margin covers; the side needs
                    // the double search's triangle (the points' own): a float near-tie may pick
                    // a triangle whose pseudonormal puts c on the other side (a sliver's edge an
                    // ulp beside a sharp edge), and the ball would carry that side.
                    int32_t slot = hit.slot;
                    if constexpr (std::is_same_v<T, float>)
                        slot = closest_double(exact_view, c, seed_hit(exact_view, hit.slot, c), stats).slot;
                    const SignedDistanceSample<double> s = signed_distance_to_triangle(exact, c, view.triangle_index[slot]);
                    const double d = std::abs(s.distance);
                    const double margin = band.relative_margin * (d + band.coordinate_scale + std::abs(c.x) + std::abs(c.y) + std::abs(c.z));
                    ball = {c, d - band.width - margin - band.sliver_reach, s.distance < 0, s.triangle, d};
                    below = ball;
                    ++probes;
                }
                bool skip = brick_in_ball(br, ball);
                // A solid's inside never leaves its box: a point outside the box in an "inside"
                // ball means the mesh is not the solid assumed, so the brick is computed.
                if (skip && band.winding == nullptr && ball.negative)
                    for (int k = 0; k < br.count; ++k) skip = skip && !exact.outside_box(br.position[k]);
                if (skip) {
                    // No surface within the ball: a closed mesh's winding number is one integer
                    // there, its centre's (PacketSign::ball_side). Every point of the ball is
                    // more than w from the surface.
                    if (band.winding && ball.side == -1) {
                        bool in = false;
                        ball.side = packet_sign.ball_side(ball.centre, ball.triangle, ball.distance, in) ? (in ? 1 : 0) : -2;
                    }
                    if (band.winding && ball.side >= 0) packet_sign.count_surface(br.count);
                    for (int k = 0; k < br.count; ++k)
                        emit_outside(br.local[k], (band.winding ? (ball.side >= 0 ? ball.side == 1
                                                                                  : packet_sign.inside(br.position[k], ball.triangle, band.width))
                                                                : ball.negative)
                                                      ? kBandSideInside : kBandSideOutside);
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
            LaneNear near[kBrick];
            search_packet(view, certifier, br.position, br.count, pk, stats, certified, slot, near);
            for (int k = 0; k < kBrick; ++k) column_below[k] = pk.best_slot[k];
            SignedDistanceSample<double> sample[kBrick];
            for (int k = 0; k < br.count; ++k) sample[k] = signed_distance_to_triangle(exact, br.position[k], view.triangle_index[slot[k]]);
            packet_sign.prepare(br.position, sample, near, br.count);
            for (int k = 0; k < br.count; ++k) emit(br.local[k], packet_sign.apply(sample[k], k, br.position[k]));
            // The next brick's lanes start from this brick's last column in x, (1 to 4
            // spacings away rather than 4): a tighter first radius.
            for (int k = 0; k < kBrick; ++k) seed[k] = pk.best_slot[k - k % kBrickX + kBrickX - 1];
            if (row_start)
                for (int k = 0; k < kBrick; ++k) row_seed[k] = pk.best_slot[k];
        }
        certified.add_to(counters.certificate);
        packet_sign.add_to(counters.winding);
        counters.nodes += stats.nodes;
        counters.triangles += stats.triangles;
        band_counters.probes += probes;
        band_counters.bricks_skipped += skipped_bricks;
        band_counters.points_skipped += skipped_points;
        reporter.advance(done);
    });
}

}  // namespace sdf::cpu_bvh
