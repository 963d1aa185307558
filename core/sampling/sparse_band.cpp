#include "core/sampling/sparse_band.h"

#include <algorithm>
#include <atomic>
#include <stdexcept>
#include <string>

#include "core/parallel/parallel_for.h"

namespace sdf {
namespace {

int64_t find_sorted(const std::vector<int64_t>& ids, int64_t id) {
    const auto it = std::lower_bound(ids.begin(), ids.end(), id);
    return it != ids.end() && *it == id ? int64_t(it - ids.begin()) : -1;
}

}  // namespace

nlohmann::json channel_names(BandChannels channels) {
    nlohmann::json names = nlohmann::json::array({"distance"});
    if (channels.gradient) names.push_back("gradient");
    if (channels.closest_triangle) names.push_back("closest_triangle");
    return names;
}

void BandLayout::cell_box(int64_t id, Vec3d& lo, Vec3d& hi) const {
    const Int3 c = point_coords(id, 0);
    const int span = 2 * kBandBlockDim;  // 8 spacings, in units of h/2
    lo = lattice_.position_of_coords(c);
    hi = lattice_.position_of_coords({c.x + span, c.y + span, c.z + span});
}

SparseBandField::SparseBandField(const Lattice& lattice_in, double width_in, Precision precision_in, BandChannels channels_in)
    : lattice(lattice_in), width(width_in), precision(precision_in), channels(channels_in),
      distance(channels_in.distance_type), layout_(lattice_in) {
    require_band_width(width, "sparse band width");
    if (!(width > 0)) throw std::invalid_argument("sparse band width: expected a band width > 0, got 0");
    inside_tiles.assign(size_t((layout_.block_count() + 63) / 64), 0);
}

int64_t SparseBandField::find_active(int64_t id) const { return find_sorted(active, id); }
int64_t SparseBandField::find_mixed(int64_t id) const { return find_sorted(mixed, id); }

void SparseBandField::set_tile_inside(int64_t id, bool inside) {
    const uint64_t bit = uint64_t(1) << (id & 63);
    if (inside) inside_tiles[size_t(id >> 6)] |= bit;
    else inside_tiles[size_t(id >> 6)] &= ~bit;
}

int64_t SparseBandField::add_active(int64_t id) {
    if (!active.empty() && !(id > active.back()))
        throw std::logic_error("SparseBandField::add_active: block ids must ascend");
    active.push_back(id);
    distance.resize(active.size() * kBandBlockPoints, width);
    if (channels.gradient) gradient.resize(active.size() * kBandBlockPoints, Vec3d(0.0));
    if (channels.closest_triangle) closest_triangle.resize(active.size() * kBandBlockPoints, kOutsideBandTriangle);
    band_mask.resize(active.size(), BandPointMask{});
    return int64_t(active.size()) - 1;
}

void SparseBandField::mask_from_triangles() {
    if (!channels.closest_triangle || closest_triangle.size() != active.size() * kBandBlockPoints)
        throw std::logic_error("SparseBandField::mask_from_triangles: the band holds no closest triangle per active point");
    band_mask.resize(active.size());
    parallel_for(int64_t(active.size()), 256, 0, [&](int64_t begin, int64_t end) {
        for (int64_t a = begin; a < end; ++a) {
            BandPointMask m{};
            for (int local = 0; local < kBandBlockPoints; ++local)
                if (closest_triangle[size_t(a) * kBandBlockPoints + size_t(local)] != kOutsideBandTriangle &&
                    layout_.storage_index(active[size_t(a)], local) >= 0)
                    set_mask_bit(m, local);
            band_mask[size_t(a)] = m;
        }
    });
}

int64_t SparseBandField::add_mixed(int64_t id) {
    if (!mixed.empty() && !(id > mixed.back())) throw std::logic_error("SparseBandField::add_mixed: block ids must ascend");
    mixed.push_back(id);
    mixed_inside.push_back(BandSignMask{});
    return int64_t(mixed.size()) - 1;
}

void SparseBandField::require_channels(BandChannels wanted, const std::string& what) const {
    if (wanted.gradient && !channels.gradient)
        throw std::invalid_argument(what + ": the band holds no gradient (sampled without the gradient channel, or read "
                                           "from a file without one); ask for it when sampling, or write without it");
    if (wanted.closest_triangle && !channels.closest_triangle)
        throw std::invalid_argument(what + ": the band holds no closest triangle (sampled without the closest_triangle "
                                           "channel, or read from a file without one); ask for it when sampling, or write "
                                           "without it");
    if (wanted.distance_type == BandDistanceType::Float64 && distance.float32())
        throw std::invalid_argument(what + ": the band holds its distances in float32 (sampled for float32 outputs only); "
                                           "sample it with double distances for this");
    const size_t values = active.size() * kBandBlockPoints;
    if (distance.type() != channels.distance_type || distance.size() != values ||
        closest_triangle.size() != (channels.closest_triangle ? values : 0) ||
        gradient.size() != (channels.gradient ? values : 0) || band_mask.size() != active.size())
        throw std::invalid_argument(what + ": the band's value arrays (" + std::to_string(distance.size()) + " distances, " +
                                    std::to_string(gradient.size()) + " gradients, " + std::to_string(closest_triangle.size()) +
                                    " triangles, " + std::to_string(band_mask.size()) + " block masks) do not match its " +
                                    std::to_string(active.size()) + " active blocks");
}

SparseBandCounts SparseBandField::counts() const {
    SparseBandCounts c;
    c.blocks = layout_.block_count();
    c.active_blocks = int64_t(active.size());
    c.mixed_blocks = int64_t(mixed.size());
    c.tiles = c.blocks - c.active_blocks - c.mixed_blocks;
    for (uint64_t word : inside_tiles) c.inside_tiles += __builtin_popcountll(word);
    for (const std::vector<int64_t>* ids : {&active, &mixed})  // their tile bits mean nothing
        for (int64_t id : *ids) c.inside_tiles -= tile_inside(id) ? 1 : 0;
    for (size_t a = 0; a < active.size(); ++a) {
        const BandBlockCoords b = layout_.block_coords(active[a]);
        const Int3 n = layout_.coset(b.coset).points;
        int64_t points = 1;
        for (int k = 0; k < 3; ++k) points *= std::min(kBandBlockDim, n[k] - b.block[k] * kBandBlockDim);
        c.active_points += points;
        for (uint64_t word : band_mask[a]) c.band_points += __builtin_popcountll(word);  // padding bits are clear
    }
    return c;
}

size_t SparseBandField::memory_bytes() const {
    return active.capacity() * sizeof(int64_t) + distance.memory_bytes() + gradient.capacity() * sizeof(Vec3d) +
           closest_triangle.capacity() * sizeof(int32_t) + band_mask.capacity() * sizeof(BandPointMask) +
           inside_tiles.capacity() * sizeof(uint64_t) +
           mixed.capacity() * sizeof(int64_t) + mixed_inside.capacity() * sizeof(BandSignMask);
}

int64_t SparseBandField::dense_bytes(const Lattice& lattice, BandChannels channels) {
    return lattice.num_points() *
           int64_t(sizeof(double) + (channels.gradient ? sizeof(Vec3d) : 0) + (channels.closest_triangle ? sizeof(int32_t) : 0));
}

SampledField SparseBandField::densify(int64_t max_points) const {
    const int64_t n = lattice.num_points();
    if (n > max_points)
        throw std::length_error("densifying a sparse band of " + std::to_string(n) + " lattice points (" +
                                std::to_string(dense_bytes(lattice, channels)) + " bytes) exceeds the limit of " +
                                std::to_string(max_points) + " points");
    SampledField field = densify_slab(whole_lattice_slab(lattice));
    field.timings = timings;
    field.sampler = sampler;
    field.mesh = mesh;
    return field;
}

SampledField SparseBandField::densify_slab(const LatticeSlab& slab, NarrowBandCounts* counts) const {
    if (slab.z_begin < 0 || slab.z_end > lattice.resolution.z || slab.z_begin >= slab.z_end)
        throw std::invalid_argument("densify_slab: planes [" + std::to_string(slab.z_begin) + ", " +
                                    std::to_string(slab.z_end) + ") are not a slab of a lattice of " +
                                    std::to_string(lattice.resolution.z) + " planes");
    SampledField field;
    field.lattice = lattice;
    field.precision = precision;
    const int64_t n = slab_point_count(lattice, slab);
    if (channels.gradient && channels.closest_triangle) {
        field.resize(n);
    } else {  // a channel the band does not hold: none in the field either
        field.distance.assign(size_t(n), 0.0);
        if (channels.gradient) field.gradient.assign(size_t(n), Vec3d(0.0));
        if (channels.closest_triangle) field.closest_triangle.assign(size_t(n), -1);
    }
    std::atomic<int64_t> in_band{0};
    // Each coset's planes of the slab are one contiguous range of storage (its part), and of
    // the slab's compact order.
    int64_t part_base = 0;
    for (int c = 0; c < layout_.cosets(); ++c) {
        const BandCoset& s = layout_.coset(c);
        const StorageRange range = slab_storage(lattice, slab, c);
        const int planes = c == 0 ? slab.z_end - slab.z_begin : slab_secondary_planes(lattice, slab);
        if (planes > 0) {
            const int k0 = slab.z_begin, k1 = slab.z_begin + planes;  // the coset's planes [k0, k1)
            const int bz0 = k0 / kBandBlockDim, bz1 = (k1 - 1) / kBandBlockDim;
            const int64_t row_blocks = int64_t(s.blocks.x) * s.blocks.y;
            parallel_for(int64_t(bz1 - bz0 + 1) * row_blocks, 64, 0, [&](int64_t begin, int64_t end) {
                const int64_t first_id = s.first_block + int64_t(bz0) * row_blocks + begin;
                int64_t a = std::lower_bound(active.begin(), active.end(), first_id) - active.begin();
                int64_t m = std::lower_bound(mixed.begin(), mixed.end(), first_id) - mixed.begin();
                int64_t band_points = 0;
                for (int64_t id = first_id; id < first_id + (end - begin); ++id) {
                    const bool is_active = a < int64_t(active.size()) && active[size_t(a)] == id;
                    const bool is_mixed = !is_active && m < int64_t(mixed.size()) && mixed[size_t(m)] == id;
                    for (int local = 0; local < kBandBlockPoints; ++local) {
                        const int64_t storage = layout_.storage_index(id, local);
                        if (storage < range.offset || storage >= range.offset + range.count) continue;  // padding, other planes
                        const int64_t out = part_base + (storage - range.offset);
                        if (is_active) {
                            const size_t v = size_t(a) * kBandBlockPoints + size_t(local);
                            field.distance[size_t(out)] = distance[v];
                            if (channels.gradient) field.gradient[size_t(out)] = gradient[v];
                            if (channels.closest_triangle) field.closest_triangle[size_t(out)] = closest_triangle[v];
                            band_points += mask_bit(band_mask[size_t(a)], local) ? 1 : 0;
                        } else {  // store_outside_band's values, in the channels held
                            const bool inside = is_mixed ? mask_bit(mixed_inside[size_t(m)], local) : tile_inside(id);
                            field.distance[size_t(out)] = distance.rounded(inside ? -width : width);
                            if (channels.gradient) field.gradient[size_t(out)] = Vec3d(0.0);
                            if (channels.closest_triangle) field.closest_triangle[size_t(out)] = kOutsideBandTriangle;
                        }
                    }
                    if (is_active) ++a;
                    if (is_mixed) ++m;
                }
                in_band += band_points;
            });
        }
        part_base += range.count;
    }
    if (counts) *counts = {in_band.load(), n - in_band.load()};
    return field;
}

SparseBandField SparseBandField::sparsify(const SampledField& dense, double w, BandChannels channels) {
    SparseBandField out(dense.lattice, w, dense.precision, channels);
    if (dense.size() != dense.lattice.num_points())
        throw std::invalid_argument("sparsify: the field holds " + std::to_string(dense.size()) + " points, its lattice " +
                                    std::to_string(dense.lattice.num_points()));
    if (channels.gradient && dense.gradient.size() != dense.distance.size())
        throw std::invalid_argument("sparsify: the gradient channel was asked for, but the field holds no gradient");
    if (dense.closest_triangle.size() != dense.distance.size())  // it marks the dense band's points
        throw std::invalid_argument("sparsify: the field holds no closest triangle, which marks its band's points");
    out.timings = dense.timings;
    out.sampler = dense.sampler;
    out.mesh = dense.mesh;
    const BandLayout& layout = out.layout();
    for (int64_t id = 0; id < layout.block_count(); ++id) {
        bool in_band = false, any_inside = false, any_outside = false;
        for (int local = 0; local < kBandBlockPoints; ++local) {
            const int64_t i = layout.storage_index(id, local);
            if (i < 0) continue;
            const double d = dense.distance[size_t(i)];
            if (dense.closest_triangle[size_t(i)] != kOutsideBandTriangle && !outside_band(d, w)) in_band = true;
            (std::signbit(d) ? any_inside : any_outside) = true;
        }
        if (in_band) {
            const size_t a = size_t(out.add_active(id)), base = a * kBandBlockPoints;
            for (int local = 0; local < kBandBlockPoints; ++local) {
                const int64_t i = layout.storage_index(id, local);
                if (i < 0) continue;
                const double d = dense.distance[size_t(i)];
                const bool flagged = dense.closest_triangle[size_t(i)] == kOutsideBandTriangle || outside_band(d, w);
                out.distance.set(base + size_t(local), flagged ? (std::signbit(d) ? -w : w) : d);
                if (channels.gradient) out.gradient[base + size_t(local)] = flagged ? Vec3d(0.0) : dense.gradient[size_t(i)];
                if (channels.closest_triangle)
                    out.closest_triangle[base + size_t(local)] = flagged ? kOutsideBandTriangle : dense.closest_triangle[size_t(i)];
                if (!flagged) set_mask_bit(out.band_mask[a], local);
            }
        } else if (any_inside && any_outside) {
            BandSignMask& mask = out.mixed_inside[size_t(out.add_mixed(id))];
            for (int local = 0; local < kBandBlockPoints; ++local) {
                const int64_t i = layout.storage_index(id, local);
                if (i >= 0 && std::signbit(dense.distance[size_t(i)])) set_mask_bit(mask, local);
            }
        } else {
            out.set_tile_inside(id, any_inside);
        }
    }
    return out;
}

}  // namespace sdf
