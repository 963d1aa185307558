// The sparse band's field file (harness/io/sparse_field_file.h, issue 35): written and read
// back it is the band in memory, array for array (float64); densified, it is the dense
// `--band W` field file (an independent dense sampling, written by write_field and read by
// read_field) byte for byte, CC and BCC, a solid, an open bowl (winding sign: mixed blocks)
// and nested shells; reconstructed, it is the dense file's reconstruction. Hostile files
// (truncated channels, counts past the lattice, ids out of order) are refused, naming the
// file and what was expected, before anything is allocated; replacing follows the dense file.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <tuple>

#include "core/lattice/lattice_fitting.h"
#include "core/mesh/shapes/procedural_shapes.h"
#include "core/reconstruction/reconstruction.h"
#include "core/sampling/sparse_band_cells.h"
#include "cpu_reference/bvh/bvh_cpu.h"
#include "harness/cache/field_cache.h"
#include "harness/io/sparse_field_file.h"
#include "harness/io/sparse_nvdb_file.h"
#include "harness/io/sparse_vdb_file.h"
#include "harness/study/field_source.h"
#include "harness_test_util.h"
#include "tests/cpu_reference/bvh/bvh_test_meshes.h"
#include "tests/test_util/shared_mesh.h"

namespace sdf {
namespace {

namespace fs = std::filesystem;

SamplerOptions options(double band, SignMode sign) {
    SamplerOptions o;
    o.precision = Precision::Float;
    o.band_width = band;
    o.sign = sign;
    o.progress = false;
    return o;
}

template <typename V, typename A>
bool same_bytes(const std::vector<V, A>& a, const std::vector<V, A>& b) {
    return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(V)) == 0);
}
bool same_bytes(const BandDistances& a, const BandDistances& b) { return a.same_bytes(b); }

TriangleMesh joined(const std::vector<TriangleMesh>& parts) {
    TriangleMesh m;
    m.name = "shells";
    m.source = "shape:shells";
    for (const TriangleMesh& p : parts) {
        const int base = int(m.vertices.size());
        m.vertices.insert(m.vertices.end(), p.vertices.begin(), p.vertices.end());
        for (const Int3& t : p.triangles) m.triangles.push_back({t.x + base, t.y + base, t.z + base});
    }
    return m;
}

struct Case {
    std::string name;
    PreparedMesh mesh;
    SignMode sign;
};

std::vector<Case> cases() {
    std::vector<Case> out;
    out.push_back({"torus", prepare_mesh(make_torus(1.0, 0.35, 32, 16)), SignMode::Pseudonormal});
    out.push_back({"open bowl", test::open_bowl(), SignMode::Winding});
    out.push_back({"nested shells",
                   prepare_mesh(joined({make_icosphere(2, 1.0), make_icosphere(2, 0.45, {0.1, 0.0, 0.0})})),
                   SignMode::Winding});
    return out;
}

/// The band's tile bits that mean something (tiles only).
std::vector<bool> tile_sides(const SparseBandField& b) {
    std::vector<bool> sides;
    for (int64_t id = 0; id < b.layout().block_count(); ++id)
        sides.push_back(b.find_active(id) < 0 && b.find_mixed(id) < 0 && b.tile_inside(id));
    return sides;
}

void expect_same_band(const SparseBandField& a, const SparseBandField& b, const std::string& what) {
    EXPECT_EQ(a.width, b.width) << what;
    EXPECT_EQ(a.precision, b.precision) << what;
    EXPECT_EQ(lattice_notation(a.lattice), lattice_notation(b.lattice)) << what;
    EXPECT_EQ(a.lattice.origin.x, b.lattice.origin.x) << what;
    EXPECT_EQ(a.lattice.spacing, b.lattice.spacing) << what;
    EXPECT_TRUE(same_bytes(a.active, b.active)) << what;
    EXPECT_TRUE(same_bytes(a.distance, b.distance)) << what;
    EXPECT_TRUE(same_bytes(a.gradient, b.gradient)) << what;
    EXPECT_TRUE(same_bytes(a.closest_triangle, b.closest_triangle)) << what;
    EXPECT_TRUE(same_bytes(a.band_mask, b.band_mask)) << what;
    EXPECT_TRUE(same_bytes(a.mixed, b.mixed)) << what;
    EXPECT_TRUE(same_bytes(a.mixed_inside, b.mixed_inside)) << what;
    EXPECT_TRUE(tile_sides(a) == tile_sides(b)) << what;
    EXPECT_EQ(nlohmann::json(a.mesh).dump(), nlohmann::json(b.mesh).dump()) << what;
    EXPECT_EQ(nlohmann::json(a.sampler).dump(), nlohmann::json(b.sampler).dump()) << what;
}

/// The channel files of a field header, by channel name, as bytes.
std::map<std::string, std::string> channel_bytes(const std::string& header) {
    const nlohmann::json j = test::read_json(header);
    std::map<std::string, std::string> out;
    for (const auto& [name, ch] : j["channels"].items())
        out[name] = test::read_text(fs::path(header).parent_path() / ch["file"].get<std::string>());
    return out;
}

class SparseFieldFile : public test::ScratchDirTest {
protected:
    SparseFieldFile() : ScratchDirTest("sdf_sparse_field_file_test") {}
};

TEST_F(SparseFieldFile, RoundTripAndDensifiedEqualsTheDenseBandFile) {
    for (const Case& c : cases()) {
        for (LatticeType type : {LatticeType::CC, LatticeType::BCC}) {
            const Lattice lattice = fit_lattice(type, type == LatticeType::CC ? Int3{37, 35, 33} : Int3{27, 26, 25},
                                                c.mesh.bounds(), 0.5);
            const double w = 1.5 * lattice.spacing;
            const std::string what = c.name + " " + lattice_notation(lattice);
            SparseBandField band =
                make_cpu_bvh_sampler(options(0, c.sign))->bind(share(c.mesh))->sample_band_sparse(lattice, w);
            band.mesh.name = c.name;
            // Round trip at float64: every array as held.
            SparseFieldWriteOptions o64;
            o64.dtype = FieldDtype::Float64;
            write_sparse_field(at("b64.json"), band, o64);
            ASSERT_TRUE(is_sparse_field_file(at("b64.json")));
            expect_same_band(band, read_sparse_field(at("b64.json")), what + " float64");
            // float32, against an independent dense sampling written as the dense file.
            const SampledField dense = make_cpu_bvh_sampler(options(w, c.sign))->bind(share(c.mesh))->sample(lattice);
            write_field(at("dense.json"), dense);
            write_sparse_field(at("b32.json"), band);
            const SampledField from_sparse = read_field_densified(at("b32.json"), "test");
            const SampledField from_dense = read_field(at("dense.json"));
            EXPECT_TRUE(same_bytes(from_sparse.distance, from_dense.distance)) << what;
            EXPECT_TRUE(same_bytes(from_sparse.gradient, from_dense.gradient)) << what;
            EXPECT_TRUE(same_bytes(from_sparse.closest_triangle, from_dense.closest_triangle)) << what;
            // The densified file, written as a dense one: the dense file's channel bytes.
            write_field(at("again.json"), from_sparse);
            const auto a = channel_bytes(at("dense.json")), b = channel_bytes(at("again.json"));
            ASSERT_EQ(a.size(), 3u) << what;
            for (const auto& [name, bytes] : a) EXPECT_TRUE(bytes == b.at(name)) << what << ": channel " << name;
            // A band held in float32 (sdf-sample's float32 runs): the same float32 file, every
            // channel's bytes; float64 from it refused, naming the file.
            BandChannels f32_channels;
            f32_channels.distance_type = BandDistanceType::Float32;
            const SparseBandField band_f32 =
                make_cpu_bvh_sampler(options(0, c.sign))->bind(share(c.mesh))->sample_band_sparse(lattice, w, f32_channels);
            write_sparse_field(at("f32.json"), band_f32);
            const auto from_double = channel_bytes(at("b32.json")), from_float = channel_bytes(at("f32.json"));
            EXPECT_EQ(from_double.size(), from_float.size()) << what;
            for (const auto& [name, bytes] : from_double) EXPECT_TRUE(bytes == from_float.at(name)) << what << ": channel " << name;
            const std::string refused = test::error_of([&] { write_sparse_field(at("f64.json"), band_f32, o64); });
            EXPECT_NE(refused.find("f64.json: the gradient channel and the distances' dtype: the band holds its distances in float32"),
                      std::string::npos)
                << refused;
            EXPECT_FALSE(fs::exists(at("f64.json"))) << what;
            // Without the gradient channel, as `--channels distance,closest_triangle`.
            SparseFieldWriteOptions no_gradient;
            no_gradient.gradient = false;
            write_sparse_field(at("ng.json"), band, no_gradient);
            EXPECT_FALSE(test::read_json(at("ng.json"))["channels"].contains("gradient"));
            const SampledField ng = read_field_densified(at("ng.json"), "test");
            EXPECT_TRUE(ng.gradient.empty()) << what;
            EXPECT_TRUE(same_bytes(ng.distance, from_dense.distance)) << what;
            // Reconstructed: the dense file's reconstruction, at points in the band's cells.
            const Reconstruction sparse_recon(from_sparse, type == LatticeType::CC ? "tricubic_lm" : "bcc_cubic", "true");
            const Reconstruction dense_recon(from_dense, type == LatticeType::CC ? "tricubic_lm" : "bcc_cubic", "true");
            const SparseBandField band32 = read_sparse_field(at("b32.json"));
            std::mt19937_64 rng(35);
            std::uniform_real_distribution<double> unit(0.0, 1.0);
            int in_band = 0, outside = 0;
            for (int i = 0; i < 4000; ++i) {
                const Vec3d lo = lattice.domain_min(), hi = lattice.domain_max();
                const Vec3d p{lo.x + unit(rng) * (hi.x - lo.x), lo.y + unit(rng) * (hi.y - lo.y), lo.z + unit(rng) * (hi.z - lo.z)};
                if (!in_band_cells(band32, p)) {
                    ++outside;
                    continue;
                }
                ++in_band;
                const auto s = sparse_recon.evaluate(p), d = dense_recon.evaluate(p);
                ASSERT_EQ(s.value, d.value) << what;
                ASSERT_EQ(s.gradient.x, d.gradient.x) << what;
            }
            EXPECT_GT(in_band, 20) << what;
            EXPECT_GT(outside, 20) << what;
            for (const auto& entry : fs::directory_iterator(dir_)) fs::remove(entry.path());
        }
    }
}

// Across the bowl's opening the winding sign changes far from every triangle: mixed blocks,
// stored point by point, read back and densified to the dense band file.
TEST_F(SparseFieldFile, MixedBlocksOfAnOpenBowl) {
    const PreparedMesh bowl = test::open_bowl();
    const Lattice lattice = fit_lattice(LatticeType::CC, {96, 96, 96}, bowl.bounds(), 0.6);
    const double w = 1.0 * lattice.spacing;
    const SparseBandField band =
        make_cpu_bvh_sampler(options(0, SignMode::Winding))->bind(share(bowl))->sample_band_sparse(lattice, w);
    ASSERT_GT(band.mixed.size(), 0u);
    write_sparse_field(at("bowl.json"), band);
    write_field(at("dense.json"), make_cpu_bvh_sampler(options(w, SignMode::Winding))->bind(share(bowl))->sample(lattice));
    const SparseBandField back = read_sparse_field(at("bowl.json"));
    EXPECT_TRUE(same_bytes(back.mixed, band.mixed));
    EXPECT_TRUE(same_bytes(back.mixed_inside, band.mixed_inside));
    const SampledField from_dense = read_field(at("dense.json")), from_sparse = back.densify();
    EXPECT_TRUE(same_bytes(from_sparse.distance, from_dense.distance));
    EXPECT_TRUE(same_bytes(from_sparse.gradient, from_dense.gradient));
    EXPECT_TRUE(same_bytes(from_sparse.closest_triangle, from_dense.closest_triangle));
}

// The band's cells: a world point whose cell corners are band points; the lattice's corner
// points and points off the lattice are not.
TEST_F(SparseFieldFile, BandCellsFollowTheBandsPoints) {
    const PreparedMesh torus = prepare_mesh(make_torus(1.0, 0.35, 32, 16));
    const Lattice lattice = fit_lattice(LatticeType::CC, {30, 30, 30}, torus.bounds(), 0.3);
    const SparseBandField band =
        make_cpu_bvh_sampler(options(0, SignMode::Pseudonormal))->bind(share(torus))->sample_band_sparse(lattice, 2 * lattice.spacing);
    const SampledField dense = band.densify();
    EXPECT_FALSE(in_band_cells(band, lattice.domain_min()));
    EXPECT_FALSE(in_band_cells(band, lattice.domain_max() + Vec3d(1.0)));
    EXPECT_FALSE(in_band_cells(band, Vec3d(0.0)));  // the torus's hole, far from the surface
    // The point on the torus's tube centre circle's surface: a band cell.
    EXPECT_TRUE(in_band_cells(band, Vec3d(1.35, 0.0, 0.0) + Vec3d(1e-3, 2e-3, 3e-3)));
    // Brute force over cell centres: the rule is the 8 corners' closest triangles.
    const Int3 r = lattice.resolution;
    for (int k = 0; k + 1 < r.z; k += 3)
        for (int j = 0; j + 1 < r.y; ++j)
            for (int i = 0; i + 1 < r.x; ++i) {
                bool all = true;
                for (int c = 0; c < 8; ++c)
                    all = all && dense.closest_triangle[size_t(i + (c & 1) + r.x * (j + (c >> 1 & 1) + r.y * (k + (c >> 2))))] !=
                                     kOutsideBandTriangle;
                const Vec3d p = lattice.origin + Vec3d(i + 0.5, j + 0.5, k + 0.5) * lattice.spacing;
                ASSERT_EQ(in_band_cells(band, p), all) << i << " " << j << " " << k;
            }
}

// run-experiment's fields (FieldSource, a config's band_width): a band is sampled sparsely,
// equal to the dense sampler's banded field byte for byte, and cached as the sparse file,
// which loads back as the same field.
TEST_F(SparseFieldFile, FieldSourceSamplesTheBandSparselyAndCachesItsFile) {
    const PreparedMesh bowl = test::open_bowl();
    for (LatticeType type : {LatticeType::CC, LatticeType::BCC}) {
        const Lattice lattice = fit_lattice(type, type == LatticeType::CC ? Int3{33, 31, 30} : Int3{24, 23, 44}, bowl.bounds(), 0.5);
        SamplerOptions o = options(1.5 * lattice.spacing, SignMode::Winding);
        o.backend = "cpu";
        o.threads = 2;
        const SampledField dense = make_cpu_bvh_sampler(o)->bind(share(bowl))->sample(lattice);
        const FieldCache cache(at(std::string("cache-") + lattice_type_name(type)));
        const auto mesh = share(bowl);
        std::ostringstream log;
        FieldSource source(&cache, o, "test");
        const ObtainedField fresh = source.get(mesh, lattice, "bowl", log);
        const ObtainedField cached = FieldSource(&cache, o, "test").get(mesh, lattice, "bowl", log);
        EXPECT_FALSE(fresh.from_cache);
        EXPECT_TRUE(cached.from_cache);
        for (const SampledField* f : {&fresh.field, &cached.field}) {
            EXPECT_TRUE(same_bytes(f->distance, dense.distance)) << lattice_notation(lattice);
            EXPECT_TRUE(same_bytes(f->gradient, dense.gradient)) << lattice_notation(lattice);
            EXPECT_TRUE(same_bytes(f->closest_triangle, dense.closest_triangle)) << lattice_notation(lattice);
            ASSERT_TRUE(f->sampler.band.has_value());
            EXPECT_TRUE(test::Contains(f->sampler.band->how, "sparse"));
            EXPECT_EQ(f->sampler.band->points_in_band, dense.sampler.band->points_in_band);
        }
        const nlohmann::json key = field_cache_key(bowl.content_sha256(), lattice, o);
        EXPECT_TRUE(is_sparse_field_file(cache.entry_path(key) + "/field.json"));
        EXPECT_TRUE(test::Contains(log.str(), "sampling the sparse band"));
    }
}

// A band sampled without its gradient channel: its file has no gradient channel, reads back
// as a band without one (the same distances and triangles as the full band's file), and
// densifies to the dense band file without the gradient; asking a writer for the gradient
// of such a band is refused, naming the file.
TEST_F(SparseFieldFile, BandWithoutGradientWrittenReadAndRefusedWhereAskedFor) {
    const PreparedMesh bowl = test::open_bowl();
    const Lattice lattice = fit_lattice(LatticeType::CC, {96, 96, 96}, bowl.bounds(), 0.6);  // mixed blocks, as above
    const double w = 1.0 * lattice.spacing;
    const auto bound = make_cpu_bvh_sampler(options(0, SignMode::Winding))->bind(share(bowl));
    BandChannels slim_channels;
    slim_channels.gradient = false;
    const SparseBandField full = bound->sample_band_sparse(lattice, w);
    const SparseBandField slim = bound->sample_band_sparse(lattice, w, slim_channels);
    ASSERT_GT(slim.mixed.size(), 0u);
    // The writers refuse the gradient the band does not hold.
    const std::string e = test::error_of([&] { write_sparse_field(at("slim.json"), slim); });
    EXPECT_TRUE(test::Contains(e, "slim.json")) << e;
    EXPECT_TRUE(test::Contains(e, "the band holds no gradient")) << e;
    EXPECT_THROW(write_sparse_field(at("slim.json"), slim), std::invalid_argument);
    EXPECT_FALSE(fs::exists(at("slim.json")));
    SparseVdbOptions vdb;
    EXPECT_THROW(write_sparse_band_vdb(slim, at("slim.vdb"), vdb), std::invalid_argument);
    EXPECT_FALSE(fs::exists(at("slim.vdb")));
    // Without the gradient asked: written, and read back as it was held.
    SparseFieldWriteOptions o64;
    o64.dtype = FieldDtype::Float64;
    o64.gradient = false;
    write_sparse_field(at("slim.json"), slim, o64);
    EXPECT_FALSE(test::read_json(at("slim.json"))["channels"].contains("gradient"));
    EXPECT_FALSE(test::read_json(at("slim.json")).contains("gradient_channel"));
    const SparseBandField back = read_sparse_field(at("slim.json"));
    EXPECT_FALSE(back.channels.gradient);
    EXPECT_TRUE(back.gradient.empty());
    expect_same_band(slim, back, "without gradient, float64");
    // The full band's file without its gradient channel is the same band.
    write_sparse_field(at("full.json"), full, o64);
    const SparseBandField full_back = read_sparse_field(at("full.json"));
    EXPECT_FALSE(full_back.channels.gradient);
    EXPECT_TRUE(same_bytes(full_back.distance, back.distance));
    EXPECT_TRUE(same_bytes(full_back.closest_triangle, back.closest_triangle));
    EXPECT_TRUE(same_bytes(full_back.mixed_inside, back.mixed_inside));
    // Densified: the dense band file's distances and triangles, no gradient.
    FieldWriteOptions dense64;
    dense64.dtype = FieldDtype::Float64;
    write_field(at("dense.json"), make_cpu_bvh_sampler(options(w, SignMode::Winding))->bind(share(bowl))->sample(lattice),
                dense64);
    const SampledField from_dense = read_field(at("dense.json"));
    const SampledField from_slim = read_field_densified(at("slim.json"), "test");
    EXPECT_TRUE(from_slim.gradient.empty());
    EXPECT_TRUE(same_bytes(from_slim.distance, from_dense.distance));
    EXPECT_TRUE(same_bytes(from_slim.closest_triangle, from_dense.closest_triangle));
    EXPECT_THROW(write_sparse_field(at("again.json"), back), std::invalid_argument);
}

// A band sampled without its closest triangles (the distance alone): its file holds the band
// points' mask ("band_points") instead of the triangles, reads back as the same band (mask,
// distances, tiles, signs), densifies to the dense band file without its triangle channel,
// and writes the same .vdb/.nvdb active voxels as the full band; a file with both or
// neither marking channel, or a mask bit on padding, is refused naming the file and channel.
TEST_F(SparseFieldFile, BandWithoutTrianglesWritesItsMaskAndReadsBack) {
    const PreparedMesh bowl = test::open_bowl();
    const Lattice lattice = fit_lattice(LatticeType::CC, {96, 96, 96}, bowl.bounds(), 0.6);  // mixed blocks, as above
    const double w = 1.0 * lattice.spacing;
    const auto bound = make_cpu_bvh_sampler(options(0, SignMode::Winding))->bind(share(bowl));
    BandChannels lean_channels;
    lean_channels.gradient = false;
    lean_channels.closest_triangle = false;
    const SparseBandField full = bound->sample_band_sparse(lattice, w);
    const SparseBandField lean = bound->sample_band_sparse(lattice, w, lean_channels);
    ASSERT_GT(lean.mixed.size(), 0u);
    SparseFieldWriteOptions o64;
    o64.dtype = FieldDtype::Float64;
    o64.gradient = false;
    write_sparse_field(at("lean.json"), lean, o64);
    const nlohmann::json header = test::read_json(at("lean.json"));
    EXPECT_FALSE(header["channels"].contains("closest_triangle"));
    EXPECT_EQ(header["channels"]["band_points"]["dtype"], "uint64");
    EXPECT_EQ(header["channels"]["band_points"]["components"], 8);
    EXPECT_EQ(header["band"]["band_points"], full.counts().band_points);
    EXPECT_EQ(fs::file_size(at(header["channels"]["band_points"]["file"].get<std::string>())), lean.active.size() * 64);
    const SparseBandField back = read_sparse_field(at("lean.json"));
    EXPECT_FALSE(back.channels.closest_triangle);
    EXPECT_FALSE(back.channels.gradient);
    expect_same_band(lean, back, "without triangles, float64");
    EXPECT_TRUE(same_bytes(full.band_mask, back.band_mask));
    // The full band's file: its mask comes back from its triangles.
    write_sparse_field(at("full.json"), full, o64);
    const SparseBandField full_back = read_sparse_field(at("full.json"));
    EXPECT_TRUE(same_bytes(full_back.band_mask, back.band_mask));
    EXPECT_TRUE(same_bytes(full_back.distance, back.distance));
    // Densified: the dense band file's distances (float64 both), no triangle channel.
    FieldWriteOptions dense64;
    dense64.dtype = FieldDtype::Float64;
    write_field(at("dense.json"), make_cpu_bvh_sampler(options(w, SignMode::Winding))->bind(share(bowl))->sample(lattice),
                dense64);
    const SampledField from_dense = read_field(at("dense.json"));
    const SampledField from_lean = read_field_densified(at("lean.json"), "test");
    EXPECT_TRUE(from_lean.closest_triangle.empty());
    EXPECT_TRUE(same_bytes(from_lean.distance, from_dense.distance));
    // Writers refuse the triangles the band does not hold.
    SparseVdbOptions vdb;
    vdb.gradient = false;
    vdb.closest_triangle = true;
    const std::string e = test::error_of([&] { write_sparse_band_vdb(lean, at("lean.vdb"), vdb); });
    EXPECT_TRUE(test::Contains(e, "lean.vdb")) << e;
    EXPECT_TRUE(test::Contains(e, "the band holds no closest triangle")) << e;
    EXPECT_FALSE(fs::exists(at("lean.vdb")));
    if (nanovdb_available()) {  // the same NanoVDB level set, byte for byte
        write_sparse_band_nvdb(full, at("full.nvdb"));
        const SparseNvdbCounts counts = write_sparse_band_nvdb(back, at("lean.nvdb"));
        EXPECT_EQ(counts.active_voxels, full.counts().band_points);
        EXPECT_EQ(test::read_text(at("full.nvdb")), test::read_text(at("lean.nvdb")));
    }
    // Hostile variants of its header and mask.
    const std::string mask_path = at(header["channels"]["band_points"]["file"].get<std::string>());
    const std::string mask = test::read_text(mask_path);
    nlohmann::json h = header;
    h["channels"].erase("band_points");
    test::write_file(at("lean.json"), h.dump(2));
    std::string err = test::error_of([&] { read_sparse_field(at("lean.json")); });
    EXPECT_TRUE(test::Contains(err, "lean.json") && test::Contains(err, "'band_points'") && test::Contains(err, "neither")) << err;
    h = header;
    h["channels"]["closest_triangle"] = {{"file", h["channels"]["band_points"]["file"]}, {"dtype", "int32"}};
    test::write_file(at("lean.json"), h.dump(2));
    err = test::error_of([&] { read_sparse_field(at("lean.json")); });
    EXPECT_TRUE(test::Contains(err, "lean.json") && test::Contains(err, "both")) << err;
    test::write_file(at("lean.json"), header.dump(2));
    test::write_file(mask_path, mask.substr(8));
    err = test::error_of([&] { read_sparse_field(at("lean.json")); });
    EXPECT_TRUE(test::Contains(err, "channel 'band_points'") && test::Contains(err, "bytes")) << err;
    // A bit on a padding point, in a lattice close around the bowl (active blocks at its far edges).
    const Lattice tight = fit_lattice(LatticeType::CC, {27, 26, 25}, bowl.bounds(), 0.05);
    const SparseBandField edge = bound->sample_band_sparse(tight, 2 * tight.spacing, lean_channels);
    write_sparse_field(at("edge.json"), edge, o64);
    read_sparse_field(at("edge.json"));
    size_t a = 0;
    int pad = -1;
    for (; a < edge.active.size() && pad < 0; ++a)
        for (int local = 0; local < kBandBlockPoints && pad < 0; ++local)
            if (edge.layout().storage_index(edge.active[a], local) < 0) pad = local;
    ASSERT_GE(pad, 0) << "no active block with padding";
    const std::string edge_mask = at(test::read_json(at("edge.json"))["channels"]["band_points"]["file"].get<std::string>());
    std::string bad = test::read_text(edge_mask);
    bad[(a - 1) * 64 + size_t(pad / 8)] = char(bad[(a - 1) * 64 + size_t(pad / 8)] | (1 << (pad % 8)));
    test::write_file(edge_mask, bad);
    err = test::error_of([&] { read_sparse_field(at("edge.json")); });
    EXPECT_TRUE(test::Contains(err, "edge.json") && test::Contains(err, "channel 'band_points'") &&
                test::Contains(err, "padding"))
        << err;
}

class HostileSparseFile : public SparseFieldFile {
protected:
    void SetUp() override {
        SparseFieldFile::SetUp();
        const PreparedMesh bowl = test::open_bowl();
        const Lattice lattice = fit_lattice(LatticeType::BCC, {20, 20, 20}, bowl.bounds(), 0.5);
        band_ = make_cpu_bvh_sampler(options(0, SignMode::Winding))->bind(share(bowl))->sample_band_sparse(lattice, 1.2 * lattice.spacing);
        write_sparse_field(at("h.json"), band_);
        header_ = test::read_json(at("h.json"));
    }
    /// Writes `header` over h.json and returns read_sparse_field's error.
    std::string error_with(const nlohmann::json& header) {
        test::write_file(at("h.json"), header.dump(2));
        return test::error_of([&] { read_sparse_field(at("h.json")); });
    }
    std::string channel(const std::string& name) { return at(header_["channels"][name]["file"].get<std::string>()); }

    SparseBandField band_;
    nlohmann::json header_;
};

TEST_F(HostileSparseFile, RefusedWithTheFileAndWhatWasExpected) {
    ASSERT_GT(band_.active.size(), 2u);
    nlohmann::json h = header_;
    h["band"]["active_blocks"] = int64_t(1) << 60;  // past the lattice: refused before any allocation
    std::string e = error_with(h);
    EXPECT_TRUE(test::Contains(e, "h.json"));
    EXPECT_TRUE(test::Contains(e, "active_blocks"));
    h = header_;
    h["band"]["active_blocks"] = header_["band"]["active_blocks"].get<int64_t>() + 1;  // the files are too short
    e = error_with(h);
    EXPECT_TRUE(test::Contains(e, "channel 'active_blocks'"));
    EXPECT_TRUE(test::Contains(e, "bytes; the header's band needs"));
    h = header_;
    h["band"]["blocks"] = 7;
    EXPECT_TRUE(test::Contains(error_with(h), "band.blocks"));
    h = header_;
    h["band"]["width"] = -1.0;
    EXPECT_TRUE(test::Contains(error_with(h), "band.width"));
    h = header_;
    h["band"]["mixed_blocks"] = header_["band"]["blocks"];
    EXPECT_TRUE(test::Contains(error_with(h), "band.mixed_blocks"));
    h = header_;
    h["channels"]["distance"]["dtype"] = "int32";
    EXPECT_TRUE(test::Contains(error_with(h), "dtype"));
    h = header_;
    h["channels"].erase("mixed_signs");
    EXPECT_TRUE(test::Contains(error_with(h), "mixed_signs"));
    h = header_;
    h["layout"] = "dense";
    EXPECT_TRUE(test::Contains(error_with(h), "layout"));
    // The dense reader names the layout it cannot read.
    test::write_file(at("h.json"), header_.dump(2));
    EXPECT_TRUE(test::Contains(test::error_of([&] { read_field(at("h.json")); }), "sparse_band"));

    // A truncated channel, ids out of order or out of range, a block both active and mixed.
    const std::string ids = test::read_text(channel("active_blocks"));
    test::write_file(channel("distance"), test::read_text(channel("distance")).substr(1));
    e = test::error_of([&] { read_sparse_field(at("h.json")); });
    EXPECT_TRUE(test::Contains(e, "channel 'distance'"));
    EXPECT_TRUE(test::Contains(e, "h.json"));
    write_sparse_field(at("h.json"), band_, {FieldDtype::Float32, true, Overwrite::Allow});
    header_ = test::read_json(at("h.json"));
    std::string swapped = test::read_text(channel("active_blocks"));
    std::swap_ranges(swapped.begin(), swapped.begin() + 8, swapped.begin() + 8);
    test::write_file(channel("active_blocks"), swapped);
    EXPECT_TRUE(test::Contains(test::error_of([&] { read_sparse_field(at("h.json")); }), "must ascend"));
    std::string far = swapped;
    const int64_t beyond = band_.layout().block_count();
    std::memcpy(far.data() + far.size() - 8, &beyond, 8);
    std::swap_ranges(far.begin(), far.begin() + 8, far.begin() + 8);
    test::write_file(channel("active_blocks"), far);
    EXPECT_TRUE(test::Contains(test::error_of([&] { read_sparse_field(at("h.json")); }), "is not a block of the lattice"));
    if (!band_.mixed.empty()) {
        test::write_file(channel("active_blocks"), ids);
        std::string mixed = test::read_text(channel("mixed_blocks"));
        std::memcpy(mixed.data(), &band_.active[0], 8);
        if (band_.mixed.size() == 1 || band_.active[0] < band_.mixed[1]) {
            test::write_file(channel("mixed_blocks"), mixed);
            EXPECT_TRUE(test::Contains(test::error_of([&] { read_sparse_field(at("h.json")); }), "also active"));
        }
    }
}

TEST_F(HostileSparseFile, ValuesThatContradictTheMarksAreRefused) {
    // A band point must hold |d| <= W and any other point +-W: a file that says otherwise
    // would give level sets with active voxels outside the band.
    write_sparse_field(at("h.json"), band_, {FieldDtype::Float64, true, Overwrite::Allow});
    header_ = test::read_json(at("h.json"));
    const std::string values = test::read_text(channel("distance"));
    int64_t in = -1, out = -1;
    for (size_t a = 0; a < band_.active.size(); ++a)
        for (int local = 0; local < kBandBlockPoints; ++local) {
            if (band_.layout().storage_index(band_.active[a], local) < 0) continue;
            (band_.in_band(a, local) ? in : out) = int64_t(a) * kBandBlockPoints + local;
        }
    ASSERT_GE(in, 0);
    ASSERT_GE(out, 0);
    for (const auto& [at_point, value, expected] : {std::tuple{in, 2 * band_.width, "a band point"},
                                                    std::tuple{out, 0.5 * band_.width, "outside the band"}}) {
        std::string bad = values;
        std::memcpy(bad.data() + 8 * at_point, &value, 8);
        test::write_file(channel("distance"), bad);
        const std::string e = test::error_of([&] { read_sparse_field(at("h.json")); });
        EXPECT_TRUE(test::Contains(e, "h.json") && test::Contains(e, "channel 'distance'") && test::Contains(e, expected)) << e;
    }
    test::write_file(channel("distance"), values);
    read_sparse_field(at("h.json"));
}

TEST_F(HostileSparseFile, ReplacedWholeAndNeverSilently) {
    // Refused without permission to overwrite; replaced whole with it, and the old files go.
    EXPECT_TRUE(test::Contains(test::error_of([&] { write_sparse_field(at("h.json"), band_); }), "already exists"));
    const std::string old_distance = channel("distance");
    write_sparse_field(at("h.json"), band_, {FieldDtype::Float64, true, Overwrite::Allow});
    const nlohmann::json now = test::read_json(at("h.json"));
    EXPECT_EQ(now["channels"]["distance"]["dtype"], "float64");
    expect_same_band(band_, read_sparse_field(at("h.json")), "replaced");
    // A dense field written over it removes the sparse channels.
    write_field(at("h.json"), band_.densify(), {FieldDtype::Float32, Overwrite::Allow, true});
    for (const auto& entry : fs::directory_iterator(dir_))
        EXPECT_EQ(entry.path().filename().string().find("blocks"), std::string::npos) << entry.path();
    EXPECT_FALSE(is_sparse_field_file(at("h.json")));
}

}  // namespace
}  // namespace sdf
