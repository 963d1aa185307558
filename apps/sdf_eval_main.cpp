// sdf-eval FIELD POINTS --interpolator NAME [--derivatives true|fd|fd_weighted]
//         [--sigma2 S] [--sigma-units lattice|spacing] [--threads N]
//
// Reconstructs a sampled field (the project's field file: docs/field-format.md, CC or BCC,
// with or without a gradient channel, any scalar volume) and prints one line per input
// point, in input order: "f gx gy gz" (value and world-space gradient, %.9g). POINTS has
// "x y z" per line in world units ('-' = stdin; blank lines and '#' comments are skipped), or
// is a .npy file of shape (N, 3); at least one point (none is an error naming the input).
// Points outside the interpolator's domain are clamped into it (a warning counts them). A
// sparse band's file (sdf-sample --layout sparse) is reconstructed straight from its blocks
// (core/reconstruction/sparse_reconstruction.h): bit for bit the dense `--band W` field's
// reconstruction, in memory that grows with the band, not the lattice; only the interpolating
// splines (cc_bspline3, bcc_box_quintic), whose prefilter spans the lattice, densify it, past
// the memory check. Points outside the band's cells (core/sampling/sparse_band_cells.h) print
// that field's reconstruction (built from +-W there), and a warning counts them, as the
// lattice's edge.
// docs/reconstruction.md describes the interpolators and derivative sources.
#include <CLI/CLI.hpp>

#include "apps/cli_exit.h"
#include "apps/cli_validators.h"

#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>

#include "core/reconstruction/reconstruction.h"
#include "core/reconstruction/sparse_reconstruction.h"
#include "core/sampling/sparse_band_cells.h"
#include "harness/config/json_reader.h"
#include "harness/io/field_file.h"
#include "harness/io/sparse_field_file.h"
#include "harness/io/points_file.h"
#include "harness/resources/memory_budget.h"

int main(int argc, char** argv) {
    CLI::App app{"Reconstructs a CC or BCC field file at given points: prints \"f gx gy gz\" per point."};
    sdf::add_version_flag(app, "sdf-eval");
    std::string field_path, points_path, interpolator, derivatives, sigma_units = "lattice";
    sdf::ReconstructionSpec spec;
    int threads = 0;
    app.add_option("field", field_path, "field header (NAME.json, docs/field-format.md)")->required();
    app.add_option("points", points_path,
                   "file with \"x y z\" per line (world units), a .npy file of shape (N, 3), or - for stdin; at least one "
                   "point (none is an error)")
        ->required();
    app.add_option("--interpolator", interpolator, sdf::interpolator_help())
        ->required()
        ->check(CLI::IsMember(sdf::interpolator_names()));
    app.add_option("--derivatives", derivatives,
                   "true, fd or fd_weighted (default: true when the interpolator uses derivatives and the field has a "
                   "gradient channel, else fd)")
        ->check(CLI::IsMember({"true", "fd", "fd_weighted"}));
    app.add_option("--sigma2", spec.sigma2, "fd_weighted: sigma^2 of the Gaussian weights (thesis eq. 4-15)")->capture_default_str();
    app.add_option("--sigma-units", sigma_units, "unit of sigma: lattice (h/2, thesis Figure 4-2) or spacing (h)")
        ->check(CLI::IsMember({"lattice", "spacing"}))
        ->capture_default_str();
    app.add_option("--threads", threads, "CPU threads (0 = all)")->check(sdf::kNonNegativeNumber)->capture_default_str();
    SDF_CLI_PARSE(app, argc, argv);
    std::string doing = "reading the field " + field_path;  // for an out-of-memory message
    uint64_t bytes = 0;
    try {
        // The header is parsed once; a sparse band's file is read as its blocks.
        const nlohmann::json header = sdf::read_json_file(field_path, "field header");
        std::unique_ptr<sdf::SparseBandField> band;
        sdf::SampledField field;
        bool gradient = false;
        if (sdf::is_sparse_field_header(header)) {
            band = std::make_unique<sdf::SparseBandField>(sdf::read_sparse_field(field_path, header));
            gradient = header.contains("gradient_channel");
        } else {
            field = sdf::read_field(field_path);
            gradient = !field.gradient.empty();
        }
        spec.interpolator = sdf::parse_interpolator(interpolator);
        spec.derivatives = derivatives.empty() ? sdf::default_derivative_source(spec.interpolator, gradient)
                                               : sdf::parse_derivative_source(derivatives);
        spec.sigma_units = sigma_units == "lattice" ? sdf::SigmaUnits::LatticeUnits : sdf::SigmaUnits::Spacing;
        spec.threads = threads;
        // One of the two: the band's own reconstruction, or the dense field's.
        std::optional<sdf::SparseReconstruction> sparse;
        std::optional<sdf::Reconstruction> dense;
        if (band && sdf::reconstructs_locally(spec.interpolator)) {
            doing = "reconstructing the sparse band of " + field_path + " (" + std::to_string(band->active.size()) +
                    " active blocks) at " + points_path;
            bytes = uint64_t(band->memory_bytes());
            sparse.emplace(*band, spec, gradient);
        } else {
            if (band) field = sdf::densify_within_memory(*band, gradient, field_path, "sdf-eval");
            doing = "reconstructing " + field_path + " (" + std::to_string(field.size()) + " lattice points) at " + points_path;
            bytes = uint64_t(field.size()) * sdf::kReconstructionBytesPerPoint;
            dense.emplace(field, spec);
        }
        const std::vector<sdf::Vec3d> points = sdf::read_points_file(points_path);
        const auto samples = sparse ? sparse->evaluate(points, threads) : dense->evaluate(points, threads);
        int64_t outside = 0, off_band = 0;
        for (size_t i = 0; i < samples.size(); ++i) {
            const auto& s = samples[i];
            std::printf("%.9g %.9g %.9g %.9g\n", s.value, s.gradient.x, s.gradient.y, s.gradient.z);
            outside += s.inside ? 0 : 1;
            off_band += band && s.inside && !sdf::in_band_cells(*band, points[i]) ? 1 : 0;
        }
        if (off_band > 0)
            std::fprintf(stderr,
                         "sdf-eval: warning: %lld of %zu points lie outside the sparse band's cells (|d| <= %.9g at every "
                         "corner); their values are the dense band field's, built from +-W there\n",
                         static_cast<long long>(off_band), samples.size(), band->width);
        if (outside > 0) {
            const sdf::DomainBox<double> box = sparse ? sparse->domain() : dense->domain();
            std::fprintf(stderr,
                         "sdf-eval: warning: %lld of %zu points lie outside the %s domain [%.9g %.9g %.9g] - "
                         "[%.9g %.9g %.9g] and were clamped into it\n",
                         static_cast<long long>(outside), samples.size(), sdf::describe(spec).c_str(), box.lo.x,
                         box.lo.y, box.lo.z, box.hi.x, box.hi.y, box.hi.z);
        }
        return 0;
    } catch (const std::bad_alloc&) {
        std::cerr << "sdf-eval: error: " << sdf::out_of_memory_message(doing, bytes) << "\n";
        return 1;
    } catch (const std::exception& e) {
        std::cerr << "sdf-eval: error: " << e.what() << "\n";
        return 1;
    }
}
