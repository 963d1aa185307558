// sdf-sample's streaming (harness/sampling/streamed_sampling.h): a lattice sampled slab by
// slab under a tiny memory budget writes channel files equal byte for byte to the in-memory
// writer's (write_field) for the same lattice: CC and BCC, float32 and float64, with and
// without a narrow band, all channels or some, from a sampler's fields or from its stored
// slabs (the bytes path the CUDA BVH sampler takes, here from a CPU stand-in); the plan refuses budgets too small, existing
// outputs are kept, and the tool's command line refuses bad budget strings with exit 2.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "core/lattice/lattice_fitting.h"
#include "core/mesh/shapes/procedural_shapes.h"
#include "cpu_reference/bvh/bvh_cpu.h"
#include "harness/io/field_file.h"
#include "harness/io/sparse_field_file.h"
#include "harness/resources/memory_budget.h"
#include "harness/sampling/streamed_sampling.h"
#include "harness_test_util.h"

#if SDF_HAVE_OPENVDB
#include <openvdb/openvdb.h>
#endif
#include "harness/io/volume_formats.h"
#include "tests/test_util/shared_mesh.h"

#if !defined(SDF_SAMPLE_EXE) || !defined(RUN_EXPERIMENT_EXE)
#error "SDF_SAMPLE_EXE and RUN_EXPERIMENT_EXE must be defined by CMake"
#endif

namespace sdf {
namespace {

namespace fs = std::filesystem;

std::string bytes_of(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

SamplerOptions sampler_options(double band) {
    SamplerOptions o;
    o.backend = "cpu";
    o.method = "bvh";
    o.band_width = band;
    o.progress = false;
    return o;
}

/// A bound CPU sampler that also gives its slabs as stored bytes (BoundSampler::
/// sample_slab_stored), made by the field writer's own conversion: the streamed writer's
/// bytes path, tested without a GPU.
class StoringSampler final : public BoundSampler {
public:
    StoringSampler(std::unique_ptr<BoundSampler> inner, double band)
        : BoundSampler(inner->shared_mesh()), inner_(std::move(inner)), band_(band) {}
    std::string name() const override { return inner_->name(); }
    const SignModeChoice& sign() const override { return inner_->sign(); }
    SampledField sample_slab(const Lattice& l, const LatticeSlab& s) const override { return inner_->sample_slab(l, s); }
    std::vector<PointSample> query(const std::vector<Vec3d>& p, SamplingTimings* t) const override { return inner_->query(p, t); }
    std::optional<StoredSlab> sample_slab_stored(const Lattice& l, const LatticeSlab& s, const StoredLayout& layout) const override {
        auto field = std::make_shared<SampledField>(inner_->sample_slab(l, s));
        const NarrowBandCounts counts = apply_narrow_band(*field, band_);
        const FieldDtype dtype = layout.float32 ? FieldDtype::Float32 : FieldDtype::Float64;
        auto bytes = std::make_shared<std::vector<std::vector<char>>>();
        const size_t n = size_t(field->size());
        bytes->push_back(field_channel_bytes(*field, {"distance", "", dtype, 1}, 0, n));
        bytes->push_back(field_channel_bytes(*field, {"gradient", "", dtype, 3}, 0, n));
        bytes->push_back(field_channel_bytes(*field, {"closest_triangle", "", dtype, 1}, 0, n));
        StoredSlab stored;
        stored.points = field->size();
        stored.distance = (*bytes)[0].data();
        stored.gradient = layout.gradient ? (*bytes)[1].data() : nullptr;
        stored.closest_triangle = layout.closest_triangle ? (*bytes)[2].data() : nullptr;
        stored.band = counts;
        field->distance.clear();
        field->gradient.clear();
        field->closest_triangle.clear();
        stored.info = *field;
        stored.storage = bytes;
        ++stored_slabs;
        return stored;
    }
    mutable int stored_slabs = 0;

private:
    std::unique_ptr<BoundSampler> inner_;
    double band_;
};

const PreparedMesh& torus() {
    static const PreparedMesh mesh = prepare_mesh(make_torus(1.0, 0.35, 32, 16));
    return mesh;
}

TEST(StreamedSampling, ChannelFilesEqualTheInMemoryWriterByteForByte) {
    test::ScratchDir dir("streamed_sampling");
    const PreparedMesh& mesh = torus();
    const Lattice cc = fit_lattice(LatticeType::CC, {13, 14, 15}, mesh.bounds(), 0.1);
    const Lattice bcc = fit_lattice(LatticeType::BCC, {11, 12, 9}, mesh.bounds(), 0.1);
    int n = 0;
    for (const Lattice& lattice : {cc, bcc})
        for (FieldDtype dtype : {FieldDtype::Float32, FieldDtype::Float64})
            for (double band : {0.0, 2.0 * lattice.spacing})
                for (int gradient_and_triangle : {1, 0})
                    for (bool stored_slabs : {false, true}) {
                        const std::string what = lattice_notation(lattice) + (dtype == FieldDtype::Float32 ? " float32" : " float64") +
                                                 " band " + std::to_string(band) + (gradient_and_triangle ? " all channels" : " distance only") +
                                                 (stored_slabs ? ", stored slabs" : ", fields");
                        const std::string tag = std::to_string(n++);
                        SampledField field = make_cpu_bvh_sampler(sampler_options(band))->bind(share(mesh))->sample(lattice);
                        FieldWriteOptions write;
                        write.dtype = dtype;
                        write.closest_triangle = gradient_and_triangle != 0;
                        if (!gradient_and_triangle) field.gradient.clear();
                        const std::string memory = dir.at("memory" + tag + ".json"), streamed = dir.at("streamed" + tag + ".json");
                        write_field(memory, field, write);

                        StreamOptions stream;
                        stream.header_path = streamed;
                        stream.write = write;
                        stream.gradient = gradient_and_triangle != 0;
                        stream.fixed_bytes = 1 << 20;
                        // Room for two slabs of 2 z-planes: 7 or 8 slabs.
                        const int64_t plane = int64_t(lattice.resolution.x) * lattice.resolution.y * 2;
                        stream.memory_budget = stream.fixed_bytes + 2 * 2 * uint64_t(plane) * kStreamBytesPerPoint;
                        stream.progress = false;
                        const SamplerOptions options = sampler_options(band);
                        std::unique_ptr<BoundSampler> sampler = make_cpu_bvh_sampler(options)->bind(share(mesh));
                        if (stored_slabs) sampler = std::make_unique<StoringSampler>(std::move(sampler), band);
                        const StreamResult r = sample_streamed(*sampler, options, lattice, stream, describe_prepared_mesh(mesh));
                        EXPECT_GE(r.plan.slabs, 4) << what;
                        if (stored_slabs) {
                            EXPECT_EQ(static_cast<StoringSampler&>(*sampler).stored_slabs, r.plan.slabs) << what;
                        }
                        for (const FieldChannelFile& c : r.plan.channels) {
                            const std::string mem_file = dir.at("memory" + tag + "." + c.name + ".raw");
                            ASSERT_TRUE(fs::exists(mem_file)) << what << " " << c.name;
                            EXPECT_TRUE(bytes_of(mem_file) == bytes_of(c.path)) << what << ": channel " << c.name << " differs";
                        }
                        EXPECT_EQ(r.plan.channels.size(), gradient_and_triangle ? 3u : 1u) << what;
                        const SampledField back = read_field(streamed);
                        EXPECT_EQ(back.distance.size(), size_t(lattice.num_points())) << what;
                        const nlohmann::json header = test::read_json(streamed);
                        EXPECT_EQ(header["sampler"]["streaming"]["slabs"], r.plan.slabs) << what;
                        EXPECT_GT(header["sampler"]["streaming"]["peak_resident_bytes"].get<uint64_t>(), 0u) << what;
                        if (band > 0) {
                            const NarrowBandCounts counts = count_narrow_band(field);
                            EXPECT_EQ(header["sampler"]["band"]["points_in_band"].get<int64_t>(), counts.in_band) << what;
                            EXPECT_EQ(header["sampler"]["band"]["points_outside"].get<int64_t>(), counts.outside) << what;
                        }
                        // No temporaries left beside the outputs.
                        for (const auto& e : fs::directory_iterator(dir.path()))
                            EXPECT_NE(e.path().filename().string().front(), '.') << e.path();
                        if (HasFailure()) return;
                    }
}

#if SDF_HAVE_OPENVDB
/// Every grid of `a` is in `b` with the same background and the same active voxels and values.
void expect_same_vdb(const std::string& a, const std::string& b, const std::string& what) {
    openvdb::initialize();
    openvdb::io::File fa(a), fb(b);
    fa.open();
    fb.open();
    const openvdb::GridPtrVecPtr ga = fa.getGrids(), gb = fb.getGrids();
    ASSERT_EQ(ga->size(), gb->size()) << what;
    for (size_t g = 0; g < ga->size(); ++g) {
        const openvdb::GridBase::Ptr other = fb.readGrid((*ga)[g]->getName());
        EXPECT_EQ((*ga)[g]->activeVoxelCount(), other->activeVoxelCount()) << what << " " << (*ga)[g]->getName();
        if (auto fa_grid = openvdb::gridPtrCast<openvdb::FloatGrid>((*ga)[g])) {
            auto fb_grid = openvdb::gridPtrCast<openvdb::FloatGrid>(other);
            ASSERT_TRUE(fb_grid) << what;
            EXPECT_EQ(fa_grid->background(), fb_grid->background()) << what;
            auto acc = fb_grid->getConstAccessor();
            for (auto it = fa_grid->cbeginValueOn(); it; ++it) {
                EXPECT_TRUE(acc.isValueOn(it.getCoord())) << what;
                EXPECT_EQ(*it, acc.getValue(it.getCoord())) << what;
            }
        } else if (auto va = openvdb::gridPtrCast<openvdb::Vec3fGrid>((*ga)[g])) {
            auto vb = openvdb::gridPtrCast<openvdb::Vec3fGrid>(other);
            ASSERT_TRUE(vb) << what;
            auto acc = vb->getConstAccessor();
            for (auto it = va->cbeginValueOn(); it; ++it) EXPECT_EQ(*it, acc.getValue(it.getCoord())) << what;
        }
    }
}

TEST(StreamedSampling, NarrowBandVdbEqualsTheInMemoryExport) {
    test::ScratchDir dir("streamed_vdb");
    const PreparedMesh& mesh = torus();
    const Lattice cc = fit_lattice(LatticeType::CC, {24, 25, 26}, mesh.bounds(), 0.1);
    const Lattice bcc = fit_lattice(LatticeType::BCC, {17, 18, 15}, mesh.bounds(), 0.1);
    int n = 0;
    for (const Lattice& lattice : {cc, bcc}) {
        const std::string tag = std::to_string(n++), what = lattice_notation(lattice);
        const double w = 2.0 * lattice.spacing;
        const SampledField field = make_cpu_bvh_sampler(sampler_options(w))->bind(share(mesh))->sample(lattice);
        VolumeWriteOptions v;
        v.vdb_band = 2.0;
        write_field_as(field, dir.at("memory" + tag + ".vdb"), VolumeFormat::Vdb, v);
        StreamOptions stream;
        stream.header_path = dir.at("streamed" + tag + ".json");
        stream.fixed_bytes = 1 << 20;
        stream.memory_budget = 64 << 20;
        stream.max_planes_per_slab = 3;
        stream.progress = false;
        stream.vdb_path = dir.at("streamed" + tag + ".vdb");
        stream.vdb_band = w;
        const SamplerOptions options = sampler_options(w);
        const auto sampler = make_cpu_bvh_sampler(options)->bind(share(mesh));
        const StreamResult r = sample_streamed(*sampler, options, lattice, stream, {});
        EXPECT_GE(r.plan.slabs, 5) << what;
        EXPECT_GT(r.vdb_active_points, 100) << what;
        EXPECT_LE(r.vdb_active_points, count_narrow_band(field).in_band) << what;
        expect_same_vdb(dir.at("memory" + tag + ".vdb"), stream.vdb_path, what + " memory vs streamed");
        expect_same_vdb(stream.vdb_path, dir.at("memory" + tag + ".vdb"), what + " streamed vs memory");
    }
}
#endif

TEST(StreamedSampling, RefusesSmallBudgetsAndExistingOutputs) {
    test::ScratchDir dir("streamed_refusals");
    const Lattice lattice = fit_lattice(LatticeType::CC, {16, 16, 16}, torus().bounds(), 0.1);
    StreamOptions stream;
    stream.header_path = dir.at("f.json");
    stream.fixed_bytes = 10 << 20;
    stream.memory_budget = 10 << 20;
    try {
        plan_streamed_sampling(lattice, stream);
        ADD_FAILURE() << "a budget below the fixed part was accepted";
    } catch (const std::runtime_error& e) {
        EXPECT_TRUE(test::Contains(e.what(), "give at least 10 MiB (10518528 bytes)"));
    }
    stream.memory_budget = 64 << 20;
    stream.progress = false;
    dir.write("f.distance.raw", "someone's data");
    const SamplerOptions options = sampler_options(0);
    const auto sampler = make_cpu_bvh_sampler(options)->bind(share(torus()));
    EXPECT_THROW(sample_streamed(*sampler, options, lattice, stream, {}), std::runtime_error);
    EXPECT_EQ(test::read_text(dir.at("f.distance.raw")), "someone's data");
    EXPECT_FALSE(fs::exists(dir.at("f.json")));
}

TEST(StreamedSampling, ByteSizesParseOrFailByName) {
    EXPECT_EQ(parse_byte_size("8GiB", "b"), uint64_t(8) << 30);
    EXPECT_EQ(parse_byte_size("256 MiB", "b"), uint64_t(256) << 20);
    EXPECT_EQ(parse_byte_size("1.5g", "b"), uint64_t(3) << 29);
    EXPECT_EQ(parse_byte_size("2GB", "b"), uint64_t(2000000000));
    EXPECT_EQ(parse_byte_size("1000", "b"), uint64_t(1000));
    for (const char* bad : {"-1", "1e30GiB", "abc", "", "0", "0.1", ".", "1.2.3G", "5 XB", "9999999TiB"}) {
        try {
            parse_byte_size(bad, "--memory-budget");
            ADD_FAILURE() << "accepted " << bad;
        } catch (const std::invalid_argument& e) {
            EXPECT_TRUE(test::Contains(e.what(), "--memory-budget")) << e.what();
        }
    }
}

TEST(StreamedSampling, ToolRefusesBadOptionsWithExitTwoAndWritesWhatItPlans) {
    test::ScratchDir dir("sdf_sample_cli");
    const std::string exe = test::quote(SDF_SAMPLE_EXE);
    for (const char* budget : {"-1", "1e30GiB", "abc"}) {
        const test::ShellResult r =
            test::run_in(dir.path(), exe + " shape:sphere --resolution 8 --out f.json --memory-budget " + test::quote(budget));
        EXPECT_EQ(r.code, 2) << budget << ": " << r.err;
        EXPECT_TRUE(test::Contains(r.err, "--memory-budget")) << r.err;
    }
    for (const std::string& args : {std::string("--resolution 8 8 --out f.json"), std::string("--resolution 8 --out f.npy"),
                                    std::string("--resolution 8 --out f.json --channels gradient"),
                                    std::string("--resolution 8 --out f.json --band -1"),
                                    std::string("--resolution 0 --out f.json"),
                                    std::string("--lattice bcc --resolution 8 8 9 --out f.json"),
                                    std::string("--resolution 8 --out f.json --channels distance,normals")}) {
        const test::ShellResult r = test::run_in(dir.path(), exe + " shape:sphere " + args);
        EXPECT_EQ(r.code, 2) << args << ": " << r.err;
    }
    // The sampler flags are the options codec's keys: its checks and messages, as a config's.
    const test::ShellResult band = test::run_in(dir.path(), exe + " shape:sphere --resolution 8 --out f.json --band -1");
    EXPECT_TRUE(test::Contains(band.err, "key 'sampler.band_width': expected a band width in mesh units")) << band.err;
    const test::ShellResult kernel = test::run_in(dir.path(), exe + " shape:sphere --resolution 8 --out f.json --kernel seeded");
    EXPECT_EQ(kernel.code, 2) << kernel.err;
    EXPECT_TRUE(test::Contains(kernel.err, "a kernel needs the backend cpu or cuda")) << kernel.err;
    const test::ShellResult plan = test::run_in(dir.path(), exe + " shape:sphere --lattice bcc --resolution 10 --out f.json --dry-run");
    EXPECT_EQ(plan.code, 0) << plan.err;
    EXPECT_TRUE(test::Contains(plan.out, "10x10x20"));
    EXPECT_TRUE(test::Contains(plan.out, "memory: budget"));
    EXPECT_FALSE(fs::exists(dir.at("f.json")));
    const test::ShellResult run = test::run_in(
        dir.path(), exe + " shape:sphere --resolution 12 --out f.json --memory-budget 256MiB --max-planes-per-slab 3 --quiet");
    EXPECT_EQ(run.code, 0) << run.err;
    EXPECT_TRUE(test::Contains(run.out, "in 4 slabs"));
    EXPECT_EQ(read_field(dir.at("f.json")).distance.size(), 12u * 12u * 12u);
    const test::ShellResult again = test::run_in(dir.path(), exe + " shape:sphere --resolution 12 --out f.json --quiet");
    EXPECT_EQ(again.code, 1);
    EXPECT_TRUE(test::Contains(again.err, "already exists"));
}

TEST(StreamedSampling, ToolEqualsRunExperimentFieldsByteForByte) {
    test::ScratchDir dir("sdf_sample_vs_run_experiment");
    dir.write("c.json", R"({"name": "stream_e2e", "kind": "reconstruction", "mesh": {"shape": "torus"},
        "domain": {"margin": 0.1},
        "lattices": [{"type": "cc", "resolution": [14, 15, 16]}, {"type": "bcc", "resolution": [11, 11, 22]}],
        "sampler": {"backend": "cpu", "method": "bvh", "precision": "float", "progress": false},
        "metrics": {"domain_probes": 10, "band_probes": 10, "band": 1.0, "seed": 1}})");
    const test::ShellResult run = test::run_in(
        dir.path(), test::quote(RUN_EXPERIMENT_EXE) + " c.json --output-root results --no-cache --quiet");
    ASSERT_EQ(run.code, 0) << run.err;
    fs::path fields;
    for (const auto& e : fs::directory_iterator(dir.path() / "results" / "stream_e2e")) fields = e.path() / "fields";
    const std::string exe = test::quote(SDF_SAMPLE_EXE) + " shape:torus --backend cpu --margin 0.1 --memory-budget 256MiB --quiet";
    const test::ShellResult cc = test::run_in(dir.path(), exe + " --resolution 14 15 16 --max-planes-per-slab 3 --out cc.json");
    const test::ShellResult bcc = test::run_in(dir.path(), exe + " --lattice bcc --resolution 11 11 22 --max-planes-per-slab 2 --out bcc.json");
    ASSERT_EQ(cc.code, 0) << cc.err;
    ASSERT_EQ(bcc.code, 0) << bcc.err;
    EXPECT_TRUE(test::Contains(cc.out, "in 6 slabs"));
    EXPECT_TRUE(test::Contains(bcc.out, "in 6 slabs"));
    for (const char* channel : {"distance", "gradient", "closest_triangle"}) {
        const std::string c = std::string(".") + channel + ".raw";
        EXPECT_TRUE(bytes_of((fields / ("torus-cc-14x15x16" + c)).string()) == bytes_of(dir.at("cc" + c))) << channel;
        EXPECT_TRUE(bytes_of((fields / ("torus-bcc-11x11x22" + c)).string()) == bytes_of(dir.at("bcc" + c))) << channel;
        EXPECT_GT(bytes_of(dir.at("cc" + c)).size(), 0u);
    }
}

// Issue 35: --sparse samples only the band's blocks; the files it writes (slab by slab from
// the sparse band) are the dense --band run's, byte for byte; without a band it is refused.
TEST(StreamedSampling, SparseBandWritesTheDenseBandsBytes) {
    test::ScratchDir dir("sdf_sample_sparse");
    const std::string exe = test::quote(SDF_SAMPLE_EXE) + " --backend cpu --margin 0.3 --memory-budget 256MiB --quiet";
    for (const std::string& mesh : {std::string("shape:torus"), std::string("shape:pawn")})
        for (const std::string& lattice : {std::string("--resolution 30 29 28"), std::string("--lattice bcc --resolution 21 20 38")}) {
            const std::string args = " " + mesh + " " + lattice + " --band 0.12 --max-planes-per-slab 7";
            const test::ShellResult dense = test::run_in(dir.path(), exe + args + " --out d.json --overwrite");
            const test::ShellResult sparse = test::run_in(dir.path(), exe + args + " --sparse --out s.json --overwrite");
            ASSERT_EQ(dense.code, 0) << dense.err;
            ASSERT_EQ(sparse.code, 0) << sparse.err;
            EXPECT_TRUE(test::Contains(sparse.out, "sparse band: ")) << sparse.out;
            for (const char* channel : {"distance", "gradient", "closest_triangle"}) {
                const std::string c = std::string(".") + channel + ".raw";
                EXPECT_TRUE(bytes_of(dir.at("d" + c)) == bytes_of(dir.at("s" + c))) << mesh << " " << lattice << " " << channel;
            }
            const SampledField d = read_field(dir.at("d.json")), f = read_field(dir.at("s.json"));
            ASSERT_TRUE(d.sampler.band && f.sampler.band);
            EXPECT_EQ(d.sampler.band->points_in_band, f.sampler.band->points_in_band);
            EXPECT_EQ(d.sampler.band->points_outside, f.sampler.band->points_outside);
            EXPECT_TRUE(test::Contains(f.sampler.band->how, "sparse")) << f.sampler.band->how;
        }
    const test::ShellResult no_band = test::run_in(dir.path(), exe + " shape:sphere --resolution 8 --sparse --out n.json");
    EXPECT_EQ(no_band.code, 2) << no_band.err;
    EXPECT_TRUE(test::Contains(no_band.err, "--sparse: expected a narrow band")) << no_band.err;
}

// Issue 35: --layout sparse writes the field file's sparse variant (sparse_field_file.h):
// densified it is the dense --band run's field; sdf-eval reads it and prints what it prints
// for the dense file, warning about the points off the band's cells, from the band's blocks
// (with less memory than the dense field needs).
TEST(StreamedSampling, SparseLayoutReadsBackAsTheDenseBand) {
    test::ScratchDir dir("sdf_sample_sparse_layout");
    const std::string exe = test::quote(SDF_SAMPLE_EXE) + " --backend cpu --margin 0.3 --quiet";
    for (const std::string& lattice : {std::string("--resolution 30 29 28"), std::string("--lattice bcc --resolution 21 20 38")}) {
        const std::string args = " shape:torus " + lattice + " --band 0.12";
        const test::ShellResult dense = test::run_in(dir.path(), exe + args + " --out d.json --overwrite");
        const test::ShellResult sparse =
            test::run_in(dir.path(), exe + args + " --sparse --layout sparse --out s.json --overwrite");
        ASSERT_EQ(dense.code, 0) << dense.err;
        ASSERT_EQ(sparse.code, 0) << sparse.err;
        EXPECT_TRUE(test::Contains(sparse.out, "the sparse band's field file")) << sparse.out;
        EXPECT_TRUE(is_sparse_field_file(dir.at("s.json")));
        const SampledField d = read_field(dir.at("d.json")), f = read_sparse_field(dir.at("s.json")).densify();
        EXPECT_TRUE(d.distance == f.distance) << lattice;
        EXPECT_TRUE(d.closest_triangle == f.closest_triangle) << lattice;
        ASSERT_EQ(d.gradient.size(), f.gradient.size());
        EXPECT_EQ(std::memcmp(d.gradient.data(), f.gradient.data(), d.gradient.size() * sizeof(Vec3d)), 0) << lattice;
        // sdf-eval: the same lines for both files, on and off the band.
        std::string points;
        for (int i = 0; i < 60; ++i) points += std::to_string(-1.2 + 0.04 * i) + " " + std::to_string(0.02 * i - 0.3) + " 0.05\n";
        test::write_file(dir.at("p.txt"), points);
        const std::string interp = lattice.find("bcc") != std::string::npos ? "bcc_cubic" : "tricubic_lm";
        const std::string eval = test::quote(SDF_EVAL_EXE) + " --interpolator " + interp + " --threads 1 ";
        const test::ShellResult from_dense = test::run_in(dir.path(), eval + "d.json p.txt");
        const test::ShellResult from_sparse = test::run_in(dir.path(), eval + "s.json p.txt");
        ASSERT_EQ(from_dense.code, 0) << from_dense.err;
        ASSERT_EQ(from_sparse.code, 0) << from_sparse.err;
        EXPECT_EQ(from_dense.out, from_sparse.out);
        EXPECT_TRUE(test::Contains(from_sparse.err, "outside the sparse band's cells")) << from_sparse.err;
        // The band is reconstructed from its blocks: with less memory than its dense field
        // needs (36 bytes a point), the same lines; a filter that only densifies is refused.
        const std::string small = "SDF_MEMORY_AVAILABLE=" + std::to_string(d.size() * 36 / 2) + " ";
        const test::ShellResult from_blocks = test::run_in(dir.path(), small + eval + "s.json p.txt");
        ASSERT_EQ(from_blocks.code, 0) << from_blocks.err;
        EXPECT_EQ(from_blocks.out, from_dense.out);
        const std::string global = lattice.find("bcc") != std::string::npos ? "bcc_box_quintic" : "cc_bspline3";
        const test::ShellResult refused_dense = test::run_in(
            dir.path(), small + test::quote(SDF_EVAL_EXE) + " --interpolator " + global + " --threads 1 s.json p.txt");
        EXPECT_EQ(refused_dense.code, 1) << refused_dense.out;
        EXPECT_TRUE(test::Contains(refused_dense.err, "densifying the sparse band of s.json")) << refused_dense.err;
    }
    const test::ShellResult refused =
        test::run_in(dir.path(), exe + " shape:sphere --resolution 8 --band 0.1 --layout sparse --out n.json");
    EXPECT_EQ(refused.code, 2) << refused.err;
    EXPECT_TRUE(test::Contains(refused.err, "--layout sparse")) << refused.err;
    // --out may be left out only where level sets alone are written from a sparse band.
    for (const std::string& args : {std::string(" shape:sphere --resolution 8 --band 0.1"),
                                    std::string(" shape:sphere --resolution 8 --band 0.1 --sparse"),
                                    std::string(" shape:sphere --resolution 8 --band 0.1 --vdb n.vdb")}) {
        const test::ShellResult no_out = test::run_in(dir.path(), exe + args);
        EXPECT_EQ(no_out.code, 2) << args << ": " << no_out.err;
        EXPECT_TRUE(test::Contains(no_out.err, "--out: expected a field file header NAME.json (only --sparse with --vdb"))
            << no_out.err;
    }
}

// A sparse band's own field file may have a lattice no dense field may (max_lattice_points):
// 8192^3 around a sphere that spans a hundred of its spacings runs, and reads back with its
// lattice; the dense layout of the same lattice is refused before the mesh is loaded.
TEST(StreamedSampling, SparseLayoutTakesLatticesBeyondTheDenseLimit) {
    test::ScratchDir dir("sdf_sample_sparse_8192");
    const std::string exe = test::quote(SDF_SAMPLE_EXE) +
                            " --backend cpu --quiet shape:sphere --resolution 8192 --margin 50 --band 0.074 --sparse";
    const test::ShellResult dense = test::run_in(dir.path(), exe + " --out d.json");
    EXPECT_EQ(dense.code, 2) << dense.err;
    EXPECT_TRUE(test::Contains(dense.err, "more than the largest lattice sampled densely")) << dense.err;
    EXPECT_TRUE(test::Contains(dense.err, "a sparse narrow band may have up to 2^42")) << dense.err;
    const test::ShellResult sparse = test::run_in(dir.path(), exe + " --layout sparse --channels distance --out s.json");
    ASSERT_EQ(sparse.code, 0) << sparse.err;
    EXPECT_TRUE(test::Contains(sparse.out, "of 1073741824 blocks of 8^3 active")) << sparse.out;
    const SparseBandField back = read_sparse_field(dir.at("s.json"));
    EXPECT_EQ(back.lattice.resolution.x, 8192);
    EXPECT_EQ(back.lattice.num_points(), int64_t(1) << 39);
    EXPECT_GT(back.counts().band_points, 10000);
}

#if SDF_TEST_HAVE_NANOVDB
// --nvdb beside either field file: the streamed dense file and the sparse layout write the
// same NanoVDB level set, byte for byte (the sparse layout once returned before writing it).
TEST(StreamedSampling, NvdbIsWrittenBesideEitherFieldFile) {
    test::ScratchDir dir("sdf_sample_nvdb");
    const std::string exe = test::quote(SDF_SAMPLE_EXE) +
                            " --backend cpu --margin 0.3 --quiet shape:torus --resolution 30 29 28 --band 0.12 --sparse";
    const test::ShellResult streamed = test::run_in(dir.path(), exe + " --out d.json --nvdb d.nvdb");
    const test::ShellResult sparse = test::run_in(dir.path(), exe + " --layout sparse --out s.json --nvdb s.nvdb");
    ASSERT_EQ(streamed.code, 0) << streamed.err;
    ASSERT_EQ(sparse.code, 0) << sparse.err;
    EXPECT_TRUE(test::Contains(sparse.out, "wrote s.nvdb")) << sparse.out;
    const std::string a = test::read_text(dir.at("d.nvdb")), b = test::read_text(dir.at("s.nvdb"));
    EXPECT_EQ(a.substr(0, 8), "NanoVDB2");
    EXPECT_TRUE(a == b) << a.size() << " and " << b.size() << " bytes";
    // Without --out, the level set alone: the same bytes, and no field file.
    const test::ShellResult alone = test::run_in(dir.path(), exe + " --nvdb a.nvdb");
    ASSERT_EQ(alone.code, 0) << alone.err;
    EXPECT_TRUE(test::read_text(dir.at("a.nvdb")) == a);
    EXPECT_FALSE(test::Contains(alone.out, ".json")) << alone.out;
}
#endif

}  // namespace
}  // namespace sdf
