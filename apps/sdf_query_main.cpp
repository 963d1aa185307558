// sdf-query MESH POINTS [--method bvh|brute_force] [--backend auto|cpu|cuda] [--threads N]
//           [--precision float|double] [--sign auto|pseudonormal|winding] [--out FILE]
//
// One result per input point, in input order: "d gx gy gz tri" (signed distance, exact
// gradient, 0-based closest triangle in the file's face order). MESH is a mesh file (a format
// of core/mesh/load_mesh.h's mesh_formats(), optionally gzip-compressed; a relative name is looked up in the current
// directory, then on the data search path: harness/config/mesh_spec.h) or shape:NAME;
// POINTS has "x y z" per line ('-' = stdin) or is a .npy file of shape (N, 3), N >= 1 (no
// points is an error naming the input: most often the wrong file). Results go to
// stdout as text, or to --out: a .npy file of shape (N, 5) float64 (the same five columns,
// every bit of the double results), any other name a text file. The query itself is
// harness/sampling/point_query.h, shared with the Python module.
#include <CLI/CLI.hpp>

#include "apps/cli_exit.h"
#include "apps/cli_validators.h"
#include "apps/sampler_cli.h"

#include <cstdio>
#include <iostream>
#include <sstream>

#include "core/mesh/load_mesh.h"
#include "core/mesh/prepared_mesh.h"
#include "core/parallel/progress.h"
#include "harness/config/mesh_spec.h"
#include "harness/config/sampler_spec.h"
#include "harness/io/atomic_file.h"
#include "harness/io/npy_file.h"
#include "harness/io/points_file.h"
#include "harness/resources/memory_budget.h"
#include "harness/sampling/point_query.h"
#include "harness/sampling/sampler_table.h"

namespace {

/// The results as text lines (%.9g for float searches, %.17g for double: every bit).
std::string results_text(const std::vector<sdf::PointSample>& results, sdf::Precision precision) {
    const char* fmt = precision == sdf::Precision::Float ? "%.9g %.9g %.9g %.9g %d\n" : "%.17g %.17g %.17g %.17g %d\n";
    std::string text;
    char line[160];
    for (const sdf::PointSample& r : results) {
        std::snprintf(line, sizeof line, fmt, r.distance, r.gradient.x, r.gradient.y, r.gradient.z, r.triangle);
        text += line;
    }
    return text;
}

/// (N, 5) float64 rows "d gx gy gz tri" (triangle indices are exact in a double).
std::vector<double> results_rows(const std::vector<sdf::PointSample>& results) {
    std::vector<double> rows;
    rows.reserve(results.size() * 5);
    for (const sdf::PointSample& r : results)
        rows.insert(rows.end(), {r.distance, r.gradient.x, r.gradient.y, r.gradient.z, double(r.triangle)});
    return rows;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"Exact signed distance, gradient and closest triangle of points to a mesh."};
    sdf::add_version_flag(app, "sdf-query");
    std::string mesh_arg, points_path, out_path;
    bool quiet = false, overwrite = false;
    sdf::SamplerCli sampler;
    app.add_option("mesh", mesh_arg, "mesh file (" + sdf::mesh_formats_help() + ") or shape:NAME (sphere, box, torus, "
                                     "pawn, soccer_ball)")
        ->required();
    app.add_option("points", points_path,
                   "file with \"x y z\" per line, a .npy file of shape (N, 3), or - for stdin; at least one point "
                   "(none is an error)")
        ->required();
    sampler.add(app, "--method", "method", "search: bvh (about log n per point) or brute_force (every triangle)");
    sampler.add(app, "--backend", "backend", "sampler backend (auto: cuda when a GPU is present, else cpu)");
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
    sampler.add(app, "--sign", "sign",
                "sign mode: pseudonormal, winding (generalized winding number > 1/2), or auto (pseudonormal where "
                "the mesh is closed, manifold, oriented, one shell, without self-intersections; winding otherwise)");
    app.add_option("--out", out_path, "write the results here instead of stdout: .npy = (N, 5) float64, else text");
    app.add_flag("--overwrite", overwrite, "replace an existing --out file");
    app.add_flag("--quiet", quiet, "no progress lines on stderr");
    SDF_CLI_PARSE(app, argc, argv);
    sdf::SamplerOptions options;
    try {  // bad names and values fail before the mesh is read, as command-line errors
        options = sampler.options({{"progress", !quiet}});
        sdf::point_query_sampler_options(options);
    } catch (const std::exception& e) {
        std::cerr << "sdf-query: error: " << e.what() << "\n";
        return sdf::kExitCommandLineError;
    }
    if (quiet) sdf::ProgressReporter::set_globally_enabled(false);
    try {
        const auto mesh = std::make_shared<const sdf::PreparedMesh>(sdf::prepare_mesh(
            sdf::load_mesh(sdf::mesh_spec_from_argument(mesh_arg), sdf::data_search_path(), ".")));
        for (const std::string& w : mesh->warnings()) std::cerr << "sdf-query: warning: " << w << "\n";
        const std::vector<sdf::Vec3d> points = sdf::read_points_file(points_path);
        const sdf::PointQueryResult result = sdf::query_points(mesh, points, options);
        const sdf::Overwrite mode = overwrite ? sdf::Overwrite::Allow : sdf::Overwrite::Forbid;
        if (out_path.empty()) {
            const std::string text = results_text(result.samples, options.precision);
            std::fwrite(text.data(), 1, text.size(), stdout);
        } else if (sdf::is_npy_path(out_path)) {
            sdf::write_npy(out_path, results_rows(result.samples), {int64_t(result.samples.size()), 5}, mode);
        } else {
            sdf::write_text_atomically(out_path, results_text(result.samples, options.precision), mode);
        }
        return 0;
    } catch (const std::bad_alloc&) {
        std::cerr << "sdf-query: error: " << sdf::out_of_memory_message("querying " + mesh_arg + " at " + points_path, 0) << "\n";
        return 1;
    } catch (const std::exception& e) {
        std::cerr << "sdf-query: error: " << e.what() << "\n";
        return 1;
    }
}
