// sdf-sample MESH --resolution N|NX NY NZ --out NAME.json [--lattice cc|bcc] [--margin F]
//            [--method bvh|brute_force] [--backend auto|cpu|cuda] [--precision float|double]
//            [--sign auto|pseudonormal|winding] [--band W [--sparse [--layout sparse]]] [--memory-budget SIZE]
//            [--channels distance,gradient,closest_triangle] [--dtype float32|float64]
//            [--overwrite] [--dry-run] [--quiet]
//
// Samples a lattice fitted around the mesh (as run-experiment and the module's sample() fit
// it) slab by slab, streaming each slab into the field file's channels, so that the host's
// peak memory stays under the budget whatever the lattice's size
// (harness/sampling/streamed_sampling.h, docs/large-lattices.md). The channel files equal
// the in-memory writer's byte for byte. --dry-run prints the plan (slabs, memory, output
// size) and exits. --sparse (with --band W) samples only the blocks of 8^3 points within W of a
// triangle and signs the rest per block (core/sampling/sparse_band_sampler.h); the field file,
// the same bytes, is then written slab by slab from the sparse band, and --vdb straight from
// its blocks (harness/io/sparse_vdb_file.h: a level set, never densified), --nvdb a NanoVDB
// level set from the same blocks (harness/io/sparse_nvdb_file.h; builds with NanoVDB only), and
// --layout sparse the field file's sparse variant instead of the dense one
// (harness/io/sparse_field_file.h: the band's blocks, never densified; sdf-eval, sdf-render and
// Python's read_field read it); with --vdb or --nvdb, --out may be left out to write the level
// sets alone (the band's lattice may then be as large as a sparse field file's: up to 2^42
// points). A sparse band holds the gradient and the closest triangle only
// when --channels names them: without them, they are neither kept nor downloaded from a GPU
// (--channels distance: 8.125 bytes a point, not 36.125; the band's points are a bit mask),
// and with --dtype float32 (the default) its distances in float32 as written: 4.125 bytes.
#include <CLI/CLI.hpp>

#include "apps/cli_exit.h"
#include "apps/cli_validators.h"
#include "apps/sampler_cli.h"

#include <chrono>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

#include "core/lattice/lattice_fitting.h"
#include "core/quoted_alternatives.h"
#include "core/mesh/load_mesh.h"
#include "core/mesh/prepared_mesh.h"
#include "core/parallel/progress.h"
#include "harness/study/field_source.h"
#include "harness/config/json_reader.h"
#include "harness/config/lattice_spec.h"
#include "harness/config/mesh_spec.h"
#include "harness/config/sampler_spec.h"
#include "harness/io/atomic_file.h"
#include "harness/io/sparse_field_file.h"
#include "harness/io/sparse_nvdb_file.h"
#include "harness/io/sparse_vdb_file.h"
#include "harness/resources/memory_budget.h"
#include "harness/sampling/sampler_table.h"
#include "harness/sampling/sparse_band_slabs.h"
#include "harness/sampling/streamed_sampling.h"

namespace {

namespace fs = std::filesystem;

/// The default budget: half of the memory available now (8 GiB when unknown).
uint64_t default_memory_budget() {
    const uint64_t available = sdf::host_memory_available();
    return available > 0 ? available / 2 : uint64_t(8) << 30;
}

/// The output directory's free bytes; refuses when the channels do not fit.
void require_output_space(const sdf::StreamPlan& plan, const std::string& out) {
    const fs::path dir = fs::absolute(out).parent_path();
    if (!fs::is_directory(dir)) throw std::runtime_error(out + ": the output folder " + dir.string() + " does not exist");
    std::error_code ec;
    const fs::space_info space = fs::space(dir, ec);
    if (ec) throw std::runtime_error(dir.string() + ": cannot read the free space (" + ec.message() + ")");
    if (space.available < plan.output_bytes)
        throw std::runtime_error(out + ": the output needs " + sdf::format_bytes(plan.output_bytes) + " and " + dir.string() +
                                 " has " + sdf::format_bytes(space.available) +
                                 " free; choose fewer --channels, --dtype float32, or another directory");
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"Samples the exact signed distance of a mesh on a CC or BCC lattice slab by slab, streaming the "
                 "field file to disk under a memory budget."};
    sdf::add_version_flag(app, "sdf-sample");
    std::string mesh_arg, out_path, lattice_type = sdf::lattice_type_name(sdf::LatticeType::CC);
    std::string budget_text, channels_text = "distance,gradient,closest_triangle";
    std::string dtype = "float32";
    std::vector<int> resolution;
    double margin = 0.1;
    int max_planes = 0;
    sdf::SamplerCli sampler;  // the options codec's flags, defaults and checks (apps/sampler_cli.h)
    bool overwrite = false, dry_run = false, quiet = false, sparse = false;
    std::string layout = "dense";
    app.add_option("mesh", mesh_arg, "mesh file (" + sdf::mesh_formats_help() + ") or shape:NAME")->required();
    app.add_option("--lattice", lattice_type, "lattice type: " + sdf::quoted_alternatives(sdf::lattice_type_names()))
        ->check(CLI::IsMember(sdf::lattice_type_names()))->capture_default_str();
    app.add_option("--resolution", resolution,
                   "N or NX NY NZ: CC points per axis; BCC in the thesis's notation Rx Ry 2Rz (N: N N 2N)")
        ->required()
        ->expected(1, 3)
        ->check(sdf::kPositiveNumber);
    app.add_option("--margin", margin, "fraction of the mesh's largest extent added on every side")
        ->check(sdf::kNonNegativeNumber)
        ->capture_default_str();
    sampler.add(app, "--method", "method", "search: bvh or brute_force");
    sampler.add(app, "--backend", "backend", "cpu, cuda, or auto (cuda when a GPU is present)");
    sampler.add(app, "--kernel", "kernel", "backend kernel (" + sdf::sampler_kernels_help() + ")");
    sampler.add(app, "--threads", "threads", "CPU threads (0 = all)");
    sampler.add(app, "--device", "device", "CUDA device ordinal (with the default --devices)");
    sampler.add(app, "--devices", "devices",
                "several GPUs of this machine: all, or a list such as 0,1 (the work split over them, the results "
                "one GPU's bit for bit)");
    sampler.add(app, "--min-points-per-device", "min_points_per_device",
                "with --devices, the fewest points a GPU is given before a job is split over several (smaller jobs "
                "run on the first; docs/distributed.md)");
    sampler.add(app, "--precision", "precision", "float or double");
    sampler.add(app, "--sign", "sign", "sign mode: auto, pseudonormal or winding");
    sampler.add(app, "--band", "band_width",
                "narrow band width in mesh units: exact values where |d| <= W, elsewhere +-W, gradient 0 and "
                "closest_triangle -2 (0: no band)");
    app.add_flag("--sparse", sparse,
                 "with --band W: sample only the blocks of 8^3 points within W of a triangle and sign the rest per "
                 "block (work and memory grow with the band); the outputs are the same bytes");
    app.add_option("--layout", layout,
                   "the field file at --out: dense (every lattice point) or sparse (with --sparse: the band's blocks, tiles "
                   "and per-point signs, docs/field-format.md; its closest_triangle channel marks the band's points, or, "
                   "without closest_triangle in --channels, its band_points bit mask)")
        ->check(CLI::IsMember({"dense", "sparse"}))
        ->capture_default_str();
    app.add_option("--memory-budget", budget_text,
                   "peak host memory to stay under, e.g. 8GiB or 512MiB (default: half of the available memory)");
    app.add_option("--channels", channels_text,
                   "comma-separated channels to write: distance (always), gradient, closest_triangle (with --sparse, the "
                   "band keeps only the channels named)")
        ->capture_default_str();
    app.add_option("--dtype", dtype, "float32 or float64 for distance and gradient")
        ->check(CLI::IsMember({"float32", "float64"}))
        ->capture_default_str();
    app.add_option("--out", out_path,
                   "the field file's header, NAME.json (channels NAME.<channel>.raw beside it); required unless --sparse "
                   "writes only level sets (--vdb, --nvdb)");
    std::string vdb_path;
    app.add_option("--vdb", vdb_path,
                   "also write a narrow-band OpenVDB level set here (FILE.vdb): points with |d| < the band active (--band W, "
                   "else 3 spacings), built as the slabs arrive; with --sparse, straight from the band's blocks: a level set "
                   "with its points with |d| <= W active, inside blocks -W tiles, plus the gradient grid when --channels "
                   "names it");
    std::string nvdb_path;
    app.add_option("--nvdb", nvdb_path,
                   "with --band W --sparse: also write a NanoVDB level set here (FILE.nvdb), straight from the band's "
                   "blocks: the .vdb's distance grids (points with |d| <= W active, inside blocks -W tiles, BCC as its "
                   "two named grids); only in builds with NanoVDB");
    app.add_option("--max-planes-per-slab", max_planes, "at most this many z-planes per slab (0: from the budget)")
        ->check(sdf::kNonNegativeNumber);
    app.add_flag("--overwrite", overwrite, "replace an existing field of that name");
    app.add_flag("--dry-run", dry_run, "print the plan (slabs, memory, output size) and exit");
    app.add_flag("--quiet", quiet, "no progress lines on stderr");
    SDF_CLI_PARSE(app, argc, argv);

    // The command line's values that CLI11 cannot check: exit 2 with what was expected.
    sdf::StreamOptions stream;
    sdf::LatticeSpec spec;
    sdf::LatticeStorage storage = sdf::LatticeStorage::Dense;
    bool dense_file = true;  // a dense field file at --out
    sdf::SamplerOptions options;
    double band = 0;
    try {
        if (resolution.size() == 2) throw std::invalid_argument("--resolution: expected N or NX NY NZ, got 2 numbers");
        stream.memory_budget = budget_text.empty() ? default_memory_budget() : sdf::parse_byte_size(budget_text, "--memory-budget");
        if (out_path.empty() && !(sparse && (!vdb_path.empty() || !nvdb_path.empty())))
            throw std::invalid_argument("--out: expected a field file header NAME.json (only --sparse with --vdb or --nvdb "
                                        "may leave it out, writing the level sets alone)");
        if (!out_path.empty() && (out_path.size() < 6 || out_path.compare(out_path.size() - 5, 5, ".json") != 0))
            throw std::invalid_argument("--out " + out_path + ": expected a field file header NAME.json");
        if (out_path.empty() && layout == "sparse")
            throw std::invalid_argument("--layout sparse: the layout of the field file at --out; give --out NAME.json");
        std::stringstream names(channels_text);
        bool has_distance = false;
        stream.gradient = false;
        stream.write.closest_triangle = false;
        for (std::string name; std::getline(names, name, ',');) {
            if (name == "distance") has_distance = true;
            else if (name == "gradient") stream.gradient = true;
            else if (name == "closest_triangle") stream.write.closest_triangle = true;
            else throw std::invalid_argument("--channels: unknown channel '" + name + "'; expected distance, gradient, closest_triangle");
        }
        if (!has_distance) throw std::invalid_argument("--channels: the distance channel is always written; name it");
        if (!vdb_path.empty() && (vdb_path.size() < 5 || vdb_path.compare(vdb_path.size() - 4, 4, ".vdb") != 0))
            throw std::invalid_argument("--vdb " + vdb_path + ": expected a file name ending in .vdb");
        if (!nvdb_path.empty() && (nvdb_path.size() < 6 || nvdb_path.compare(nvdb_path.size() - 5, 5, ".nvdb") != 0))
            throw std::invalid_argument("--nvdb " + nvdb_path + ": expected a file name ending in .nvdb");
        if (!nvdb_path.empty() && !sdf::nanovdb_available())
            throw std::invalid_argument("--nvdb " + nvdb_path + ": this build has no NanoVDB (its headers were not found at "
                                        "configure time; set SDF_NANOVDB_DIR to the folder holding nanovdb/NanoVDB.h)");
        // The lattice and the sampler as the config parser reads them: its checks and messages.
        nlohmann::json lattice_json = {{"type", lattice_type}};
        if (resolution.size() == 1) {
            const int n = resolution[0];
            const bool bcc = sdf::lattice_type_named(lattice_type) == sdf::LatticeType::BCC;  // thesis notation Rx Ry 2Rz
            lattice_json["resolution"] = bcc ? std::vector<int>{n, n, 2 * n} : std::vector<int>{n, n, n};
        } else {
            lattice_json["resolution"] = resolution;
        }
        sdf::JsonReader lattice_reader(lattice_json, "command line", "--lattice/--resolution");
        // Only a sparse band without a dense field file (its own file, or level sets alone)
        // leaves the lattice unwritten: its lattice may be larger than a dense one.
        dense_file = !out_path.empty() && layout == "dense";
        storage = sparse && !dense_file ? sdf::LatticeStorage::SparseBand : sdf::LatticeStorage::Dense;
        spec = sdf::parse_lattice_spec(lattice_reader, storage);
        options = sampler.options({{"progress", false}});
        band = options.band_width;
        // Values the output cannot hold: a band whose +-W the stored type would round to 0 or inf.
        sdf::require_representable_band(band, dtype == "float32" ? sdf::FieldDtype::Float32 : sdf::FieldDtype::Float64,
                                        "--band");
        if (!vdb_path.empty()) sdf::require_representable_band(band, sdf::FieldDtype::Float32, "--band (the .vdb stores float32)");
        if (sparse && !(band > 0)) throw std::invalid_argument("--sparse: expected a narrow band, --band W with W > 0");
        if (!nvdb_path.empty() && !sparse)
            throw std::invalid_argument("--nvdb " + nvdb_path + ": the .nvdb is written from the sparse band; add --band W --sparse");
        if (!nvdb_path.empty()) sdf::require_representable_band(band, sdf::FieldDtype::Float32, "--band (the .nvdb stores float32)");
        if (layout == "sparse" && !sparse)
            throw std::invalid_argument("--layout sparse: the sparse field file is written from a sparse band; add --sparse");
    } catch (const std::exception& e) {
        std::cerr << "sdf-sample: error: " << e.what() << "\n";
        return sdf::kExitCommandLineError;
    }
    if (quiet) sdf::ProgressReporter::set_globally_enabled(false);
    std::string doing = "loading " + mesh_arg;  // for an out-of-memory message: what, and how much
    uint64_t planned_bytes = 0;
    try {
        stream.header_path = out_path;
        stream.write.dtype = dtype == "float32" ? sdf::FieldDtype::Float32 : sdf::FieldDtype::Float64;
        stream.write.overwrite = overwrite ? sdf::Overwrite::Allow : sdf::Overwrite::Forbid;
        stream.max_planes_per_slab = max_planes;
        stream.bytes_per_point = sdf::sampler_kind(options).stream_bytes_per_point;
        stream.progress = !quiet;

        // Every target is checked before the mesh is even loaded (and again before sampling).
        if (!dry_run) {
            if (!out_path.empty()) sdf::require_writable_target(out_path, stream.write.overwrite);
            if (!vdb_path.empty()) sdf::require_writable_target(vdb_path, stream.write.overwrite);
            if (!nvdb_path.empty()) sdf::require_writable_target(nvdb_path, stream.write.overwrite);
        }
        const auto shared_mesh = std::make_shared<const sdf::PreparedMesh>(
            sdf::prepare_mesh(sdf::load_mesh(sdf::mesh_spec_from_argument(mesh_arg), sdf::data_search_path(), ".")));
        const sdf::PreparedMesh& mesh = *shared_mesh;
        for (const std::string& w : mesh.warnings()) std::cerr << "sdf-sample: warning: " << w << "\n";
        const sdf::Lattice lattice = sdf::build_lattice(spec, mesh.bounds(), margin, storage);
        stream.fixed_bytes = sdf::estimate_fixed_bytes(mesh);
        stream.vdb_path = sparse ? "" : vdb_path;  // --sparse: written from the band's blocks below
        stream.vdb_band = band > 0 ? band : 3.0 * lattice.spacing;  // the .vdb export's default band: 3 spacings
        // The dense field file's slabs; the sparse layout writes none (the band checks its own
        // memory once its blocks are known: core/sampling/sparse_band_sampler.h).
        const std::optional<sdf::StreamPlan> plan =
            dense_file ? std::optional<sdf::StreamPlan>(sdf::plan_streamed_sampling(lattice, stream)) : std::nullopt;
        doing = "sampling " + mesh_arg + " on " + sdf::lattice_notation(lattice) +
                (plan ? ", " + std::to_string(plan->points) + " points" : std::string());
        planned_bytes = plan ? plan->peak_estimate : stream.fixed_bytes;
        // What the run checks before sampling; the dry run checks it too and says so.
        const auto require_runnable = [&] {
            sdf::require_plan_fits_machine(planned_bytes, stream.memory_budget, "--memory-budget");
            if (plan) require_output_space(*plan, out_path);  // sparse: known once sampled
        };
        if (dry_run) {
            std::cout << "sampler: " << options.backend << " " << options.method << ", " << sdf::precision_name(options.precision);
            if (band > 0) std::cout << ", band " << band << (sparse ? " (sparse: the band's memory is added when sampled)" : "");
            if (layout == "sparse")
                std::cout << "\nout: " << out_path << ", the sparse band's field file (its size grows with the band)\n";
            else if (plan)
                std::cout << "\n" << plan->describe() << "out: " << out_path << "\n";
            else
                std::cout << "\nout: none, the level sets alone\n";
            if (!vdb_path.empty() && sparse)
                std::cout << "vdb: " << vdb_path << ", a level set from the sparse band's blocks, points with |d| <= "
                          << band << " active (outside the budget)\n";
            else if (!vdb_path.empty())
                std::cout << "vdb: " << vdb_path << ", points with |d| < " << stream.vdb_band
                          << " active (its grids hold the band's points, outside the budget)\n";
            if (!nvdb_path.empty())
                std::cout << "nvdb: " << nvdb_path << ", a NanoVDB level set from the sparse band's blocks, points with |d| <= "
                          << band << " active (outside the budget)\n";
            try {
                if (!out_path.empty()) sdf::require_writable_target(out_path, stream.write.overwrite);
                if (!vdb_path.empty()) sdf::require_writable_target(vdb_path, stream.write.overwrite);
                if (!nvdb_path.empty()) sdf::require_writable_target(nvdb_path, stream.write.overwrite);
                require_runnable();
            } catch (const std::exception& e) {
                std::cerr << "sdf-sample: error: the run would be refused: " << e.what() << "\n";
                return 1;
            }
            return 0;
        }
        require_runnable();
        // Temporaries of an interrupted earlier run in the output folder (their process is gone).
        for (const std::string& target : {out_path, vdb_path, nvdb_path})
            if (!target.empty()) sdf::remove_stale_staging(fs::absolute(target).parent_path().string());
        const sdf::MeshProvenance mesh_provenance = sdf::describe_prepared_mesh(mesh);
        if (!quiet && plan) std::cerr << plan->describe();
        // The front ends' one field source (harness/study/field_source.h), without a cache:
        // its sampler, bound to the mesh, samples the slabs this tool streams to disk.
        sdf::FieldSource source(nullptr, options, "the command line: sampler", sdf::SamplerReach::ThisProcess);
        const sdf::BoundSampler& bound = source.bound(shared_mesh);
        std::unique_ptr<sdf::SparseBandSlabs> sparse_slabs;
        if (sparse) {
            doing = "sampling the sparse band of " + mesh_arg + " on " + sdf::lattice_notation(lattice);
            sdf::BandChannels channels;
            channels.gradient = stream.gradient;
            channels.closest_triangle = stream.write.closest_triangle;  // the band's points are its mask either way
            // Every output of a float32 run stores float32 (the field file, .vdb, .nvdb): the band
            // holds its distances rounded as they will be written (4 bytes a point, not 8).
            if (stream.write.dtype == sdf::FieldDtype::Float32) channels.distance_type = sdf::BandDistanceType::Float32;
            sdf::SparseBandField sparse_band = bound.sample_band_sparse(lattice, band, channels);
            sparse_band.mesh = mesh_provenance;
            stream.fixed_bytes += sparse_band.memory_bytes();  // held while the slabs are written
            sparse_slabs = std::make_unique<sdf::SparseBandSlabs>(bound, std::move(sparse_band));
            const sdf::SparseBandCounts c = sparse_slabs->band().counts();
            std::cout << "sparse band: " << c.active_blocks << " of " << c.blocks << " blocks of 8^3 active ("
                      << c.active_points << " points searched, " << c.band_points << " in the band), " << c.tiles
                      << " tiles (" << c.inside_tiles << " inside), " << c.mixed_blocks << " mixed; "
                      << sdf::format_bytes(sparse_slabs->band().memory_bytes()) << ", " << sparse_slabs->band().timings.total
                      << " s\n";
        }
        // The level sets written straight from the sparse band's blocks, after either field file.
        // Seconds of each file written from the band: where an end-to-end run's time goes.
        const auto since = [](std::chrono::steady_clock::time_point t) {
            return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
        };
        double vdb_seconds = 0, nvdb_seconds = 0;
        const auto write_level_sets = [&]() -> std::pair<int64_t, int64_t> {
            std::pair<int64_t, int64_t> active{0, 0};
            if (!vdb_path.empty()) {
                const auto t = std::chrono::steady_clock::now();
                doing = "writing " + vdb_path + " from the sparse band";
                sdf::SparseVdbOptions vdb_options;
                vdb_options.gradient = stream.gradient;
                // As the dense .vdb: no closest-triangle grid (Debian's pyopenvdb 10 cannot read an Int32Grid).
                vdb_options.closest_triangle = false;
                vdb_options.overwrite = stream.write.overwrite;
                active.first = sdf::write_sparse_band_vdb(sparse_slabs->band(), vdb_path, vdb_options).active_voxels;
                vdb_seconds = since(t);
            }
            if (!nvdb_path.empty()) {
                const auto t = std::chrono::steady_clock::now();
                doing = "writing " + nvdb_path + " from the sparse band";
                active.second = sdf::write_sparse_band_nvdb(sparse_slabs->band(), nvdb_path, stream.write.overwrite).active_voxels;
                nvdb_seconds = since(t);
            }
            return active;
        };
        const auto report_level_sets = [&](int64_t vdb_active, int64_t nvdb_active) {
            if (!vdb_path.empty())
                std::cout << "wrote " << vdb_path << ": " << vdb_active << " active points (|d| <= " << band << ", "
                          << vdb_seconds << " s)\n";
            if (!nvdb_path.empty())
                std::cout << "wrote " << nvdb_path << ": " << nvdb_active << " active points (|d| <= " << band << ", "
                          << nvdb_seconds << " s)\n";
        };
        if (out_path.empty()) {  // --sparse writing its level sets alone
            const auto [vdb_active, nvdb_active] = write_level_sets();
            report_level_sets(vdb_active, nvdb_active);
            return 0;
        }
        if (layout == "sparse") {
            doing = "writing the sparse field file " + out_path;
            sdf::SparseFieldWriteOptions file;
            file.dtype = stream.write.dtype;
            file.gradient = stream.gradient;
            file.overwrite = stream.write.overwrite;
            const auto t = std::chrono::steady_clock::now();
            sdf::write_sparse_field(out_path, sparse_slabs->band(), file);
            const double field_seconds = since(t);
            const auto [vdb_active, nvdb_active] = write_level_sets();
            std::cout << "wrote " << out_path << ": the sparse band's field file, " << sparse_slabs->band().active.size()
                      << " active blocks (" << field_seconds << " s)\n";
            report_level_sets(vdb_active, nvdb_active);
            return 0;
        }
        const sdf::StreamResult r = sdf::sample_streamed(sparse_slabs ? *sparse_slabs : bound, options, lattice, stream, mesh_provenance);
        int64_t vdb_active = r.vdb_active_points, nvdb_active = 0;
        if (sparse_slabs) {
            const std::pair<int64_t, int64_t> active = write_level_sets();
            if (!vdb_path.empty()) vdb_active = active.first;
            nvdb_active = active.second;
        }
        std::cout << "wrote " << out_path << ": " << r.plan.points << " points in " << r.plan.slabs << " slabs, "
                  << sdf::format_bytes(r.plan.output_bytes) << "; " << r.seconds << " s end to end ("
                  << r.header.timings.kernel << " s sampler kernels, " << r.write_wait_seconds
                  << " s waiting for the disk); peak resident memory " << sdf::format_bytes(r.peak_resident_bytes)
                  << " (budget " << sdf::format_bytes(stream.memory_budget) << ")\n";
        if (!vdb_path.empty())
            std::cout << "wrote " << vdb_path << ": " << vdb_active << " active points (|d| " << (sparse ? "<=" : "<") << " "
                      << stream.vdb_band << ")\n";
        if (!nvdb_path.empty())
            std::cout << "wrote " << nvdb_path << ": " << nvdb_active << " active points (|d| <= " << band << ")\n";
        if (band > 0)
            std::cout << "band " << band << ": " << r.band.in_band << " points in the band, " << r.band.outside << " outside\n";
        return 0;
    } catch (const std::bad_alloc&) {
        std::cerr << "sdf-sample: error: " << sdf::out_of_memory_message(doing, planned_bytes) << "\n";
        return 1;
    } catch (const std::exception& e) {
        std::cerr << "sdf-sample: error: " << e.what() << "\n";
        return 1;
    }
}
