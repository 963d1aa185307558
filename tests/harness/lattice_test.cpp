// Lattice indexing and the sampling blocks (kernels/lattice): storage order, the BCC
// primary/secondary split, parity rules, neighbourhood tables and the blocks each sampling
// strategy computes. Expected values follow from the definitions in lattice.h (integer
// coordinates in units of h/2, x fastest) and are enumerated here independently.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <set>
#include <tuple>
#include <vector>

#include "core/lattice/lattice_fitting.h"
#include "kernels/lattice/lattice.h"
#include "kernels/lattice/sampling_grid.h"

namespace sdf {
namespace {

using Key = std::tuple<int, int, int>;
Key key(const Int3& c) { return {c.x, c.y, c.z}; }

Lattice make(LatticeType type, Int3 res, Vec3d origin = {0, 0, 0}, double h = 1.0) {
    Lattice l;
    l.type = type;
    l.resolution = res;
    l.origin = origin;
    l.spacing = h;
    return l;
}

// ---- counts and indexing ---------------------------------------------------------------

TEST(Lattice, PointCounts) {
    for (int r = 2; r <= 12; ++r) {
        const Lattice cc = make(LatticeType::CC, {r, r, r});
        const Lattice bcc = make(LatticeType::BCC, {r, r, r});
        EXPECT_EQ(cc.num_points(), int64_t(r) * r * r);
        EXPECT_EQ(bcc.num_points(), int64_t(r) * r * r + int64_t(r - 1) * (r - 1) * (r - 1));
        EXPECT_EQ(bcc.num_points(), cubic_lattice_points(LatticeType::BCC, r));
        EXPECT_EQ(cc.secondary_count(), 0);
    }
    EXPECT_EQ(make(LatticeType::BCC, {64, 64, 64}).num_points(), 512191);
    const Lattice thin = make(LatticeType::BCC, {3, 4, 1});  // one layer: no cube centres
    EXPECT_EQ(thin.secondary_count(), 0);
    EXPECT_EQ(thin.num_points(), 12);
    const Lattice box = make(LatticeType::BCC, {3, 4, 5});
    EXPECT_EQ(box.primary_count(), 60);
    EXPECT_EQ(box.secondary_resolution(), (Int3{2, 3, 4}));
    EXPECT_EQ(box.secondary_count(), 24);
}

TEST(Lattice, StorageOrderIsXFastestPrimaryThenSecondary) {
    const Lattice l = make(LatticeType::BCC, {3, 4, 5});
    EXPECT_EQ(l.coords_of(0), (Int3{0, 0, 0}));
    EXPECT_EQ(l.coords_of(1), (Int3{2, 0, 0}));
    EXPECT_EQ(l.coords_of(3), (Int3{0, 2, 0}));
    EXPECT_EQ(l.coords_of(12), (Int3{0, 0, 2}));
    EXPECT_EQ(l.coords_of(59), (Int3{4, 6, 8}));
    EXPECT_EQ(l.coords_of(60), (Int3{1, 1, 1}));
    EXPECT_EQ(l.coords_of(61), (Int3{3, 1, 1}));
    EXPECT_EQ(l.coords_of(62), (Int3{1, 3, 1}));
    EXPECT_EQ(l.coords_of(66), (Int3{1, 1, 3}));
    EXPECT_EQ(l.coords_of(83), (Int3{3, 5, 7}));
}

TEST(Lattice, RoundTripCoversEveryPointOnce) {
    for (LatticeType type : {LatticeType::CC, LatticeType::BCC}) {
        const Lattice l = make(type, {3, 4, 5});
        std::set<Key> seen;
        for (int64_t i = 0; i < l.num_points(); ++i) {
            const Int3 c = l.coords_of(i);
            EXPECT_EQ(l.index_of_coords(c), i) << "index " << i;
            const bool secondary = i >= l.primary_count();
            const int parity = secondary ? 1 : 0;
            EXPECT_EQ(c.x & 1, parity);
            EXPECT_EQ(c.y & 1, parity);
            EXPECT_EQ(c.z & 1, parity);
            seen.insert(key(c));
        }
        EXPECT_EQ(int64_t(seen.size()), l.num_points());
    }
}

// Every integer point of a box around the lattice: exactly the lattice points map to an
// index (each index once); everything else -- mixed parity, odd on CC, outside -- to -1.
TEST(Lattice, IndexOfCoordsIsExactlyTheLatticePoints) {
    for (LatticeType type : {LatticeType::CC, LatticeType::BCC}) {
        const Int3 r{3, 4, 5};
        const Lattice l = make(type, r);
        std::vector<int> hits(size_t(l.num_points()), 0);
        for (int z = -3; z <= 2 * r.z + 2; ++z)
            for (int y = -3; y <= 2 * r.y + 2; ++y)
                for (int x = -3; x <= 2 * r.x + 2; ++x) {
                    const int64_t i = l.index_of_coords({x, y, z});
                    const bool even = x % 2 == 0 && y % 2 == 0 && z % 2 == 0;
                    const bool odd = (x & 1) && (y & 1) && (z & 1);
                    const bool in_primary = even && x >= 0 && y >= 0 && z >= 0 && x <= 2 * (r.x - 1) &&
                                            y <= 2 * (r.y - 1) && z <= 2 * (r.z - 1);
                    const bool in_secondary = type == LatticeType::BCC && odd && x >= 1 && y >= 1 && z >= 1 &&
                                              x <= 2 * r.x - 3 && y <= 2 * r.y - 3 && z <= 2 * r.z - 3;
                    if (in_primary || in_secondary) {
                        ASSERT_GE(i, 0) << x << " " << y << " " << z;
                        ASSERT_LT(i, l.num_points());
                        ++hits[size_t(i)];
                        EXPECT_EQ(l.coords_of(i), (Int3{x, y, z}));
                    } else {
                        EXPECT_EQ(i, -1) << x << " " << y << " " << z;
                    }
                }
        for (size_t i = 0; i < hits.size(); ++i) EXPECT_EQ(hits[i], 1) << "index " << i;
    }
}

TEST(Lattice, SpecificRejections) {
    const Lattice bcc = make(LatticeType::BCC, {3, 4, 5});
    const Lattice cc = make(LatticeType::CC, {3, 4, 5});
    for (const Int3& c : {Int3{1, 0, 0}, Int3{0, 1, 1}, Int3{2, 3, 2}, Int3{1, 1, 2}}) {
        EXPECT_EQ(bcc.index_of_coords(c), -1);
        EXPECT_EQ(cc.index_of_coords(c), -1);
    }
    EXPECT_EQ(cc.index_of_coords({1, 1, 1}), -1);      // odd on CC
    EXPECT_EQ(bcc.index_of_coords({1, 1, 1}), 60);     // first secondary point
    EXPECT_EQ(bcc.index_of_coords({-2, 0, 0}), -1);    // below
    EXPECT_EQ(bcc.index_of_coords({-1, -1, -1}), -1);  // secondary below
    EXPECT_EQ(bcc.index_of_coords({6, 0, 0}), -1);     // x = 3 > Rx - 1
    EXPECT_EQ(bcc.index_of_coords({4, 0, 0}), 2);
    EXPECT_EQ(bcc.index_of_coords({5, 1, 1}), -1);     // secondary x index 2 >= Rx - 1
    EXPECT_EQ(bcc.index_of_coords({3, 5, 7}), 83);     // last secondary point
    EXPECT_EQ(bcc.index_of_coords({3, 5, 9}), -1);
}

TEST(Lattice, PositionsAreOriginPlusHalfSpacingTimesCoords) {
    const Lattice l = make(LatticeType::BCC, {3, 4, 5}, {1.0, -2.0, 0.5}, 0.4);
    EXPECT_EQ(l.half_spacing(), 0.2);
    const Vec3d p = l.position_of_coords({3, 5, -1});
    EXPECT_EQ(p, (Vec3d{1.0 + 0.2 * 3.0, -2.0 + 0.2 * 5.0, 0.5 - 0.2}));
    for (int64_t i = 0; i < l.num_points(); ++i) EXPECT_EQ(l.position(i), l.position_of_coords(l.coords_of(i)));
    EXPECT_EQ(l.position(0), l.origin);
    EXPECT_EQ(l.position(l.primary_count() - 1), l.domain_max());
    // The first secondary point is the centre of the first primary cube.
    const Vec3d c = l.position(l.primary_count());
    EXPECT_NEAR(c.x, 1.2, 1e-15);
    EXPECT_NEAR(c.y, -1.8, 1e-15);
    EXPECT_NEAR(c.z, 0.7, 1e-15);
    EXPECT_NEAR(l.domain_max().x, 1.8, 1e-15);
    EXPECT_NEAR(l.domain_max().y, -0.8, 1e-15);
    EXPECT_NEAR(l.domain_max().z, 2.1, 1e-15);
}

// ---- neighbourhoods ---------------------------------------------------------------------

TEST(Neighbours, BccTwentySixDistinctAntipodalOffsets) {
    EXPECT_EQ(bcc_neighbour_offset(0), (Int3{0, 0, 0}));
    std::set<Key> offsets;
    int odd = 0, axis = 0, face = 0;
    for (int n = 1; n < 27; ++n) {
        const Int3 o = bcc_neighbour_offset(n);
        EXPECT_NE(o, (Int3{0, 0, 0})) << n;
        const bool all_odd = (o.x & 1) && (o.y & 1) && (o.z & 1);
        const bool all_even = !(o.x & 1) && !(o.y & 1) && !(o.z & 1);
        EXPECT_TRUE(all_odd || all_even) << n;
        const int zeros = (o.x == 0) + (o.y == 0) + (o.z == 0);
        const int sq = o.x * o.x + o.y * o.y + o.z * o.z;
        if (all_odd && sq == 3) ++odd;            // (+-1,+-1,+-1): distance h*sqrt(3)/2
        if (all_even && zeros == 2 && sq == 4) ++axis;  // (+-2,0,0): distance h
        if (all_even && zeros == 1 && sq == 8) ++face;  // (+-2,+-2,0): distance h*sqrt(2)
        offsets.insert(key(o));
    }
    EXPECT_EQ(offsets.size(), 26u);
    EXPECT_EQ(odd, 8);
    EXPECT_EQ(axis, 6);
    EXPECT_EQ(face, 12);
    int pairs = 0;
    for (const Key& k : offsets) {
        const Key minus{-std::get<0>(k), -std::get<1>(k), -std::get<2>(k)};
        EXPECT_TRUE(offsets.count(minus)) << "no antipode";
        if (k < minus) ++pairs;
    }
    EXPECT_EQ(pairs, 13);
}

TEST(Neighbours, BccNeighboursOfInteriorPointsAreLatticePoints) {
    const Lattice l = make(LatticeType::BCC, {5, 5, 5});
    for (const Int3& centre : {Int3{4, 4, 4}, Int3{3, 3, 3}, Int3{5, 3, 5}}) {
        ASSERT_GE(l.index_of_coords(centre), 0);
        for (int n = 0; n < 27; ++n) {
            const Int3 o = bcc_neighbour_offset(n);
            EXPECT_GE(l.index_of_coords({centre.x + o.x, centre.y + o.y, centre.z + o.z}), 0) << n;
        }
    }
}

TEST(Neighbours, CcCoversTheThreeByThreeBlockOnce) {
    EXPECT_EQ(cc_neighbour_offset(0), (Int3{0, 0, 0}));
    std::map<Key, int> count;
    for (int n = 0; n < 27; ++n) ++count[key(cc_neighbour_offset(n))];
    EXPECT_EQ(count.size(), 27u);
    for (int z = -2; z <= 2; z += 2)
        for (int y = -2; y <= 2; y += 2)
            for (int x = -2; x <= 2; x += 2) EXPECT_EQ(count[(Key{x, y, z})], 1) << x << " " << y << " " << z;
}

// ---- sampling blocks --------------------------------------------------------------------

TEST(SamplingBlocks, CcIsOneDirectBlock) {
    const Lattice l = make(LatticeType::CC, {3, 4, 5});
    for (BccStrategy s : {BccStrategy::TwoGrids, BccStrategy::DoubleResolution}) {
        GridBlock b[kMaxSamplingBlocks];
        ASSERT_EQ(sampling_blocks(l, s, b), 1);
        EXPECT_EQ(b[0].first, (Int3{0, 0, 0}));
        EXPECT_EQ(b[0].step, 2);
        EXPECT_EQ(b[0].resolution, l.resolution);
        EXPECT_EQ(b[0].output_offset, 0);
        EXPECT_FALSE(b[0].scatter);
        EXPECT_EQ(b[0].count(), l.num_points());
        for (int64_t i = 0; i < b[0].count(); ++i) {
            EXPECT_EQ(b[0].output_index(l, i), i);
            EXPECT_EQ(b[0].coords(i), l.coords_of(i));
        }
    }
}

TEST(SamplingBlocks, BccTwoGridsArePrimaryAndShiftedSecondary) {
    const Lattice l = make(LatticeType::BCC, {3, 4, 5});
    GridBlock b[kMaxSamplingBlocks];
    ASSERT_EQ(sampling_blocks(l, BccStrategy::TwoGrids, b), 2);
    EXPECT_EQ(b[0].first, (Int3{0, 0, 0}));
    EXPECT_EQ(b[0].step, 2);
    EXPECT_EQ(b[0].resolution, (Int3{3, 4, 5}));
    EXPECT_EQ(b[0].output_offset, 0);
    EXPECT_FALSE(b[0].scatter);
    EXPECT_EQ(b[1].first, (Int3{1, 1, 1}));
    EXPECT_EQ(b[1].step, 2);
    EXPECT_EQ(b[1].resolution, (Int3{2, 3, 4}));
    EXPECT_EQ(b[1].output_offset, 60);
    EXPECT_FALSE(b[1].scatter);
    std::vector<int> hits(size_t(l.num_points()), 0);
    for (const GridBlock& g : b)
        for (int64_t i = 0; i < g.count(); ++i) {
            const int64_t out = g.output_index(l, i);
            ASSERT_GE(out, 0);
            ASSERT_LT(out, l.num_points());
            EXPECT_EQ(l.index_of_coords(g.coords(i)), out);  // positions agree with storage
            ++hits[size_t(out)];
        }
    for (int h : hits) EXPECT_EQ(h, 1);
}

TEST(SamplingBlocks, BccTwoGridsWithoutSecondaryIsOneBlock) {
    GridBlock b[kMaxSamplingBlocks];
    EXPECT_EQ(sampling_blocks(make(LatticeType::BCC, {3, 3, 1}), BccStrategy::TwoGrids, b), 1);
}

TEST(SamplingBlocks, BccDoubleResolutionMapsExactlyTheBccPoints) {
    for (const Int3& r : {Int3{3, 4, 5}, Int3{2, 2, 2}, Int3{6, 6, 6}}) {
        const Lattice l = make(LatticeType::BCC, r);
        GridBlock b[kMaxSamplingBlocks];
        ASSERT_EQ(sampling_blocks(l, BccStrategy::DoubleResolution, b), 1);
        const GridBlock& g = b[0];
        EXPECT_TRUE(g.scatter);
        EXPECT_EQ(g.step, 1);
        EXPECT_EQ(g.first, (Int3{0, 0, 0}));
        std::vector<int> hits(size_t(l.num_points()), 0);
        int64_t discarded = 0;
        for (int64_t i = 0; i < g.count(); ++i) {
            const Int3 c = g.coords(i);
            const int64_t out = g.output_index(l, i);
            const bool even = !(c.x & 1) && !(c.y & 1) && !(c.z & 1);
            const bool odd = (c.x & 1) && (c.y & 1) && (c.z & 1);
            const bool is_point = (even && c.x <= 2 * (r.x - 1) && c.y <= 2 * (r.y - 1) && c.z <= 2 * (r.z - 1)) ||
                                  (odd && c.x <= 2 * r.x - 3 && c.y <= 2 * r.y - 3 && c.z <= 2 * r.z - 3);
            if (is_point) {
                ASSERT_GE(out, 0);
                ASSERT_LT(out, l.num_points());
                EXPECT_EQ(l.coords_of(out), c);
                ++hits[size_t(out)];
            } else {
                EXPECT_EQ(out, -1) << c.x << " " << c.y << " " << c.z;
                ++discarded;
            }
        }
        for (size_t i = 0; i < hits.size(); ++i) EXPECT_EQ(hits[i], 1) << "index " << i;
        EXPECT_EQ(g.count() - discarded, l.num_points());
    }
}

// Strategy A (thesis Figure 3-3 A) samples a 2Rx x 2Ry x 2Rz grid at spacing h/2. (2R-1) per
// axis would reach the primary grid's last point already; the extra plane per axis, h/2
// beyond domain_max(), is computed and discarded. That is deliberate: it is the thesis's
// grid, and strategy comparisons follow the thesis.
TEST(SamplingBlocks, BccDoubleResolutionIsTheThesisGrid) {
    const Lattice l = make(LatticeType::BCC, {16, 16, 16});
    GridBlock b[kMaxSamplingBlocks];
    ASSERT_EQ(sampling_blocks(l, BccStrategy::DoubleResolution, b), 1);
    EXPECT_EQ(b[0].resolution, (Int3{32, 32, 32}));
    EXPECT_EQ(b[0].step, 1);
    EXPECT_TRUE(b[0].scatter);
    // The last block point lies beyond the lattice and is discarded.
    EXPECT_EQ(b[0].coords(b[0].count() - 1), (Int3{31, 31, 31}));
    EXPECT_EQ(b[0].output_index(l, b[0].count() - 1), -1);
}

}  // namespace
}  // namespace sdf
