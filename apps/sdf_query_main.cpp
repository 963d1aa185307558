// sdf-query MESH POINTS [--backend cpu|cuda] [--threads N] [--precision float|double]
//           [--sign auto|pseudonormal|winding]
//
// Prints one line per input point, in input order: "d gx gy gz tri" (signed distance,
// exact gradient, 0-based closest triangle in the file's face order). MESH is an OBJ file
// (a relative name is looked up in the current directory, then on the data search path:
// harness/config/mesh_spec.h) or shape:NAME; POINTS has "x y z" per line ('-' = stdin).
#include <CLI/CLI.hpp>

#include "apps/cli_exit.h"

#include <algorithm>
#include <cstdio>
#include <iostream>

#include "core/mesh/prepared_mesh.h"
#include "core/parallel/progress.h"
#include "harness/config/mesh_spec.h"
#include "harness/config/sampler_spec.h"
#include "harness/io/points_file.h"
#include "harness/sampling/sampler_table.h"

int main(int argc, char** argv) {
    CLI::App app{"Exact signed distance, gradient and closest triangle of points to a mesh."};
    std::string mesh_arg, points_path, precision = "float", sign = sdf::kSignModes[0].name;
    sdf::SamplerOptions options;
    app.add_option("mesh", mesh_arg, "OBJ file or shape:NAME (sphere, box, torus, pawn, soccer_ball)")->required();
    app.add_option("points", points_path, "file with \"x y z\" per line, or - for stdin")->required();
    app.add_option("--backend", options.backend, "sampler backend")
        ->check(CLI::IsMember(sdf::sampler_backends()))
        ->capture_default_str();
    app.add_option("--kernel", options.kernel, "backend kernel (" + sdf::sampler_kernels_help() + ")");
    app.add_option("--threads", options.threads, "CPU threads (0 = all)")
        ->check(CLI::NonNegativeNumber)
        ->capture_default_str();
    app.add_option("--precision", precision, "float or double")->check(CLI::IsMember({"float", "double"}))->capture_default_str();
    app.add_option("--sign", sign,
                   "sign mode: pseudonormal, winding (generalized winding number > 1/2), or auto (pseudonormal where "
                   "the mesh is closed, manifold, oriented, one shell, without self-intersections; winding otherwise)")
        ->check(CLI::IsMember(sdf::sign_mode_names()))
        ->capture_default_str();
    SDF_CLI_PARSE(app, argc, argv);
    options.precision = precision == "float" ? sdf::Precision::Float : sdf::Precision::Double;
    options.sign = sdf::sign_mode_from_name(sign, "--sign");
    options.progress = false;
    sdf::ProgressReporter::set_globally_enabled(false);
    try {
        sdf::check_sampler_kernel(options);
        const sdf::PreparedMesh mesh = sdf::prepare_mesh(
            sdf::load_mesh(sdf::mesh_spec_from_argument(mesh_arg), sdf::data_search_path(), "."));
        for (const std::string& w : mesh.warnings()) std::cerr << "sdf-query: warning: " << w << "\n";
        const std::vector<sdf::Vec3d> points = sdf::read_points_file(points_path);
        const auto results = sdf::make_sampler(options)->query(mesh, points);
        const char* fmt = options.precision == sdf::Precision::Float ? "%.9g %.9g %.9g %.9g %d\n"
                                                                     : "%.17g %.17g %.17g %.17g %d\n";
        for (const sdf::PointSample& r : results)
            std::printf(fmt, r.distance, r.gradient.x, r.gradient.y, r.gradient.z, r.triangle);
        return 0;
    } catch (const std::exception& e) {
        std::cerr << "sdf-query: error: " << e.what() << "\n";
        return 1;
    }
}
