// sdf-render INPUT [options]: ray-cast images of reconstructed distance fields without the
// harness (docs/raycast.md, "sdf-render").
//
// INPUT is a field file (NAME.json, docs/field-format.md) or a mesh (an OBJ file found on
// the data search path, or shape:NAME). A mesh is sampled on --lattice/--resolution (fields
// are kept in the field cache shared with run-experiment); a field file is used as it is (a
// sparse band's file densified, past the memory check: the dense `--band W` field, whose +-W
// off the band the ray marcher steps through).
//
//   one image per view:  sdf-render dragon.obj --lattice bcc --resolution 64,64,128
//                          --interpolator bcc_cubic --derivatives true --view dragon_side
//                          --size 1024 --backend cuda --repeat 20 --out dragon.png
//   thesis grid:         sdf-render dragon.obj --grid --view dragon_side --view dragon_front
//                          --size 512 --out-dir results/figures
//
// Single images write OUT (PNG, or PPM without OpenImageIO), OUT's .exr (all channels, or
// PFMs) and, with --reference, the mesh reference and OUT's .metrics.json. With several
// views the view name is appended to OUT's stem. Grids write the files of
// harness/render/thesis_figure.h. Timings are printed (CPU: wall time; CUDA: median
// kernel time over --repeat launches, CUDA events).
#include <CLI/CLI.hpp>

#include "apps/cli_exit.h"
#include "apps/cli_validators.h"
#include "apps/sampler_cli.h"

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>

#include "core/lattice/lattice_fitting.h"
#include "core/mesh/load_mesh.h"
#include "core/mesh/sha256.h"
#include "core/parallel/progress.h"
#include "harness/study/field_source.h"
#include "harness/cache/field_cache.h"
#include "harness/config/mesh_spec.h"
#include "harness/io/field_file.h"
#include "harness/io/sparse_field_file.h"
#include "harness/provenance/provenance.h"
#include "harness/render/image_io.h"
#include "harness/render/render_backend.h"
#include "harness/resources/memory_budget.h"
#include "harness/render/thesis_figure.h"

namespace {

namespace fs = std::filesystem;
using namespace sdf;

struct Options {
    std::string input, mesh_file;
    std::string lattice = lattice_type_name(LatticeType::BCC);
    std::vector<int> resolution;
    std::vector<int> cc_resolution{80, 80, 80}, bcc_resolution{64, 64, 128};
    double margin = 0.1;
    std::string interpolator, derivatives;
    std::vector<std::string> views, panels;
    std::vector<double> eye, target, up{0, 1, 0};
    double fov = 30;
    std::vector<int> size{512};
    std::string backend = "auto", precision = "float";
    int threads = 0, repeat = 1, device = 0;
    bool reference = false, grid = false, no_reference = false, no_error_maps = false, no_exr = false;
    bool overwrite = false, quiet = false, no_cache = false;
    bool up_given = false;  ///< --up was on the command line (it applies to --eye/--target only)
    int downsample = 1;
    double heat_max = 20;
    std::string out = "render.png", out_dir = ".", name, title, cache_dir;
    SamplerCli sampler;  ///< mesh input: --sampler-backend, --sampler-method, --sign (the codec's defaults)
};

bool is_field_file(const std::string& input) { return fs::path(input).extension() == ".json"; }

Vec3d vec3(const std::vector<double>& v) { return {v[0], v[1], v[2]}; }

SamplerOptions sampler_options(const Options& o) { return o.sampler.options({{"progress", !o.quiet}}); }

/// The field of `mesh` on `lattice`: from the field cache when it holds it, else sampled and
/// stored there, by the studies' FieldSource (the same key, log and sign warning).
SampledField obtain_field(const std::shared_ptr<const PreparedMesh>& mesh, const Lattice& lattice, const Options& o) {
    const std::optional<FieldCache> cache =
        o.no_cache ? std::nullopt : std::optional<FieldCache>(o.cache_dir.empty() ? ContentCache::default_root() : o.cache_dir);
    FieldSource source(cache ? &*cache : nullptr, sampler_options(o), "the command line: sampler");
    return source.get(mesh, lattice, "field " + mesh->name(), std::cerr).field;
}

Lattice mesh_lattice(const PreparedMesh& mesh, LatticeType type, const std::vector<int>& res, double margin) {
    if (res.size() != 3) throw std::invalid_argument("a resolution needs 3 integers, e.g. 80,80,80");
    const Int3 r{res[0], res[1], res[2]};
    return fit_lattice(type, type == LatticeType::BCC ? bcc_primary_from_notation(r) : r, mesh.bounds(), margin);
}

/// The explicit camera's flags, checked with messages that name them (the codec then reads
/// the camera as a config's).
void check_camera_flags(const Options& o) {
    if (o.up_given && o.eye.empty())
        throw std::invalid_argument("--up applies to an explicit camera only; give --eye and --target too");
    if (o.eye.empty() && o.target.empty()) return;
    if (o.eye.size() != 3 || o.target.size() != 3)
        throw std::invalid_argument("--eye and --target are both needed for an explicit camera");
    const auto text = [](const std::vector<double>& v) {
        std::string t;
        for (const double x : v) {
            char number[32];
            std::snprintf(number, sizeof number, "%.6g", x);
            t += (t.empty() ? "" : ",") + std::string(number);
        }
        return t;
    };
    // Each problem by its name: a NaN or overflowing eye is no "up parallel to the view".
    for (const auto& [flag, v] : {std::pair{"--eye", &o.eye}, {"--target", &o.target}, {"--up", &o.up}})
        for (const double x : *v)
            if (!std::isfinite(x))
                throw std::invalid_argument(std::string(flag) + " " + text(*v) + ": expected three finite numbers");
    const Vec3d forward = vec3(o.target) - vec3(o.eye);
    if (!std::isfinite(length_squared(forward)) || !std::isfinite(length_squared(vec3(o.up))))
        return;  // distances beyond double's range: the camera's check names them (views.cpp, make_camera)
    if (length_squared(forward) == 0.0) throw std::invalid_argument("--eye and --target are the same point");
    // A zero up vector, or one along the line of sight, leaves the camera's roll undefined.
    if (length_squared(cross(forward, vec3(o.up))) == 0.0)
        throw std::invalid_argument("--up " + text(o.up) +
                                    " is zero or parallel to the line of sight; expected a direction that fixes "
                                    "the camera's roll");
}

/// The render flags as a config's "render" object, read by its one codec (render_spec.h): the
/// views (the explicit camera first, then the named ones; three_quarter when none), size, fov,
/// backend, precision and, for grids, the rows, heat-map scale, downsampling and panels.
RenderSpec render_spec(const Options& o) {
    check_camera_flags(o);
    nlohmann::json j = {{"size", o.size.size() > 1 ? nlohmann::json{o.size[0], o.size[1]} : nlohmann::json(o.size[0])},
                        {"fov", o.fov},
                        {"backend", o.backend},
                        {"precision", o.precision}};
    nlohmann::json views = nlohmann::json::array();
    if (!o.eye.empty())
        views.push_back({{"name", "camera"}, {"eye", o.eye}, {"target", o.target}, {"up", o.up}, {"fov", o.fov}});
    for (const std::string& name : o.views) views.push_back(name);
    if (!views.empty()) j["views"] = views;
    if (o.grid) {
        j["reference"] = !o.no_reference;
        j["error_maps"] = !o.no_error_maps;
        j["heat_max_degrees"] = o.heat_max;
        j["grid_downsample"] = o.downsample;
        if (!o.panels.empty()) j["panels"] = o.panels;
    } else {
        j["reference"] = o.reference;
    }
    return render_spec_from_json(j, "the command line");
}

/// The spec's backend and precision, and the flags beyond a config's block.
RenderOptions render_options(const Options& o, const RenderSpec& spec) {
    RenderOptions r = render_options(spec);
    r.threads = o.threads;
    r.progress = !o.quiet;
    r.repetitions = o.repeat;
    r.device = o.device;
    return r;
}

std::string with_suffix(const std::string& path, const std::string& suffix, const std::string& ext = "") {
    const fs::path p(path);
    return (p.parent_path() / (p.stem().string() + suffix + (ext.empty() ? p.extension().string() : ext))).string();
}

void print_timing(const std::string& what, const RenderedImage& image) {
    const nlohmann::json& i = image.info;
    std::printf("%s: %dx%d, backend %s, %.4f s", what.c_str(), image.width, image.height,
                i.value("backend", std::string("?")).c_str(), i.value("seconds", 0.0));
    if (i.contains("kernel_seconds"))
        std::printf(", kernel %.3f ms median of %d (min %.3f ms)", 1e3 * i["kernel_seconds"].get<double>(),
                    i.value("repetitions", 1), 1e3 * i.value("kernel_seconds_min", 0.0));
    if (i.contains("march"))
        std::printf(", %.1f steps/pixel, %lld hits", i["march"].value("mean_steps", 0.0),
                    static_cast<long long>(i["march"].value("hits", 0)));
    std::printf("\n");
}

nlohmann::json provenance(const Options& o, const nlohmann::json& resolved, const std::string& mesh_sha) {
    const GitState git = git_state();
    const std::string text = resolved.dump();
    return {{"tool", "sdf-render"},
            {"config_hash", sha256_hex(text.data(), text.size())},
            {"config", resolved},
            {"git_commit", git.commit},
            {"git_dirty", git.dirty},
            {"created", utc_timestamp()},
            {"mesh_sha256", mesh_sha},
            {"machine", machine_and_build()},
            {"input", o.input}};
}

/// Every file run_single() writes, checked before anything is sampled or rendered (the
/// folder exists and is writable, no file is replaced without --overwrite).
void require_single_targets(const Options& o, const RenderSpec& spec) {
    const Overwrite overwrite = o.overwrite ? Overwrite::Allow : Overwrite::Forbid;
    for (const ViewRequest& v : spec.views) {
        const std::string out = spec.views.size() > 1 ? with_suffix(o.out, "_" + v.name) : o.out;
        std::vector<std::string> targets = {out};
        if (!o.no_exr) targets.push_back(with_suffix(out, "", ".exr"));
        if (spec.reference) {
            targets.push_back(with_suffix(out, "_reference"));
            if (!o.no_exr) targets.push_back(with_suffix(out, "_reference", ".exr"));
            targets.push_back(with_suffix(out, "", ".metrics.json"));
        }
        for (const std::string& t : targets) require_writable_target(t, overwrite);
    }
}

int run_single(const Options& o, const RenderSpec& spec, const nlohmann::json& resolved) {
    require_single_targets(o, spec);
    std::shared_ptr<const PreparedMesh> mesh;
    SampledField field;
    if (is_field_file(o.input)) {
        field = read_field_densified(o.input, "sdf-render");  // a sparse band's file: densified (the dense --band field)
        if (!o.mesh_file.empty())
            mesh = std::make_shared<const PreparedMesh>(
                prepare_mesh(load_mesh(mesh_spec_from_argument(o.mesh_file), data_search_path(), ".")));
    } else {
        mesh = std::make_shared<const PreparedMesh>(prepare_mesh(load_mesh(mesh_spec_from_argument(o.input), data_search_path(), ".")));
        const LatticeType type = lattice_type_named(o.lattice);
        const std::vector<int> res =
            !o.resolution.empty() ? o.resolution : (type == LatticeType::CC ? o.cc_resolution : o.bcc_resolution);
        field = obtain_field(mesh, mesh_lattice(*mesh, type, res, o.margin), o);
    }
    if (spec.reference && !mesh) throw std::invalid_argument("--reference needs the mesh: give a mesh INPUT or --mesh");
    const Bounds3 bounds = mesh ? mesh->bounds() : field_solid_bounds(field);
    const Reconstruction recon(field, o.interpolator.empty() ? (field.lattice.type == LatticeType::BCC ? "bcc_cubic" : "tricubic_lm")
                                                             : o.interpolator,
                               o.derivatives);
    const std::vector<ViewRequest>& views = spec.views;
    const nlohmann::json prov = provenance(o, resolved, mesh ? mesh->content_sha256() : std::string());
    const Overwrite overwrite = o.overwrite ? Overwrite::Allow : Overwrite::Forbid;
    std::optional<MeshReferenceRenderer> reference_renderer;
    if (spec.reference) reference_renderer.emplace(*mesh);
    for (const ViewRequest& v : views) {
        const int w = spec.width, h = spec.height;
        const CameraSpec camera = mesh ? resolve_view(v, mesh->vertices(), w, h) : resolve_view(v, bounds, w, h);
        const RenderedImage image = render_reconstruction(recon, camera, render_options(o, spec));
        print_timing(recon.description() + " " + lattice_notation(field.lattice) + ", view " + v.name, image);
        const std::string out = views.size() > 1 ? with_suffix(o.out, "_" + v.name) : o.out;
        nlohmann::json attributes = prov;
        attributes["render_seconds"] = image.info.value("seconds", 0.0);
        attributes["reconstruction"] = recon.description();
        attributes["lattice"] = lattice_notation(field.lattice);
        attributes["camera"] = camera_to_json(camera);
        attributes["render"] = image.info;
        const std::string written = write_image(out, shaded_image(image), attributes, overwrite);
        if (!o.no_exr) write_render_exr(with_suffix(out, "", ".exr"), image, attributes, overwrite);
        std::printf("  wrote %s\n", written.c_str());
        if (reference_renderer) {
            MeshRenderOptions mo;
            mo.threads = o.threads;
            mo.progress = !o.quiet;
            const RenderedImage ref = reference_renderer->render(camera, mo);
            print_timing("mesh reference, view " + v.name, ref);
            const ImageMetrics m = compare_images(image, ref, field.lattice.spacing);
            write_image(with_suffix(out, "_reference"), shaded_image(ref), prov, overwrite);
            if (!o.no_exr) write_render_exr(with_suffix(out, "_reference", ".exr"), ref, prov, overwrite);
            write_text_atomically(with_suffix(out, "", ".metrics.json"), metrics_to_json(m).dump(2) + "\n", overwrite);
            std::printf("  normal error mean %.3f p95 %.3f deg, coverage mismatch %lld px, shade RMSE %.4f\n",
                        m.normal_angle_degrees.mean, m.normal_angle_degrees.p95,
                        static_cast<long long>(m.coverage_mismatch), m.shade_rmse);
        }
    }
    return 0;
}

int run_grid(const Options& o, const RenderSpec& spec, const nlohmann::json& resolved) {
    if (is_field_file(o.input)) throw std::invalid_argument("--grid needs a mesh INPUT (it samples CC and BCC fields)");
    // The output folder before anything is sampled or rendered.
    if (fs::exists(o.out_dir) && !fs::is_directory(o.out_dir))
        throw std::runtime_error("--out-dir " + o.out_dir + ": is not a folder; expected a folder for the figures");
    fs::create_directories(o.out_dir);
    require_writable_target((fs::path(o.out_dir) / "probe").string(), Overwrite::Allow);
    const auto shared_mesh =
        std::make_shared<const PreparedMesh>(prepare_mesh(load_mesh(mesh_spec_from_argument(o.input), data_search_path(), ".")));
    const PreparedMesh& mesh = *shared_mesh;
    const SampledField cc = obtain_field(shared_mesh, mesh_lattice(mesh, LatticeType::CC, o.cc_resolution, o.margin), o);
    const SampledField bcc = obtain_field(shared_mesh, mesh_lattice(mesh, LatticeType::BCC, o.bcc_resolution, o.margin), o);
    FigureOptions fo = figure_options(spec);  // panels, rows, heat-map scale, downsampling
    fo.render = render_options(o, spec);
    fo.mesh.threads = o.threads;
    fo.mesh.progress = !o.quiet;
    const nlohmann::json prov = provenance(o, resolved, mesh.content_sha256());
    const std::string name = o.name.empty() ? mesh.name() : o.name;
    fs::create_directories(o.out_dir);
    for (const ViewRequest& v : spec.views) {
        const CameraSpec camera = resolve_view(v, mesh.vertices(), spec.width, spec.height);
        fo.title = o.title.empty() ? name + ", view " + v.name + ": CC " + lattice_notation(cc.lattice) + " / BCC " +
                                         lattice_notation(bcc.lattice)
                                   : o.title;
        std::fprintf(stderr, "figure %s, view %s\n", name.c_str(), v.name.c_str());
        const ThesisFigure figure = render_thesis_figure(cc, bcc, fo.reference_row || fo.error_rows ? &mesh : nullptr,
                                                         camera, fo);
        for (const FigurePanel& p : figure.panels) print_timing(p.label, p.image);
        const std::string grid = write_thesis_figure(o.out_dir, name + "_" + v.name, figure, prov,
                                                     o.overwrite ? Overwrite::Allow : Overwrite::Forbid);
        std::printf("  wrote %s (%dx%d)\n", grid.c_str(), figure.grid.width, figure.grid.height);
    }
    return 0;
}

}  // namespace

/// Host memory of the images (memory_budget.h): measured 67 bytes per pixel of one image
/// (peak RSS at 1024^2 and 3072^2), rounded up to 96; a grid holds every panel until the
/// figure is composed (at most 16 panels: two lattices' reconstructions, the reference row
/// and the heat maps) plus the figure itself.
MemoryNeed render_memory_need(const Options& o) {
    const uint64_t w = uint64_t(o.size[0]), h = uint64_t(o.size.size() > 1 ? o.size[1] : o.size[0]);
    const uint64_t images = o.grid ? 17 : 1;
    MemoryNeed need;
    need.host_bytes = kBaseBytes + w * h * 96 * images;  // <= 16384^2 * 96 * 17: no overflow
    need.what = std::string(o.grid ? "a grid of " : "an image of ") + std::to_string(w) + "x" + std::to_string(h) +
                (o.grid ? " pixel panels" : " pixels");
    return need;
}

int main(int argc, char** argv) {
    CLI::App app{"Ray-casts reconstructed distance fields (docs/raycast.md): one image per view, or the thesis grid."};
    sdf::add_version_flag(app, "sdf-render");
    Options o;
    app.add_option("input", o.input, "field file (NAME.json) or mesh (" + mesh_formats_help() + ", on the data path; or shape:NAME)")->required();
    app.add_option("--mesh", o.mesh_file, "field input: the mesh, for --reference and framing");
    app.add_option("--lattice", o.lattice, "mesh input: lattice type")->check(CLI::IsMember(lattice_type_names()))->capture_default_str();
    app.add_option("--resolution", o.resolution, "mesh input: resolution, BCC in thesis notation (64,64,128); default "
                                                 "--cc-resolution or --bcc-resolution")->delimiter(',')->expected(3);
    app.add_option("--cc-resolution", o.cc_resolution, "CC resolution (grid, and the default for --lattice cc)")
        ->delimiter(',')->expected(3)->capture_default_str();
    app.add_option("--bcc-resolution", o.bcc_resolution, "BCC resolution Rx,Ry,2Rz (grid, and the default for --lattice bcc)")
        ->delimiter(',')->expected(3)->capture_default_str();
    app.add_option("--margin", o.margin, "mesh input: lattice margin, fraction of the largest extent")
        ->check(sdf::kNonNegativeNumber)
        ->capture_default_str();
    app.add_option("--interpolator", o.interpolator, interpolator_help() + "; default: bcc_cubic (BCC) or tricubic_lm (CC)")
        ->check(CLI::IsMember(interpolator_names()));
    app.add_option("--derivatives", o.derivatives, "true, fd or fd_weighted (default: true when available)")
        ->check(CLI::IsMember({"true", "fd", "fd_weighted"}));
    app.add_option("--view", o.views, "named view (repeatable): " + [] {
        std::string s;
        for (const std::string& n : named_view_names()) s += (s.empty() ? "" : ", ") + n;
        return s;
    }())->check(CLI::IsMember(named_view_names()));
    app.add_option("--eye", o.eye, "explicit camera: eye x,y,z")->delimiter(',')->expected(3);
    app.add_option("--target", o.target, "explicit camera: target x,y,z")->delimiter(',')->expected(3);
    app.add_option("--up", o.up, "explicit camera: up x,y,z")->delimiter(',')->expected(3)->capture_default_str();
    app.add_option("--fov", o.fov, "vertical field of view, degrees (between 0 and 180, exclusive)")
        ->check(CLI::Validator(
            [](const std::string& text) {
                double fov = 0;
                return CLI::detail::lexical_cast(text, fov) && fov > 0 && fov < 180
                           ? std::string()
                           : "expected a field of view between 0 and 180 degrees (exclusive), got " + text;
            },
            "(0, 180)"))
        ->capture_default_str();
    app.add_option("--size", o.size, "image size W[,H], each in 1..16384 (as in configs)")
        ->delimiter(',')
        ->expected(1, 2)
        ->check(CLI::Range(1, 16384))
        ->capture_default_str();
    app.add_option("--backend", o.backend, "ray caster backend")->check(CLI::IsMember(render_backend_choices()))->capture_default_str();
    app.add_option("--precision", o.precision, "cpu casting precision")->check(CLI::IsMember({"float", "double"}))->capture_default_str();
    app.add_option("--threads", o.threads, "CPU threads (0 = all)")->check(sdf::kNonNegativeNumber)->capture_default_str();
    app.add_option("--repeat", o.repeat, "timed renders (cuda: kernel launches after a warm-up); the median is printed")
        ->check(sdf::kPositiveNumber)->capture_default_str();
    app.add_option("--device", o.device, "CUDA device")->capture_default_str();
    app.add_flag("--reference", o.reference, "single images: also ray-trace the mesh and write metrics");
    app.add_option("--out", o.out, "single images: output image (.png, .exr, .ppm, .pfm)")->capture_default_str();
    app.add_flag("--no-exr", o.no_exr, "single images: skip the EXR with all channels");
    app.add_flag("--grid", o.grid, "the thesis figure (CC and BCC fields of a mesh; the five reconstructions or --panels)");
    app.add_option("--out-dir", o.out_dir, "grid: output directory")->capture_default_str();
    app.add_option("--name", o.name, "grid: file name prefix (default: the mesh's name)");
    app.add_option("--title", o.title, "grid: title line (default: mesh, view and lattices)");
    app.add_flag("--no-reference", o.no_reference, "grid: no reference row (and no heat maps)");
    app.add_flag("--no-error-maps", o.no_error_maps, "grid: no heat-map rows");
    app.add_option("--heat-max", o.heat_max, "grid: heat-map scale, degrees")->check(sdf::kPositiveNumber)->capture_default_str();
    app.add_option("--downsample", o.downsample, "grid: reduce the grid's images by this factor")->check(sdf::kPositiveNumber)->capture_default_str();
    app.add_option("--panels", o.panels,
                   "grid: the reconstructions shown, in order (default: the thesis's five), e.g. "
                   "bcc_cubic/true,bcc_box_quintic,cc_bspline3; each INTERPOLATOR or INTERPOLATOR/DERIVATIVES of: " +
                       interpolator_help())
        ->delimiter(',')
        ->check([](const std::string& text) {
            try {
                parse_panel_request(text);
                return std::string();
            } catch (const std::invalid_argument& e) {
                return std::string(e.what());
            }
        });
    o.sampler.add(app, "--sampler-backend", "backend", "mesh input: sampler backend");
    o.sampler.add(app, "--sampler-method", "method", "mesh input: sampler method");
    o.sampler.add(app, "--sign", "sign",
                  "mesh input: sign mode: pseudonormal, winding (generalized winding number), or auto (winding "
                  "where the mesh report says pseudonormal signs are not exact)");
    app.add_option("--cache-dir", o.cache_dir, "field cache (default $SDF_CACHE_DIR or <repo>/cache)");
    app.add_flag("--no-cache", o.no_cache, "sample again; neither read nor fill the field cache");
    app.add_flag("--overwrite", o.overwrite, "replace existing output files");
    app.add_flag("--quiet", o.quiet, "no progress lines");
    SDF_CLI_PARSE(app, argc, argv);
    o.up_given = app.count("--up") > 0;
    try {
        if (o.quiet) ProgressReporter::set_globally_enabled(false);
        require_host_memory(render_memory_need(o), "");
        // Every option's value (defaults included) as CLI11 writes a config file: the
        // "config" whose SHA-256 is the images' config_hash
        const nlohmann::json resolved = app.config_to_str(true, false);
        const RenderSpec spec = render_spec(o);
        return o.grid ? run_grid(o, spec, resolved) : run_single(o, spec, resolved);
    } catch (const std::bad_alloc&) {
        std::cerr << "sdf-render: error: " << sdf::out_of_memory_message("rendering " + o.input, 0) << "\n";
        return 1;
    } catch (const std::exception& e) {
        std::cerr << "sdf-render: error: " << e.what() << "\n";
        return 1;
    }
}
