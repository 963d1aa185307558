/// @file bvh_test_meshes.h
/// @brief The meshes the BVH is checked on (CPU and GPU tests) and the comparison of a BVH
/// field with the brute-force field: the procedural shapes, a sphere full of tiny and
/// sliver triangles, issue 38's sliver beside a wide triangle, a slab with large flat faces, and bunny/dragon when SDF_DATA_PATH has
/// them.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <random>
#include <tuple>
#include <vector>

#include "core/lattice/lattice_fitting.h"
#include "core/mesh/load_mesh.h"
#include "core/mesh/load_obj.h"
#include "core/mesh/prepared_mesh.h"
#include "core/mesh/shapes/procedural_shapes.h"
#include "core/sampling/sampler.h"
#include "core/winding/winding_sign.h"
#include "kernels/distance/closest_point_on_triangle.h"

namespace sdf::test {

/// Icosphere whose every triangle is split at a point very near one of its vertices (one
/// tiny triangle and two slivers) or very near an edge (two slivers of almost zero area).
/// Stays closed and manifold: the new vertex is inside the old triangle.
inline TriangleMesh make_sliver_sphere(int subdivisions = 3) {
    TriangleMesh m = make_icosphere(subdivisions);
    std::vector<Int3> out;
    const double e = 1e-4;
    for (size_t i = 0; i < m.triangles.size(); ++i) {
        const Int3 t = m.triangles[i];
        const Vec3d a = m.vertices[size_t(t.x)], b = m.vertices[size_t(t.y)], c = m.vertices[size_t(t.z)];
        const Vec3d p = i % 2 == 0 ? a * (1 - 2 * e) + b * e + c * e                  // near a vertex
                                   : a * (0.5 - e) + b * (0.5 - e) + c * (2 * e);  // near an edge
        const int v = int(m.vertices.size());
        m.vertices.push_back(p);
        out.push_back({t.x, t.y, v});
        out.push_back({t.y, t.z, v});
        out.push_back({t.z, t.x, v});
    }
    m.triangles = out;
    m.name = "sliver_sphere";
    return m;
}

/// Issue 38's two triangles: a wide one (triangle 0) and, sharing its long edge, a sliver
/// of 100 x 0.872 (triangle 1: an angle of 0.5 degrees at the origin, inradius 0.54) that the
/// searches ranked by its edges only. (66,0,0) and (50,0.1,0) lie on the sliver, (66,0,-1)
/// is 1 below it.
inline TriangleMesh make_issue38_slivers() {
    TriangleMesh m;
    m.vertices = {{0, 0, 0}, {100, 0.436, 0}, {0, 5, 0}, {100, -0.436, 0}};
    m.triangles = {{0, 1, 2}, {0, 3, 1}};
    m.name = "issue_38_sliver";
    return m;
}

/// Box of half extents `half` with every face cut into a grid of squares of side about
/// `cell` (2 triangles each): large coplanar regions, many equal box distances.
inline TriangleMesh make_flat_slab(Vec3d half = {4.0, 4.0, 0.5}, double cell = 0.25) {
    TriangleMesh m;
    m.name = "flat_slab";
    std::map<std::tuple<long, long, long>, int> ids;  // vertices shared along the box edges
    const int n[3] = {int(std::lround(2 * half.x / cell)), int(std::lround(2 * half.y / cell)),
                      int(std::lround(2 * half.z / cell))};
    auto vertex = [&](int i, int j, int k) {
        const auto key = std::make_tuple(long(i), long(j), long(k));
        auto it = ids.find(key);
        if (it != ids.end()) return it->second;
        const Vec3d p{-half.x + 2 * half.x * i / n[0], -half.y + 2 * half.y * j / n[1], -half.z + 2 * half.z * k / n[2]};
        m.vertices.push_back(p);
        return ids[key] = int(m.vertices.size()) - 1;
    };
    // Face with normal +-axis a; (u, v) run over the other two axes, ordered so that the
    // triangles are counter-clockwise seen from outside.
    for (int a = 0; a < 3; ++a)
        for (int side = 0; side < 2; ++side) {
            const int u = (a + 1) % 3, v = (a + 2) % 3;
            for (int i = 0; i < n[u]; ++i)
                for (int j = 0; j < n[v]; ++j) {
                    int c[4][3];
                    const int corner[4][2] = {{i, j}, {i + 1, j}, {i + 1, j + 1}, {i, j + 1}};
                    for (int q = 0; q < 4; ++q) {
                        c[q][a] = side * n[a];
                        c[q][u] = corner[q][0];
                        c[q][v] = corner[q][1];
                    }
                    int id[4];
                    for (int q = 0; q < 4; ++q) id[q] = vertex(c[q][0], c[q][1], c[q][2]);
                    if (side == 1) {
                        m.triangles.push_back({id[0], id[1], id[2]});
                        m.triangles.push_back({id[0], id[2], id[3]});
                    } else {
                        m.triangles.push_back({id[0], id[2], id[1]});
                        m.triangles.push_back({id[0], id[3], id[2]});
                    }
                }
        }
    return m;
}

/// Finds `file` in the colon-separated SDF_DATA_PATH (set by ctest); empty if absent.
inline std::string find_data_file(const std::string& file) {
    const char* env = std::getenv("SDF_DATA_PATH");
    std::stringstream dirs(env ? env : "");
    for (std::string dir; std::getline(dirs, dir, ':');)
        if (!dir.empty() && std::ifstream(dir + "/" + file).good()) return dir + "/" + file;
    return {};
}

struct NamedMesh {
    std::string name;
    PreparedMesh mesh;
};

/// Most of an icosphere, open at the top: auto signs it by winding numbers, and a
/// pseudonormal sign forced on it changes sides beyond the rim, away from the surface (the
/// narrow band's tests).
inline PreparedMesh open_bowl() {
    TriangleMesh m = make_icosphere(3, 1.0);
    std::vector<Int3> kept;
    for (const Int3& t : m.triangles)
        if (m.vertices[size_t(t.x)].z + m.vertices[size_t(t.y)].z + m.vertices[size_t(t.z)].z < 0.6) kept.push_back(t);
    m.triangles = kept;
    return prepare_mesh(m);
}

/// Solids for the sparse band's search bounded by the band and its sides taken from the
/// neighbours (kernels/lattice/band_sides.h), with CC and BCC resolutions times `scale`: an
/// icosahedron (its triangles' boxes reach far from it: blocks without a band point), the
/// torus, and the dragon where SDF_DATA_PATH has it.
struct BandSolid {
    std::string name;
    PreparedMesh mesh;
    Int3 cc, bcc;
};
inline std::vector<BandSolid> band_solids(double scale) {
    const auto times = [scale](Int3 r) { return Int3{int(r.x * scale), int(r.y * scale), int(r.z * scale)}; };
    std::vector<BandSolid> out;
    out.push_back({"icosahedron", prepare_mesh(make_icosphere(0, 1.0)), times({40, 40, 40}), times({28, 28, 28})});
    out.push_back({"torus", prepare_mesh(make_torus(1.0, 0.35, 32, 16)), times({49, 46, 44}), times({33, 31, 29})});
    const std::string dragon = find_data_file("dragon.obj");
    if (!dragon.empty()) out.push_back({"dragon", prepare_mesh(load_mesh_file(dragon)), times({64, 54, 48}), times({44, 37, 33})});
    return out;
}

/// A lattice of `type` cutting the box make_box({1, 1, 1}): its last plane of points (a block
/// of one plane in x, the rest padding) lies inside, 3.3 spacings below the +x face whose
/// triangles make the block active. With W = 3 spacings its middle blocks hold no point within
/// W and no point a probe or brick skip signs: their sides come from the search at point 0.
inline Lattice lattice_cutting_the_box(LatticeType type) {
    Lattice lattice;
    lattice.type = type;
    lattice.spacing = 0.05;
    lattice.resolution = {33, 49, 49};
    lattice.origin = {1.0 - 35.3 * lattice.spacing, -1.2, -1.2};
    return lattice;
}

/// A closed solid of slivers, down to those searched by their edges alone (kRobustSliverSin2):
/// a tetrahedron A B C D whose edge A B is split at the parameters k / 64 and, towards A, at
/// 2^-30 .. 2^-7, its two faces on that edge fans from C and from D over the split points
/// (angles at C and D down to about 2^-31). The slivers' edges from C and D lie within a float
/// ulp of the sharp edges A C and A D, where a float search's near-tie picks a sliver whose
/// pseudonormal puts a point beside that edge on the wrong side (the double search does not:
/// 2^-30 is far above its rounding). A lies at `offset`, B = A + (1, 0, 0): without an offset
/// the split points are exactly collinear and lattice_through_the_fan's points fall on them and
/// on A B (exact ties between the fans' triangles); with a large one the points nearest A round
/// onto A and their triangles are dropped. `finest` 45 puts slivers within the double search's
/// rounding of A C, where the pseudonormal sign itself fails (docs/large-lattices.md).
inline TriangleMesh fanned_tetrahedron(const Vec3d& offset = {0, 0, 0}, int finest = 30) {
    std::vector<double> t{0.0};
    for (int e = finest; e >= 7; --e) t.push_back(std::ldexp(1.0, -e));
    for (int k = 1; k <= 64; ++k) t.push_back(k / 64.0);
    TriangleMesh m;
    m.name = "fanned-tetrahedron";
    m.source = "shape:fanned-tetrahedron";
    for (double s : t) m.vertices.push_back(offset + Vec3d{s, 0, 0});
    const int n = int(t.size()), c = n, d = n + 1;
    m.vertices.push_back(offset + Vec3d{0.3, 0.9, 0.2});
    m.vertices.push_back(offset + Vec3d{0.45, 0.25, -0.8});
    for (int k = 0; k + 1 < n; ++k) {
        m.triangles.push_back({k, k + 1, c});  // face A B C
        m.triangles.push_back({k + 1, k, d});  // face A D B
    }
    m.triangles.push_back({0, c, d});      // A C D
    m.triangles.push_back({n - 1, d, c});  // B D C
    return m;
}

/// A lattice of spacing 1/32 over fanned_tetrahedron(offset), its points on A B at k / 32 (CC,
/// and BCC's primary grid) when the offset is 0.
inline Lattice lattice_through_the_fan(LatticeType type, const Vec3d& offset = {0, 0, 0}) {
    Lattice lattice;
    lattice.type = type;
    lattice.spacing = 1.0 / 32;
    lattice.resolution = {49, 46, 47};
    lattice.origin = offset + Vec3d{-0.25, -0.25, -1.0};
    return lattice;
}

/// One case of the sliver tests (CPU and GPU): fanned_tetrahedron, lattice_through_the_fan,
/// a precision and a band width.
struct FanCase {
    const PreparedMesh& mesh;
    Lattice lattice;
    Precision precision;
    double spacings;  ///< the band's width in spacings
    double width;     ///< and in mesh units
    std::string name;  ///< for messages
};

/// Calls check(FanCase) for fanned_tetrahedron without and with an offset of 10^4 (a solid,
/// asserted), CC and BCC, float and double, and each width in `spacings`; stops at a failure.
template <typename Check>
void for_each_fan_case(const std::vector<double>& spacings, Check check) {
    for (const Vec3d& offset : {Vec3d{0, 0, 0}, Vec3d{1e4, -2500.5, 1234.25}}) {
        const PreparedMesh fan = prepare_mesh(fanned_tetrahedron(offset));
        ASSERT_EQ(choose_sign_mode(fan.report(), SignMode::Auto).mode, SignMode::Pseudonormal) << "the fanned tetrahedron is a solid";
        for (LatticeType type : {LatticeType::CC, LatticeType::BCC})
            for (Precision precision : {Precision::Float, Precision::Double})
                for (double s : spacings) {
                    const Lattice lattice = lattice_through_the_fan(type, offset);
                    check(FanCase{fan, lattice, precision, s, s * lattice.spacing,
                                  "fanned tetrahedron offset " + std::to_string(offset.x) + " " + lattice_notation(lattice) + " " +
                                      precision_name(precision) + " W = " + std::to_string(s) + " h"});
                    if (::testing::Test::HasFailure()) return;
                }
    }
}

/// The points whose side in `field` is not the exact winding number's (`winding`, the same
/// lattice) off the surface: |d| > 1e-6 (on it, where distances round to 1e-16 .. 1e-9 through
/// the slivers, either side is right).
inline int64_t sides_off_the_winding_number(const SampledField& field, const SampledField& winding) {
    int64_t wrong = 0;
    for (size_t i = 0; i < field.distance.size(); ++i)
        wrong += std::abs(winding.distance[i]) > 1e-6 && std::signbit(winding.distance[i]) != std::signbit(field.distance[i]);
    return wrong;
}

/// Every BVH test mesh, prepared once; bunny and dragon only when the data path has them.
inline const std::vector<NamedMesh>& bvh_test_meshes() {
    static const std::vector<NamedMesh> meshes = [] {
        std::vector<NamedMesh> m;
        m.push_back({"sphere", prepare_mesh(make_icosphere(4))});
        m.push_back({"box", prepare_mesh(make_box({1, 0.5, 0.75}))});
        m.push_back({"torus", prepare_mesh(make_torus())});
        m.push_back({"pawn", prepare_mesh(make_pawn())});
        m.push_back({"soccer_ball", prepare_mesh(make_soccer_ball())});
        m.push_back({"sliver_sphere", prepare_mesh(make_sliver_sphere())});
        m.push_back({"flat_slab", prepare_mesh(make_flat_slab())});
        for (const char* file : {"bunny.obj", "dragon.obj"}) {
            const std::string path = find_data_file(file);
            if (path.empty()) std::printf("note: %s not in SDF_DATA_PATH: skipped\n", file);
            else m.push_back({file, prepare_mesh(load_obj(path))});
        }
        return m;
    }();
    return meshes;
}

/// Prepared-mesh index of each file-order triangle index.
inline std::vector<int> prepared_index(const PreparedMesh& m) {
    std::vector<int> inverse(size_t(m.report().input_triangles), -1);
    for (size_t i = 0; i < m.source_triangle().size(); ++i) inverse[size_t(m.source_triangle()[i])] = int(i);
    return inverse;
}

inline double exact_distance_to(const PreparedMesh& m, const Vec3d& p, int prepared) {
    const Int3 t = m.triangles()[size_t(prepared)];
    return std::sqrt(closest_point_on_triangle(p, m.vertices()[size_t(t.x)], m.vertices()[size_t(t.y)],
                                               m.vertices()[size_t(t.z)]).distance_squared);
}

inline double longest_edge(const PreparedMesh& m) {
    double e = 0;
    for (const Int3& t : m.triangles())
        for (int k = 0; k < 3; ++k)
            e = std::max(e, length(m.vertices()[size_t(t[k])] - m.vertices()[size_t(t[(k + 1) % 3])]));
    return e;
}

struct Agreement {
    int64_t points = 0, triangle_ties = 0, sign_ties = 0;
    double max_abs_distance = 0;
};

/// Compares a BVH result with the brute-force result point by point. Where both found the
/// same triangle, the final double evaluation is the same code on the same input: distance,
/// sign and gradient must agree to double rounding (`rel` relative). Where they differ, it
/// must be a tie: the two triangles' exact distances agree within the search rounding of
/// precision `eps` (squared distances carry about eps (|d| + longest edge)^2, see
/// packed_triangle.h), and a sign may differ only on the surface.
class FieldComparer {
public:
    /// `abs_floor`: an absolute floor of the same-triangle distance tolerance, relative to
    /// |p| + the longest edge (0 for CPU-vs-CPU comparisons, which are bit-identical; the GPU
    /// fuses multiply-adds elsewhere than the CPU, so distances near 0 differ by ~1e-16 |p|).
    /// `gradient_floor`: likewise for gradients; Eberly's closest point on a sliver is
    /// ill-conditioned, so CPU and GPU rounding can move it by ~1e-10 of the distance.
    FieldComparer(const PreparedMesh& mesh, double eps, double rel = 1e-12, double abs_floor = 0, double gradient_floor = 0)
        : mesh_(mesh), index_(prepared_index(mesh)), edge_(longest_edge(mesh)), eps_(eps), rel_(rel), abs_floor_(abs_floor),
          gradient_floor_(gradient_floor) {}

    void point(const Vec3d& p, double d_brute, double d_bvh, const Vec3d& g_brute, const Vec3d& g_bvh, int t_brute,
               int t_bvh, const std::string& what) {
        ++a_.points;
        a_.max_abs_distance = std::max(a_.max_abs_distance, std::abs(d_brute - d_bvh));
        const double scale = std::abs(d_brute) + edge_;
        // Float positions move both candidates by up to eps |p|: add that to the bound.
        const double tol_q = 64 * eps_ * scale * (scale + length(p));
        if (t_brute == t_bvh) {
            ASSERT_NEAR(d_bvh, d_brute, std::max(rel_ * std::abs(d_brute), abs_floor_ * (length(p) + edge_)) + 1e-300) << what;
            ASSERT_LE(length(g_bvh - g_brute),
                      std::max(1e-12 * (1 + length(p) / std::max(std::abs(d_brute), 1e-300)), gradient_floor_)) << what;
            return;
        }
        ++a_.triangle_ties;
        const double e_brute = exact_distance_to(mesh_, p, index_[size_t(t_brute)]);
        const double e_bvh = exact_distance_to(mesh_, p, index_[size_t(t_bvh)]);
        ASSERT_LE(std::abs(e_bvh * e_bvh - e_brute * e_brute), tol_q)
            << what << ": triangles " << t_brute << " (brute) and " << t_bvh << " (bvh) are no tie";
        ASSERT_NEAR(std::abs(d_bvh), e_bvh, 1e-12 * scale) << what;
        if ((d_brute < 0) != (d_bvh < 0)) {
            ++a_.sign_ties;
            ASSERT_LE(std::abs(d_brute), std::sqrt(tol_q)) << what << ": sign differs off the surface";
        }
    }

    void fields(const SampledField& brute, const SampledField& bvh, const std::string& what) {
        ASSERT_EQ(brute.size(), bvh.size()) << what;
        for (int64_t i = 0; i < brute.size(); ++i) {
            const size_t k = size_t(i);
            point(brute.lattice.position(i), brute.distance[k], bvh.distance[k], brute.gradient[k], bvh.gradient[k],
                  brute.closest_triangle[k], bvh.closest_triangle[k], what + " point " + std::to_string(i));
            if (::testing::Test::HasFatalFailure()) return;
        }
    }

    void samples(const std::vector<Vec3d>& pts, const std::vector<PointSample>& brute, const std::vector<PointSample>& bvh,
                 const std::string& what) {
        ASSERT_EQ(brute.size(), bvh.size()) << what;
        for (size_t i = 0; i < pts.size(); ++i) {
            point(pts[i], brute[i].distance, bvh[i].distance, brute[i].gradient, bvh[i].gradient, brute[i].triangle,
                  bvh[i].triangle, what + " point " + std::to_string(i));
            if (::testing::Test::HasFatalFailure()) return;
        }
    }

    const Agreement& agreement() const { return a_; }

private:
    const PreparedMesh& mesh_;
    std::vector<int> index_;
    double edge_, eps_, rel_, abs_floor_, gradient_floor_;
    Agreement a_;
};

/// A fan of long needles (length 1e3 per ring, the smallest angles just above the sliver
/// threshold) around an apex at `center`, each ring slightly out of plane, with points where
/// the double search's rounding is largest against Q: at the apex (an exact tie of every
/// needle), on the spokes (shared edges), inside the needles near the apex (a point far
/// nearer a triangle than the triangle is long) and a little above and below these. The
/// computed Q of a point on the surface may round below 0 there.
struct NeedleFan {
    TriangleMesh mesh;
    std::vector<Vec3d> points;
};

inline NeedleFan make_needle_fan(const Vec3d& center, int count = 600, unsigned seed = 5) {
    NeedleFan f;
    TriangleMesh& m = f.mesh;
    m.name = "needle_fan";
    const int spokes = 120, rings = 3;
    m.vertices.push_back(center);
    for (int r = 0; r < rings; ++r)
        for (int i = 0; i < spokes; ++i) {
            const double a = 2 * M_PI * i / spokes, len = 1e3 * (r + 1);
            m.vertices.push_back(center + Vec3d{len * std::cos(a), len * std::sin(a), 1e-3 * len * ((i * 7 + r) % 5)});
        }
    for (int i = 0; i < spokes; ++i) {
        const int j = (i + 1) % spokes;
        m.triangles.push_back({0, 1 + i, 1 + j});
        for (int r = 1; r < rings; ++r) {
            const int a = 1 + (r - 1) * spokes, b = 1 + r * spokes;
            m.triangles.push_back({a + i, b + i, b + j});
            m.triangles.push_back({a + i, b + j, a + j});
        }
    }
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0, 1);
    f.points.push_back(center);
    for (int k = 0; k < count; ++k) {
        const Int3 t = m.triangles[size_t(rng() % m.triangles.size())];
        const Vec3d a = m.vertices[size_t(t.x)], b = m.vertices[size_t(t.y)], c = m.vertices[size_t(t.z)];
        const double s = std::pow(10.0, -6.0 * u(rng)) * (k % 3 == 0 ? 0.0 : 1.0), w = u(rng) * (1 - s);
        const Vec3d on = k % 4 == 0 ? a : a + (b - a) * s + (c - a) * (k % 2 ? w * 1e-3 : 0.0);
        const double lift = k % 5 == 0 ? 0.0 : std::pow(10.0, -9.0 * u(rng)) * 1e3;
        f.points.push_back(on + Vec3d{0.0, 0.0, lift * (k % 2 ? 1.0 : -1.0)});
    }
    return f;
}

/// The fan prepared as every needle-fan test searches it: its triangles as built (orient_outward off).
inline PreparedMesh prepare_needle_fan(const NeedleFan& fan) {
    MeshPreparationOptions options;
    options.orient_outward = false;
    return prepare_mesh(fan.mesh, options);
}

inline double epsilon_of(Precision p) {
    return p == Precision::Float ? double(std::numeric_limits<float>::epsilon()) : std::numeric_limits<double>::epsilon();
}

}  // namespace sdf::test
