#include "core/sampling/sparse_band_sampler.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "core/host_memory.h"
#include "core/lattice/lattice_fitting.h"
#include "core/parallel/parallel_for.h"
#include "core/sampling/sampler.h"
#include "core/sampling/sampler_sign.h"
#include "core/sampling/search_range.h"
#include "core/sampling/sparse_band_outside.h"
#include "core/winding/winding_sign.h"

namespace sdf {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

/// Step 1: the blocks whose cells meet a triangle's box dilated by W and the slab within W of its plane.
BlockBits active_blocks(const PreparedMesh& mesh, const BandLayout& layout, double width) {
    BlockBits bits(layout.block_count());
    const Lattice& lattice = layout.lattice();
    const double h = lattice.spacing;
    const double dilation = width * (1 + 1e-9) + 1e-4 * h;
    const double eps = 1e-4;  // in spacings: the rounding of u below
    const std::vector<Vec3d>& v = mesh.vertices();
    for (int c = 0; c < layout.cosets(); ++c) {
        const BandCoset& s = layout.coset(c);
        const Vec3d o = lattice.position_of_coords(s.first);
        for (const Int3& t : mesh.triangles()) {
            int lo[3], hi[3];
            bool empty = false;
            for (int a = 0; a < 3; ++a) {
                const double tlo = std::min({v[size_t(t.x)][a], v[size_t(t.y)][a], v[size_t(t.z)][a]}) - dilation;
                const double thi = std::max({v[size_t(t.x)][a], v[size_t(t.y)][a], v[size_t(t.z)][a]}) + dilation;
                // Coset index u = (x - o) / h; block b's cell covers u in [8b, 8b + 8].
                const double ulo = (tlo - o[a]) / h - eps, uhi = (thi - o[a]) / h + eps;
                const double blo = std::ceil(ulo / kBandBlockDim - 1), bhi = std::floor(uhi / kBandBlockDim);
                const int n = s.blocks[a];
                lo[a] = int(std::max(0.0, std::min(blo, double(n))));
                hi[a] = int(std::max(-1.0, std::min(bhi, double(n - 1))));
                empty = empty || lo[a] > hi[a];
            }
            if (empty) continue;
            // Of those, the cells that meet the slab within W of the triangle's plane: a
            // triangle across its box (a diagonal one) leaves most of the box's cells beyond W.
            // Conservative: the cell's distance to the plane, |n.(centre - V0)| less the cell's
            // half extent along n, is taken within the dilation plus 1e-4 spacings and 2^-40 of
            // the magnitudes (the rounding of n and the dot products). A degenerate triangle
            // (no normal) keeps its box.
            const Vec3d a = v[size_t(t.x)], e0 = v[size_t(t.y)] - a, e1 = v[size_t(t.z)] - a;
            const Vec3d normal = cross(e0, e1);
            const double area2 = length(normal);
            // The normal's direction is off by about u |E0| |E1| / |E0 x E1| (a sliver's cross
            // product cancels): that times the cell's distance from V0 is added to the reach;
            // past 1e-3 rad (an extreme sliver) the box alone decides.
            const double tilt = 8 * 0x1p-53 * length(e0) * length(e1) / area2 + 8 * 0x1p-53;
            const bool slab = area2 > 0 && std::isfinite(area2) && tilt < 1e-3;
            const Vec3d n = slab ? normal / area2 : Vec3d(0.0);
            const double half = 0.5 * kBandBlockDim * h * (std::abs(n.x) + std::abs(n.y) + std::abs(n.z));
            const double magnitude = std::abs(a.x) + std::abs(a.y) + std::abs(a.z) + std::abs(o.x) + std::abs(o.y) + std::abs(o.z) +
                                     3 * kBandBlockDim * h * (double(s.blocks.x) + s.blocks.y + s.blocks.z);
            const double reach = dilation + half + 1e-4 * h + 0x1p-40 * magnitude;
            for (int z = lo[2]; z <= hi[2]; ++z)
                for (int y = lo[1]; y <= hi[1]; ++y)
                    for (int x = lo[0]; x <= hi[0]; ++x) {
                        if (slab) {
                            const double cell = 0.5 * kBandBlockDim * h;  // the cell's centre, from its first point
                            const Vec3d centre{o.x + (kBandBlockDim * x) * h + cell, o.y + (kBandBlockDim * y) * h + cell,
                                               o.z + (kBandBlockDim * z) * h + cell};
                            const Vec3d from = centre - a;
                            if (std::abs(dot(n, from)) > reach + tilt * (length(from) + kBandBlockDim * h)) continue;
                        }
                        bits.set(layout.block_id(c, {x, y, z}));
                    }
        }
    }
    return bits;
}

/// Queries `points` (lattice positions) in batches; f(first, results) per batch.
template <typename F>
void query_in_batches(const BoundSampler& sampler, const std::vector<Vec3d>& points, int64_t batch, SamplingTimings& total,
                      F&& f) {
    for (size_t first = 0; first < points.size(); first += size_t(batch)) {
        const size_t last = std::min(points.size(), first + size_t(batch));
        const std::vector<Vec3d> part(points.begin() + long(first), points.begin() + long(last));
        SamplingTimings t;
        const std::vector<PointSample> r = sampler.query(part, &t);
        total.kernel += t.kernel;
        total.upload += t.upload;
        total.download += t.download;
        total.certified_points += t.certified_points;
        total.reranked_points += t.reranked_points;
        total.full_double_points += t.full_double_points;
        f(first, r);
    }
}

}  // namespace

SparseBandField sample_sparse_band(const BoundSampler& sampler, const Lattice& lattice, double width,
                                   const SparseBandPlan& plan, const BandBlockKernel& blocks) {
    const Clock::time_point start = Clock::now();
    const PreparedMesh& mesh = sampler.mesh();
    require_search_range(mesh, lattice, plan.precision);
    if (plan.batch_points < kBandBlockPoints)
        throw std::invalid_argument("sparse band: batch_points must be at least " + std::to_string(kBandBlockPoints));
    // Every size is checked before it is allocated: first the two bitsets of one bit per
    // block (the active blocks, the inside tiles: 2 x 128 MiB at 8192^3), then, once the
    // active blocks are known, their channels.
    const std::string what = "the sparse band of " + lattice_notation(lattice);
    require_host_bytes(2 * uint64_t((BandLayout(lattice).block_count() + 63) / 64) * sizeof(uint64_t),
                       what + " (its per-block bitsets)");
    SparseBandField out(lattice, width, plan.precision, plan.channels);
    const BandLayout& layout = out.layout();
    nlohmann::json steps = nlohmann::json::object();

    // 1. Active blocks.
    Clock::time_point t = Clock::now();
    const BlockBits active = active_blocks(mesh, layout, width);
    const int64_t active_count = active.count();
    const uint64_t point_bytes = band_distance_type(plan.channels.distance_type).bytes + (plan.channels.gradient ? sizeof(Vec3d) : 0) +
                                 (plan.channels.closest_triangle ? sizeof(int32_t) : 0);
    require_host_bytes(uint64_t(active_count) * (kBandBlockPoints * point_bytes + sizeof(BandPointMask) + sizeof(int64_t)),
                       what + ": " + std::to_string(active_count) + " active blocks of " +
                           std::to_string(kBandBlockPoints) + " points, " + std::to_string(point_bytes) +
                           " bytes a point (" + channel_names(plan.channels).dump() + ")");
    out.active = active.set_bits();
    steps["find_blocks_seconds"] = seconds_since(t);

    // 2. Their points, batch by batch (batches of whole blocks).
    t = Clock::now();
    const size_t values = out.active.size() * kBandBlockPoints;
    const int64_t blocks_per_batch = plan.batch_points / kBandBlockPoints;
    int64_t points_computed = 0;
    if (blocks) {
        // The kernel writes every lattice point's values: allocated, not written (the fill
        // and the pages' first touch cost what a GPU's kernels do, 36 bytes a point), but
        // for the padding of the blocks at the lattice's far edges.
        out.distance.resize(values);
        if (plan.channels.gradient) out.gradient.resize(values);
        if (plan.channels.closest_triangle) out.closest_triangle.resize(values);
        out.band_mask.resize(out.active.size());  // the kernel writes every block's
        for (size_t a = 0; a < out.active.size(); ++a) {
            const BandBlockCoords b = layout.block_coords(out.active[a]);
            const Int3 n = layout.coset(b.coset).points;
            Int3 r{};
            for (int k = 0; k < 3; ++k) r[k] = std::min(kBandBlockDim, n[k] - b.block[k] * kBandBlockDim);
            points_computed += int64_t(r.x) * r.y * r.z;
            if (r.x == kBandBlockDim && r.y == kBandBlockDim && r.z == kBandBlockDim) continue;
            for (int local = 0; local < kBandBlockPoints; ++local) {
                const Int3 p = BandLayout::local_offset(local);
                if (p.x < r.x && p.y < r.y && p.z < r.z) continue;
                const size_t v = a * kBandBlockPoints + size_t(local);
                out.distance.set(v, width);
                if (plan.channels.gradient) out.gradient[v] = Vec3d(0.0);
                if (plan.channels.closest_triangle) out.closest_triangle[v] = kOutsideBandTriangle;
            }
        }
        // One call for every block: the kernel batches as its memory allows (a GPU uploads
        // the ids once).
        if (!out.active.empty()) blocks(out, 0, out.active.size());
    } else {
        out.distance.assign(values, width);
        if (plan.channels.gradient) out.gradient.assign(values, Vec3d(0.0));
        if (plan.channels.closest_triangle) out.closest_triangle.assign(values, kOutsideBandTriangle);
        out.band_mask.assign(out.active.size(), BandPointMask{});
    }
    for (size_t first = 0; !blocks && first < out.active.size(); first += size_t(blocks_per_batch)) {
        const size_t last = std::min(out.active.size(), first + size_t(blocks_per_batch));
        std::vector<Vec3d> points;
        std::vector<size_t> slot;  // value index of each point
        points.reserve((last - first) * kBandBlockPoints);
        slot.reserve((last - first) * kBandBlockPoints);
        for (size_t a = first; a < last; ++a)
            for (int local = 0; local < kBandBlockPoints; ++local) {
                if (layout.storage_index(out.active[a], local) < 0) continue;
                points.push_back(lattice.position_of_coords(layout.point_coords(out.active[a], local)));
                slot.push_back(a * kBandBlockPoints + size_t(local));
            }
        points_computed += int64_t(points.size());
        query_in_batches(sampler, points, int64_t(points.size()) + 1, out.timings, [&](size_t, const std::vector<PointSample>& r) {
            for (size_t i = 0; i < r.size(); ++i) {
                const size_t v = slot[i];
                if (outside_band(r[i].distance, width)) {
                    out.distance.set(v, std::signbit(r[i].distance) ? -width : width);  // store_outside_band's values
                } else {
                    out.distance.set(v, r[i].distance);
                    if (plan.channels.gradient) out.gradient[v] = r[i].gradient;
                    if (plan.channels.closest_triangle) out.closest_triangle[v] = r[i].triangle;
                    set_mask_bit(out.band_mask[v / kBandBlockPoints], int(v % kBandBlockPoints));
                }
            }
        });
    }
    steps["active_points_seconds"] = seconds_since(t);
    steps["active_points_by"] = blocks ? "the backend's block kernel" : "point queries";

    // 3. The outside.
    t = Clock::now();
    const SignModeChoice& sign = sampler.sign();
    const bool solid = choose_sign_mode(mesh.report(), SignMode::Auto).mode == SignMode::Pseudonormal;
    std::vector<BoundaryEdge> edges;
    std::unique_ptr<WindingSign> winding;
    OutsideRule rule = OutsideRule::Uniform;
    if (sign.mode == SignMode::Winding) {
        edges = boundary_edges(mesh);
        if (!edges.empty()) {
            rule = OutsideRule::WindingBound;
            winding = std::make_unique<WindingSign>(mesh, mesh.bvh(), SamplerSign::winding_options());
        }
    } else if (!solid) {
        rule = OutsideRule::PerPoint;
    }
    const size_t boundary_edge_count = edges.size();
    const OutsideCells classify = classify_outside(layout, active, rule, winding.get(), mesh, std::move(edges), plan.threads);
    const auto sign_cell = [&](const Cell& c, bool inside) {
        if (!inside) return;  // tiles start outside
        for (int z = c.lo.z; z < c.hi.z; ++z)
            for (int y = c.lo.y; y < c.hi.y; ++y)
                for (int x = c.lo.x; x < c.hi.x; ++x) out.set_tile_inside(layout.block_id(c.coset, {x, y, z}), true);
    };
    // The uniform cells' sides from their neighbours (sparse_band_outside.cpp), where the band is at least a
    // coset spacing wide and the sign is uniform off the surface; the others are queried, one
    // point each, at their first block's first point.
    std::vector<const Cell*> queried;
    int64_t cells_beside_the_band = 0;
    if (rule == OutsideRule::Uniform && width >= lattice.spacing) {
        const std::vector<signed char> sides = cell_sides_from_neighbours(layout, active, classify.uniform, out, plan.threads);
        for (size_t k = 0; k < classify.uniform.size(); ++k) {
            if (sides[k] < 0) {
                queried.push_back(&classify.uniform[k]);
                continue;
            }
            sign_cell(classify.uniform[k], sides[k] == 1);
            ++cells_beside_the_band;
        }
    } else {
        for (const Cell& c : classify.uniform) queried.push_back(&c);
    }
    std::vector<Vec3d> reps;
    reps.reserve(queried.size());
    for (const Cell* c : queried) reps.push_back(lattice.position_of_coords(layout.point_coords(layout.block_id(c->coset, c->lo), 0)));
    query_in_batches(sampler, reps, plan.batch_points, out.timings, [&](size_t first, const std::vector<PointSample>& r) {
        for (size_t i = 0; i < r.size(); ++i) sign_cell(*queried[first + i], std::signbit(r[i].distance));
    });
    // Blocks not proven uniform: every point's side, batch by batch; a block whose sides all
    // agree becomes a tile.
    int64_t per_point_points = 0;
    for (size_t first = 0; first < classify.per_point.size(); first += size_t(blocks_per_batch)) {
        const size_t last = std::min(classify.per_point.size(), first + size_t(blocks_per_batch));
        std::vector<Vec3d> points;
        std::vector<std::pair<size_t, int>> where;
        for (size_t b = first; b < last; ++b)
            for (int local = 0; local < kBandBlockPoints; ++local) {
                if (layout.storage_index(classify.per_point[b], local) < 0) continue;
                points.push_back(lattice.position_of_coords(layout.point_coords(classify.per_point[b], local)));
                where.push_back({b, local});
            }
        per_point_points += int64_t(points.size());
        std::vector<BandSignMask> masks(last - first, BandSignMask{});
        std::vector<int> inside(last - first, 0), total(last - first, 0);
        query_in_batches(sampler, points, int64_t(points.size()) + 1, out.timings, [&](size_t, const std::vector<PointSample>& r) {
            for (size_t i = 0; i < r.size(); ++i) {
                const size_t b = where[i].first - first;
                const int local = where[i].second;
                ++total[b];
                if (!std::signbit(r[i].distance)) continue;
                ++inside[b];
                masks[b][size_t(local >> 6)] |= uint64_t(1) << (local & 63);
            }
        });
        for (size_t b = first; b < last; ++b) {
            const int64_t id = classify.per_point[b];
            if (inside[b - first] == 0 || inside[b - first] == total[b - first]) {
                out.set_tile_inside(id, inside[b - first] > 0);
            } else {
                out.mixed_inside[size_t(out.add_mixed(id))] = masks[b - first];
            }
        }
    }
    steps["outside_seconds"] = seconds_since(t);

    // The report: the dense band's keys, and the sparse steps' counts.
    const SparseBandCounts counts = out.counts();
    BandReport band;
    band.width = width;
    band.points_in_band = counts.band_points;
    band.points_outside = lattice.num_points() - counts.band_points;
    band.how = "sparse: active blocks sampled, the outside signed per cell";
    out.sampler.backend = sampler.name();
    out.sampler.precision = precision_name(plan.precision);
    out.sampler.points_computed = points_computed + int64_t(reps.size()) + per_point_points;
    out.sampler.band = band;
    out.sampler.details["sign"] = {{"mode", sign_mode_name(sign.mode)}, {"reason", sign.reason}};
    const char* rule_name = rule == OutsideRule::Uniform ? "uniform off the surface"
                            : rule == OutsideRule::WindingBound ? "winding number bound (Biot-Savart)"
                                                                : "every point";
    out.sampler.details["sparse_band"] = {{"block", kBandBlockDim},
                                          {"blocks", counts.blocks},
                                          {"active_blocks", counts.active_blocks},
                                          {"active_points", counts.active_points},
                                          {"mixed_blocks", counts.mixed_blocks},
                                          {"tiles", counts.tiles},
                                          {"inside_tiles", counts.inside_tiles},
                                          {"uniform_cells", int64_t(classify.uniform.size())},
                                          {"uniform_cells_beside_the_band", cells_beside_the_band},
                                          {"cells_refused_by_evaluation", classify.refused_by_evaluation},
                                          {"cells_refused_by_gradient", classify.refused_by_gradient},
                                          {"points_signed_per_point", per_point_points},
                                          {"outside_rule", rule_name},
                                          {"channels", channel_names(plan.channels)},
                                          {"distance_type", band_distance_type(plan.channels.distance_type).name},
                                          {"boundary_edges", int64_t(boundary_edge_count)},
                                          {"steps", steps},
                                          {"memory_bytes", int64_t(out.memory_bytes())}};
    out.timings.total = seconds_since(start);
    if (out.timings.kernel <= 0) out.timings.kernel = out.timings.total;  // a host backend: its wall time, as BackendSampler's slabs
    out.timings.point_triangle_pairs = double(out.sampler.points_computed) * double(mesh.triangles().size());
    return out;
}

}  // namespace sdf

namespace sdf {

SparseBandField BoundSampler::sample_band_sparse(const Lattice& lattice, double width, BandChannels channels) const {
    require_band_width(width, "sparse band width");
    SampledField field = sample(lattice);
    if (field.sampler.band && field.sampler.band->width < width)
        throw std::invalid_argument("sparse band of width " + std::to_string(width) + ": sampler " + name() +
                                    " bands its fields at " + std::to_string(field.sampler.band->width) +
                                    ", narrower; sample with band_width 0 or >= the band's");
    apply_narrow_band(field, width);
    SparseBandField band = SparseBandField::sparsify(field, width, channels);
    if (band.sampler.band) band.sampler.band->how = "post-processed: the whole lattice sampled, then sparsified";
    return band;
}

}  // namespace sdf
