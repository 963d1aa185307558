// The peers experiment's rows and summary (experiments/peers/peer_rows.h, issue 37 item 4):
// a row that fails its own check (a wrong sign) is never the basis of a ratio, the summary
// says which sign every side has, and where no row of ours passes it compares nothing. And
// the method table (peer.h) with our samplers as adapters of the peer interface: their
// distances are MeshSdf's own, bit for bit, their sign the one the mode resolved to, and
// their build time is measured.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <memory>
#include <set>
#include <tuple>

#include "core/lattice/lattice_fitting.h"
#include "core/mesh/shapes/procedural_shapes.h"
#include "experiments/peers/peer.h"
#include "experiments/peers/peer_rows.h"
#include "harness/sampling/mesh_sdf.h"

namespace sdf::peers {
namespace {

using Json = nlohmann::json;

/// A timed row of the case "dragon gaussian_surface(0.01)/1000".
Json row(const std::string& method, const std::string& by, Json threads, double query, const std::string& sign, bool passes,
         const std::string& check = "") {
    Json r = {{"mesh", "dragon"}, {"resolution", "gaussian_surface(0.01)/1000"}, {"method", method}, {"by", by},
              {"threads", threads}, {"build_seconds", 0.1}, {"query_seconds", query}, {"total_seconds", 0.1 + query},
              {"cpu_seconds", query * 4}, {"sign", sign}, {"signed", sign != "none"}, {"passes_check", passes},
              {"check", passes ? (sign == "none" ? "exact, unsigned (no sign returned)" : "exact, signed") : check}};
    if (sign == "own") r["sign_method"] = "Side_of_triangle_mesh (ray casting)";
    return r;
}

TEST(PeerRows, TheCheckFailsARowWithWrongSignsBeyondTheTolerance) {
    // 20 points, of which 18 far from the surface have the wrong sign and 1 within the tolerance does.
    std::vector<double> reference, d;
    for (int i = 0; i < 20; ++i) {
        reference.push_back(i < 19 ? 0.5 + i : 1e-9);
        d.push_back(i < 18 || i == 19 ? -reference.back() : reference.back());
    }
    const Errors e = compare(d, reference, {}, true, 1e-6);
    EXPECT_EQ(e.sign_disagreements, 19);
    EXPECT_EQ(e.sign_disagreements_beyond_tolerance, 18);
    EXPECT_DOUBLE_EQ(e.max_abs_unsigned, 0.0);
    Json r;
    set_check(r, e, true, true, 1e-6);
    EXPECT_FALSE(r["passes_check"].get<bool>());
    EXPECT_NE(r["check"].get<std::string>().find("18 wrong signs"), std::string::npos) << r["check"];
    // The same distances unsigned pass: only the sign was wrong.
    Json u;
    set_check(u, compare(d, reference, {}, false, 1e-6), false, true, 1e-6);
    EXPECT_TRUE(u["passes_check"].get<bool>());
    EXPECT_EQ(u["check"], "exact, unsigned (no sign returned)");
}

TEST(PeerRows, TheSummaryComparesOnlyRowsThatPassTheirChecks) {
    const std::string wrong = "18 wrong signs farther than the tolerance 1e-05 from the surface (max signed error 0.2)";
    Json rows = Json::array();
    // 16 threads: our pseudonormal row is the fastest but fails; the exact-sign row passes and is slower than FCPW.
    rows.push_back(row("bvh_cpu_exact_sign", "ours", 16, 3.53, "winding", true));
    rows.push_back(row("bvh_cpu", "ours", 16, 1.0, "pseudonormal", false, wrong));
    rows.push_back(row("fcpw", "peer", 16, 3.03, "none", true));
    rows.push_back(row("embree", "peer", 16, 6.0, "none", true));
    rows.push_back(row("cgal", "peer", 16, 2.0, "own", false, "5 wrong signs farther than the tolerance"));  // fast but wrong
    rows.push_back(row("open3d", "peer", 16, 30.0, "own", true));
    // A strided brute-force row that passes is not a measured time of these points.
    Json brute = row("brute_cpu", "ours", 16, 0.01, "winding", true);
    brute["extrapolated"] = true;
    rows.push_back(brute);
    // 1 thread: only the failing row of ours.
    rows.push_back(row("bvh_cpu", "ours", 1, 8.0, "pseudonormal", false, wrong));
    rows.push_back(row("fcpw", "peer", 1, 40.0, "none", true));
    // A status row and another case's rows are ignored.
    rows.push_back({{"mesh", "dragon"}, {"resolution", "gaussian_surface(0.01)/1000"}, {"method", "cubql"}, {"by", "peer"},
                    {"status", "not built"}});
    Json other = row("bvh_cpu", "ours", 16, 0.001, "winding", true);
    other["resolution"] = "uniform_box/1000";
    rows.push_back(other);

    const std::vector<Json> s = summarise_case(rows, "dragon", "gaussian_surface(0.01)/1000", {16, 1, "GPU"}, 3.0);
    ASSERT_EQ(s.size(), 2u);  // no GPU rows: no GPU entry
    const Json& at16 = s[0];
    EXPECT_EQ(at16["threads"], 16);
    EXPECT_EQ(at16["ours"], "bvh_cpu_exact_sign");
    EXPECT_EQ(at16["ours_sign"], "winding");
    EXPECT_TRUE(at16["ours_passes_check"].get<bool>());
    EXPECT_EQ(at16["fastest_exact_peer"], "fcpw");
    EXPECT_EQ(at16["fastest_exact_peer_sign"], "unsigned");
    EXPECT_FALSE(at16["fastest_exact_peer_signed"].get<bool>());
    EXPECT_NEAR(at16["query_speedup"].get<double>(), 3.03 / 3.53, 1e-12);  // below 1: said as it is
    EXPECT_NEAR(at16["total_speedup"].get<double>(), 3.13 / 3.63, 1e-12);
    EXPECT_NEAR(at16["cpu_time_ratio"].get<double>(), 3.03 / 3.53, 1e-12);
    EXPECT_EQ(at16["fastest_exact_signed_peer"], "open3d");  // CGAL fails its sign check
    EXPECT_EQ(at16["fastest_exact_signed_peer_sign"], "own: Side_of_triangle_mesh (ray casting)");
    EXPECT_NEAR(at16["query_speedup_vs_signed"].get<double>(), 30.0 / 3.53, 1e-12);
    ASSERT_EQ(at16["excluded"].size(), 1u);
    EXPECT_EQ(at16["excluded"][0]["method"], "bvh_cpu");
    EXPECT_EQ(at16["excluded"][0]["sign"], "pseudonormal");
    EXPECT_EQ(at16["excluded"][0]["check"], wrong);
    EXPECT_FALSE(at16.contains("not_compared"));

    const Json& at1 = s[1];
    EXPECT_EQ(at1["threads"], 1);
    EXPECT_FALSE(at1.contains("query_speedup"));
    EXPECT_FALSE(at1.contains("ours"));
    EXPECT_EQ(at1["not_compared"], "no row of ours passes its check");
    ASSERT_EQ(at1["excluded"].size(), 1u);
    EXPECT_EQ(at1["excluded"][0]["check"], wrong);

    const std::string text = summary_text(at16);
    EXPECT_NE(text.find("=> bvh_cpu_exact_sign [winding] vs fastest exact peer fcpw [unsigned], 16 threads: 0.86x query"),
              std::string::npos) << text;
    EXPECT_NE(text.find("not compared: bvh_cpu [pseudonormal] fails its check: 18 wrong signs"), std::string::npos) << text;
    EXPECT_NE(summary_text(at1).find("=> no comparison, 1 threads: no row of ours passes its check\n"
                                      "       not compared: bvh_cpu [pseudonormal] fails its check: 18 wrong signs"),
              std::string::npos) << summary_text(at1);
}

TEST(PeerRows, NoPassingPeerIsSaidAndOldRowsStillHaveASign) {
    Json rows = Json::array();
    rows.push_back(row("bvh_gpu", "ours", "GPU", 0.01, "winding", true));
    rows.push_back(row("openvdb", "peer", "GPU", 0.001, "own", false, "not an exact method (narrow band)"));
    const std::vector<Json> s = summarise_case(rows, "dragon", "gaussian_surface(0.01)/1000", {"GPU"}, 1.5);
    ASSERT_EQ(s.size(), 1u);
    EXPECT_EQ(s[0]["not_compared"], "no peer passes its check");
    EXPECT_NE(summary_text(s[0]).find("no comparison, GPU"), std::string::npos);
    // Runs from before "sign" was recorded.
    EXPECT_EQ(sign_label({{"signed", true}}), "signed");
    EXPECT_EQ(sign_label({{"signed", false}}), "unsigned");
    EXPECT_EQ(sign_label({{"sign", "none"}}), "unsigned");
}

TEST(MethodTable, NamesAreUniqueAndOurCpuSamplersRunAsAdapters) {
    std::set<std::string> names;
    for (const MethodKind& m : method_table()) EXPECT_TRUE(names.insert(m.name).second) << m.name;
    EXPECT_THROW(method_kind("nonesuch"), std::invalid_argument);
    for (const char* n : {"cgal", "embree", "open3d", "openvdb", "fcpw", "cubql"})
        EXPECT_EQ(method_kind(n).by, By::Peer) << n;

    const auto mesh = std::make_shared<const PreparedMesh>(prepare_mesh(make_torus(1.0, 0.35, 32, 16)));
    const std::vector<Vec3d> points = {{0, 0, 0}, {1, 0, 0}, {1.2, 0.1, 0.05}, {2, 2, 2}, {-0.7, 0.6, 0.1}};
    PeerOptions options;
    options.exact_sign = SignMode::Winding;
    PeerInput in;
    in.mesh = mesh;
    in.points = &points;
    in.threads = 2;
    in.our_sign = SignMode::Pseudonormal;
    for (const char* name : {"bvh_cpu", "bvh_cpu_exact_sign", "bvh_cpu_per_point", "brute_cpu"}) {
        SCOPED_TRACE(name);
        const std::string method = name;  // a named string: GCC 13 warns of a temporary's reference
        const MethodKind& kind = method_kind(method);
        EXPECT_EQ(kind.by, By::Ours);
        EXPECT_EQ(kind.sign, SignKind::Mode);
        std::string why_not;
        const std::unique_ptr<PeerAdapter> adapter = kind.make(options, why_not);
        ASSERT_TRUE(adapter) << why_not;
        const PeerResult r = adapter->run(in);
        // bvh_cpu follows the case's sign; the exact-sign reference and the brute force keep "sign".
        const bool case_sign = std::string(name) == "bvh_cpu" || std::string(name) == "bvh_cpu_per_point";
        SamplerOptions o;
        o.backend = "cpu";
        o.method = std::string(name) == "brute_cpu" ? "brute_force" : "bvh";
        o.kernel = std::string(name) == "bvh_cpu_per_point" ? "seeded" : "";
        o.threads = 2;
        o.sign = case_sign ? SignMode::Pseudonormal : SignMode::Winding;
        o.progress = false;
        const std::vector<PointSample> expected = MeshSdf(mesh, o).query(points);
        ASSERT_EQ(r.distance.size(), points.size());
        for (size_t i = 0; i < points.size(); ++i) EXPECT_EQ(r.distance[i], expected[i].distance) << i;
        EXPECT_EQ(r.sign, case_sign ? SignKind::Pseudonormal : SignKind::Winding);
        EXPECT_GT(r.build_seconds, 0.0);
        EXPECT_GE(r.query_seconds, 0.0);
        EXPECT_GT(r.cpu_seconds, 0.0);
        EXPECT_EQ(r.threads, 2);
    }
    // On a lattice our samplers sample it: the field's distances.
    const Lattice lattice = fit_lattice(LatticeType::CC, {4, 4, 4}, mesh->bounds(), 0.1);
    std::vector<Vec3d> lattice_points;
    for (int64_t i = 0; i < lattice.num_points(); ++i) lattice_points.push_back(lattice.position(i));
    in.lattice = &lattice;
    in.points = &lattice_points;
    std::string why_not;
    const PeerResult r = method_kind("bvh_cpu").make(options, why_not)->run(in);
    SamplerOptions o;
    o.backend = "cpu";
    o.method = "bvh";
    o.threads = 2;
    o.sign = SignMode::Pseudonormal;
    o.progress = false;
    EXPECT_EQ(r.distance, MeshSdf(mesh, o).sample(lattice).distance);
}

// Band cases (issue 35): our sparse band's active voxels are the dense banded field's band
// points (|d| <= W), with its values; OpenVDB's level set, where built, has its voxels on the
// lattice's points.
TEST(MethodTable, BandMethodsReturnTheirOwnActiveVoxels) {
    const auto mesh = std::make_shared<const PreparedMesh>(prepare_mesh(make_torus(1.0, 0.35, 32, 16)));
    const Lattice lattice = fit_lattice(LatticeType::CC, {30, 28, 26}, mesh->bounds(), 0.1);
    PeerOptions options;
    options.exact_sign = SignMode::Pseudonormal;
    PeerInput in;
    in.mesh = mesh;
    in.lattice = &lattice;
    in.threads = 2;
    in.band_width = 2.5 * lattice.spacing;
    std::string why_not;
    const std::string band_cpu = "band_cpu";  // named: a temporary argument would look dangling to GCC 13
    const MethodKind& ours = method_kind(band_cpu);
    EXPECT_EQ(ours.inputs, Inputs::Bands);
    const PeerResult r = ours.make(options, why_not)->run(in);
    SamplerOptions o;
    o.backend = "cpu";
    o.method = "bvh";
    o.threads = 2;
    o.sign = SignMode::Pseudonormal;
    o.band_width = in.band_width;
    o.progress = false;
    const SampledField dense = MeshSdf(mesh, o).sample(lattice);
    std::map<std::tuple<double, double, double>, double> band;
    for (int64_t i = 0; i < lattice.num_points(); ++i)
        if (dense.closest_triangle[size_t(i)] != kOutsideBandTriangle) {
            const Vec3d p = lattice.position(i);
            band[{p.x, p.y, p.z}] = dense.distance[size_t(i)];
        }
    ASSERT_GT(band.size(), 0u);
    ASSERT_EQ(r.band_points.size(), band.size());
    ASSERT_EQ(r.distance.size(), band.size());
    for (size_t k = 0; k < r.band_points.size(); ++k) {
        const Vec3d& p = r.band_points[k];
        const auto it = band.find({p.x, p.y, p.z});
        ASSERT_NE(it, band.end()) << "not a band point: " << p.x << " " << p.y << " " << p.z;
        EXPECT_EQ(r.distance[k], it->second);
    }
    EXPECT_EQ(r.sign, SignKind::Pseudonormal);

    const std::unique_ptr<PeerAdapter> openvdb = method_kind("openvdb_band").make(options, why_not);
    if (!openvdb) return;  // "not built": no libopenvdb-dev
    const PeerResult v = openvdb->run(in);
    ASSERT_GT(v.band_points.size(), 0u);
    EXPECT_EQ(v.sign, SignKind::Own);
    for (const Vec3d& p : v.band_points)
        for (double c : {(p.x - lattice.origin.x) / lattice.spacing, (p.y - lattice.origin.y) / lattice.spacing,
                         (p.z - lattice.origin.z) / lattice.spacing})
            ASSERT_NEAR(c, std::round(c), 1e-9) << "a voxel off the lattice's points";
}

}  // namespace
}  // namespace sdf::peers
