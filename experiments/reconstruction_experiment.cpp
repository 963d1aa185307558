/// @file reconstruction_experiment.cpp
/// @brief Kind "reconstruction": thesis Figures 5-2..5-11 as numbers. One mesh is sampled on
/// CC and BCC lattices of matched point counts (through the field cache), the configured
/// reconstructions are built (core/reconstruction), and their errors against the
/// exact signed distance are measured at probe points (experiments/common/probes.h): RMS,
/// max and mean |error| over the domain and in a band around the surface, and the angle
/// between reconstructed and exact gradients in the band.
///
///   "metrics": {"domain_probes": 100000, "band_probes": 100000, "band": 1.0, "seed": 1, "threads": 0}
///     band: half-width of the surface band in units of the coarsest lattice spacing
///   "render": {"size": [512, 512], "views": ["side", "front"], ...}   (harness/config/render_spec.h)
///     optional: for every view, the five reconstructions of the thesis's figures (the first
///     CC and the first BCC lattice), the mesh reference and the image metrics, as a labelled
///     grid in the thesis's layout (harness/render/thesis_figure.h) under images/<view>/;
///     "panels": ["bcc_cubic/true", "bcc_box_quintic", ...] chooses other reconstructions
///   every reconstruction also records its cost: prepare_seconds (derivative arrays or
///   prefilter, on the metrics' threads) and eval_ns_per_point (one thread, at the first 2^16
///   probes, i.e. uniformly random domain probes; time_evaluation in reconstruction.h)
///   "thesis_figures": ["5-3", "5-4"]   the thesis figures this study stands for (for reports)
///   "output": {"fields": true}   the sampled fields into the run directory, fields/<mesh>-<label>.json
///     (docs/field-format.md), so a run holds what it measured, not only the cache's hashes
/// and the study keys (study_inputs.h) and "reconstructions" (reconstruction_list.h).
#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <ostream>
#include <sstream>

#include "core/lattice/lattice_fitting.h"
#include "core/raycast/views.h"
#include "core/reconstruction/reconstruction.h"
#include "harness/study/field_source.h"
#include "experiments/common/probes.h"
#include "experiments/common/reconstruction_list.h"
#include "harness/study/study_inputs.h"
#include "harness/experiment/experiment.h"
#include "harness/io/field_file.h"
#include "harness/provenance/provenance.h"
#include "harness/render/thesis_figure.h"

namespace sdf {
namespace {

/// The box every reconstruction covers (probes outside one of them would be clamped there).
DomainBox<double> common_domain(const std::vector<std::unique_ptr<Reconstruction>>& recons) {
    DomainBox<double> box = recons.front()->domain();
    for (const auto& r : recons) {
        const DomainBox<double> d = r->domain();
        for (int a = 0; a < 3; ++a) {
            box.lo[a] = std::max(box.lo[a], d.lo[a]);
            box.hi[a] = std::min(box.hi[a], d.hi[a]);
        }
    }
    return box;
}

class ReconstructionExperiment final : public Experiment {
public:
    void configure(JsonReader& config, const RunContext& context) override {
        inputs_ = read_study_inputs(config, context);
        recons_ = read_reconstructions(config, inputs_.lattices, inputs_.lattice_labels);
        JsonReader m = config.optional_object("metrics");
        probes_.domain_probes = m.optional<int64_t>("domain_probes", 100000, "a number of probes (>= 0)");
        probes_.band_probes = m.optional<int64_t>("band_probes", 100000, "a number of probes (>= 0)");
        if (probes_.domain_probes < 0 || probes_.band_probes < 0 || probes_.domain_probes + probes_.band_probes < 1)
            m.fail("domain_probes", "expected non-negative probe counts, at least one probe in all, got " +
                                        std::to_string(probes_.domain_probes) + " and " + std::to_string(probes_.band_probes));
        // Each probe costs an exact query and 48 bytes; counts beyond this are typos, and
        // their sum must not overflow the reservation of place_probes.
        constexpr int64_t kMaxProbes = int64_t(1) << 30;
        if (probes_.domain_probes > kMaxProbes || probes_.band_probes > kMaxProbes)
            m.fail(probes_.domain_probes > kMaxProbes ? "domain_probes" : "band_probes",
                   "expected at most 2^30 probes, got " +
                       std::to_string(std::max(probes_.domain_probes, probes_.band_probes)));
        probes_.band = m.optional<double>("band", 1.0, "the band half-width in lattice spacings (> 0)");
        if (!(probes_.band > 0)) m.fail("band", "expected a positive number of lattice spacings, got " + std::to_string(probes_.band));
        probes_.seed = m.optional<uint64_t>("seed", 1, "a random seed (a non-negative integer)");
        threads_ = m.optional<int>("threads", inputs_.sampler.threads, "a thread count (0 = all cores)");
        if (threads_ < 0) m.fail("threads", "expected 0 (all cores) or a positive count, got " + std::to_string(threads_));
        m.finish();
        if (config.has("render")) {
            JsonReader r = config.optional_object("render");
            render_ = parse_render_spec(r);
            const FigureOptions figure = figure_options(*render_);
            for (const FigurePanelSpec& p : figure.panels.empty() ? thesis_figure_panels() : figure.panels) {
                const bool present = std::any_of(inputs_.lattices.begin(), inputs_.lattices.end(),
                                                 [&](const LatticeSpec& l) { return l.type == p.lattice; });
                if (!present)
                    config.fail("render", std::string(render_->panels.empty() ? "the thesis's figures need" : "the panels need") +
                                              " a " + lattice_type_label(p.lattice) +
                                              " lattice in \"lattices\" (panel " + p.letter + ": " + p.interpolator + "/" +
                                              p.derivatives + ")");
            }
        }
        figures_ = config.optional<std::vector<std::string>>("thesis_figures", {}, "an array of figure numbers such as \"5-3\"");
        JsonReader out = config.optional_object("output");
        write_fields_ = out.optional<bool>("fields", true, "true or false");
        out.finish();
        // The run's field files are float32: a band they cannot store is refused in the plan,
        // not after sampling (and caching) every lattice.
        if (write_fields_) {
            try {
                require_representable_band(inputs_.sampler.band_width, FieldDtype::Float32, "band_width");
            } catch (const std::invalid_argument& e) {
                config.fail("sampler", std::string(e.what()) + " (the run's fields/ files; or \"output\": {\"fields\": false})");
            }
        }
    }

    MemoryNeed memory_need(const RunContext&) const override {
        // Every lattice's field and reconstructions are alive until the figures are drawn.
        return lattice_memory_need(inputs_, kReconstructionBytesPerPoint, /*all_at_once=*/true, "reconstructing");
    }

    std::vector<std::string> plan(const RunContext& ctx) const override {
        std::ostringstream quiet;
        const PreparedMesh mesh = load_prepared_mesh(inputs_, quiet);
        FieldSource source(ctx, inputs_.sampler);
        std::vector<std::string> lines = {"mesh " + mesh.name() + " (" + mesh.source() + ", " +
                                          with_commas(int64_t(mesh.triangles().size())) + " triangles, sha256 " +
                                          mesh.content_sha256().substr(0, 12) + ")"};
        for (size_t i = 0; i < inputs_.lattices.size(); ++i) {
            const Lattice l = build_lattice(inputs_.lattices[i], mesh.bounds(), inputs_.margin);
            lines.push_back("field " + inputs_.lattice_labels[i] + ": " + lattice_spec_notation(inputs_.lattices[i]) + ", " +
                            with_commas(l.num_points()) + " points, " + inputs_.sampler.backend + "/" +
                            inputs_.sampler.method + ": " + source.status(mesh, l) +
                            (write_fields_ ? "; write fields/" + mesh.name() + "-" + inputs_.lattice_labels[i] + ".json" : ""));
        }
        lines.push_back("probes: " + with_commas(probes_.domain_probes) + " in the common domain + " +
                        with_commas(probes_.band_probes) + " within " + nlohmann::json(probes_.band).dump() +
                        " spacing(s) of the surface (seed " + std::to_string(probes_.seed) +
                        "), exact distances by the sampler's query" + (ctx.cache ? " (or the cache)" : ""));
        for (const ReconstructionEntry& e : recons_)
            lines.push_back("reconstruct " + e.id + (e.thesis_panel.empty() ? "" : " (thesis panel " + e.thesis_panel + ")") +
                            ": errors at the probes");
        if (render_) {
            std::string views;
            for (const ViewRequest& v : render_->views) views += (views.empty() ? "" : ", ") + v.name;
            lines.push_back("render " + views + " at " + std::to_string(render_->width) + "x" +
                            std::to_string(render_->height) + " (" + render_->backend + "): " +
                            (render_->panels.empty() ? std::string("the thesis's five reconstructions")
                                                     : "panels " + panel_list(figure_options(*render_).panels)) +
                            (render_->reference ? ", the mesh reference and image metrics" : "") +
                            ", one labelled grid per view");
        }
        return lines;
    }

    void run(RunContext& ctx) override {
        std::ostream& log = *ctx.log;
        const auto shared_mesh = std::make_shared<const PreparedMesh>(load_prepared_mesh(inputs_, log));
        const PreparedMesh& mesh = *shared_mesh;
        ctx.metrics["mesh"] = describe_prepared_mesh(mesh);
        ctx.inputs["mesh"] = {{"source", mesh.source()}, {"sha256", mesh.content_sha256()}};
        FieldSource source(ctx, inputs_.sampler);

        // Fields, then every reconstruction built from them.
        std::vector<SampledField> fields;
        double h_ref = 0;
        for (size_t i = 0; i < inputs_.lattices.size(); ++i) {
            const Lattice l = build_lattice(inputs_.lattices[i], mesh.bounds(), inputs_.margin);
            ObtainedField got = source.get(shared_mesh, l, inputs_.lattice_labels[i], log);
            nlohmann::json d = got.describe();
            d["label"] = inputs_.lattice_labels[i];
            ctx.metrics["lattices"].push_back(d);
            nlohmann::json input = {{"label", inputs_.lattice_labels[i]}, {"cache_key", got.cache_key}};
            if (write_fields_) {
                const std::string file = "fields/" + mesh.name() + "-" + inputs_.lattice_labels[i] + ".json";
                got.field.mesh = describe_prepared_mesh(mesh);
                write_field((std::filesystem::path(ctx.output_dir) / file).string(), got.field);
                input["file"] = file;
            }
            ctx.inputs["fields"].push_back(input);
            ctx.metrics["regression"]["lattices/" + inputs_.lattice_labels[i] + "/points"] = {{"value", l.num_points()},
                                                                                              {"kind", "exact"}};
            h_ref = std::max(h_ref, l.spacing);
            fields.push_back(std::move(got.field));
        }
        std::vector<std::unique_ptr<Reconstruction>> recons;
        std::vector<double> prepare_seconds;
        for (const ReconstructionEntry& e : recons_) {
            ReconstructionSpec spec = e.spec;
            spec.threads = threads_;
            const auto start = std::chrono::steady_clock::now();
            recons.push_back(std::make_unique<Reconstruction>(fields[e.lattice], spec));
            prepare_seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
        }

        // Probes with exact values, then the errors of each reconstruction.
        const DomainBox<double> box = common_domain(recons);
        std::string probe_log;
        const auto bound = [&]() -> const BoundSampler& { return source.bound(shared_mesh); };
        const ProbeSet probes = make_probes(mesh, box, probes_.band * h_ref, probes_, bound, inputs_.sampler, ctx.cache, &probe_log);
        log << "  " << probe_log << "\n";
        int64_t in_band = 0;
        for (size_t i = 0; i < probes.points.size(); ++i) in_band += probes.in_band(i);
        ctx.metrics["probes"] = {{"domain", probes.domain_count},
                                 {"band_placed", int64_t(probes.points.size()) - probes.domain_count},
                                 {"in_band", in_band},
                                 {"band_width", probes.band_width},
                                 {"band_spacings", probes_.band},
                                 {"h_ref", h_ref},
                                 {"seed", probes_.seed},
                                 {"box", {{box.lo.x, box.lo.y, box.lo.z}, {box.hi.x, box.hi.y, box.hi.z}}}};
        // Errors over no probes would read as 0: a perfect score for nothing measured.
        const int64_t band_placed = int64_t(probes.points.size()) - probes.domain_count;
        if (probes.points.empty() || (probes_.band_probes > 0 && in_band == 0))
            throw std::runtime_error(
                ctx.config_path + ": key 'metrics': no probe " +
                (probes.points.empty() ? std::string("was placed") : "lies within the band") + ": " +
                std::to_string(probes.domain_count) + " domain probes, " + std::to_string(band_placed) + " of " +
                std::to_string(probes_.band_probes) + " band probes placed inside the common domain, " +
                std::to_string(in_band) + " within " + nlohmann::json(probes_.band).dump() +
                " spacing(s) of the surface; nothing would be measured. Expected probes in the domain "
                "(\"domain_probes\" > 0) or a band that fits inside it (a smaller \"band\")");
        ctx.metrics["regression"]["probes/in_band"] = {{"value", in_band}, {"kind", "exact"}};
        print_header(log, h_ref);
        for (size_t k = 0; k < recons.size(); ++k) measure(ctx, recons_[k], *recons[k], probes, h_ref, prepare_seconds[k]);
        if (render_) render_figures(ctx, mesh, fields);
        ctx.metrics["thesis_figures"] = figures_;
    }

private:
    static std::string join(const std::vector<std::string>& v) {
        std::string s;
        for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
        return s;
    }

    static std::string panel_list(const std::vector<FigurePanelSpec>& panels) {
        std::string s;
        for (const FigurePanelSpec& p : panels) s += (s.empty() ? "" : ", ") + p.letter + " " + p.interpolator + "/" + p.derivatives;
        return s;
    }

    static void print_header(std::ostream& log, double h) {
        char line[256];
        std::snprintf(line, sizeof line,
                      "  errors in units of h = %.4g (the coarsest spacing):\n  %-44s %10s %10s %10s %10s %8s %8s %8s\n", h,
                      "reconstruction", "RMS", "max", "band mean", "band RMS", "angle", "p95", "ns/point");
        log << line;
    }

    void measure(RunContext& ctx, const ReconstructionEntry& e, const Reconstruction& recon, const ProbeSet& probes,
                 double h, double prepare_seconds) {
        const auto got = recon.evaluate(probes.points, threads_);
        const EvaluationTiming timing = time_evaluation(recon, probes.points);
        const nlohmann::json err = probe_errors(probes, got);
        const nlohmann::json& d = err["domain"];
        const nlohmann::json& b = err["band"];
        char line[256];
        std::snprintf(line, sizeof line, "  %-44s %10.4g %10.4g %10.4g %10.4g %7.3g° %7.3g° %8.1f\n",
                      (e.id + (e.thesis_panel.empty() ? "" : " (" + e.thesis_panel + ")")).c_str(),
                      d["rms"].get<double>() / h, err["max_abs"].get<double>() / h, b["mean_abs"].get<double>() / h,
                      b["rms"].get<double>() / h, b["gradient_angle_mean_deg"].get<double>(),
                      b["gradient_angle_p95_deg"].get<double>(), timing.ns_per_point);
        *ctx.log << line;
        ctx.metrics["reconstructions"].push_back({{"id", e.id},
                                                  {"lattice", inputs_.lattice_labels[e.lattice]},
                                                  {"interpolator", interpolator_name(e.spec.interpolator)},
                                                  {"derivatives", derivative_source_name(e.spec.derivatives)},
                                                  {"description", recon.description()},
                                                  {"thesis_panel", e.thesis_panel},
                                                  {"prepare_seconds", prepare_seconds},
                                                  {"eval_ns_per_point", timing.ns_per_point},
                                                  {"timed_points", timing.points},
                                                  {"errors", err}});
        nlohmann::json& reg = ctx.metrics["regression"];
        auto add = [&](const std::string& name, double v) { reg[e.id + "/" + name] = {{"value", v}, {"kind", "error"}}; };
        add("domain_rms", d["rms"]);
        add("max_abs", err["max_abs"]);
        add("band_rms", b["rms"]);
        add("band_mean_abs", b["mean_abs"]);
        add("gradient_angle_mean_deg", b["gradient_angle_mean_deg"]);
        add("gradient_angle_p95_deg", b["gradient_angle_p95_deg"]);
    }

    /// The figure grid for every configured view (the thesis's five panels, or the config's
    /// "panels"), from the first CC and BCC fields.
    void render_figures(RunContext& ctx, const PreparedMesh& mesh, const std::vector<SampledField>& fields) {
        const SampledField* cc = nullptr;
        const SampledField* bcc = nullptr;
        for (const SampledField& f : fields) {
            if (!cc && f.lattice.type == LatticeType::CC) cc = &f;
            if (!bcc && f.lattice.type == LatticeType::BCC) bcc = &f;
        }
        const FigureOptions options = figure_options(*render_);
        const nlohmann::json provenance = {{"run", ctx.run_id}, {"git", machine_and_build()["git"]}};
        for (const ViewRequest& view : render_->views) {
            const CameraSpec camera = resolve_view(view, mesh.vertices(), render_->width, render_->height);
            *ctx.log << "  rendering view " << view.name << " (" << render_->width << "x" << render_->height << ")\n";
            const ThesisFigure figure = render_thesis_figure(cc, bcc, render_->reference ? &mesh : nullptr, camera, options);
            const std::string dir = ctx.output_dir + "/images/" + view.name;
            std::filesystem::create_directories(dir);
            const std::string grid = write_thesis_figure(dir, mesh.name() + "_" + view.name, figure, provenance);
            nlohmann::json summary = figure.summary;
            summary["grid_file"] = std::filesystem::relative(grid, ctx.output_dir).string();
            ctx.metrics["render"]["views"][view.name] = summary;
            for (const FigurePanel& p : figure.panels) {
                if (!p.has_metrics) continue;
                const std::string id = "render/" + view.name + "/" + p.spec.letter + "_" + p.spec.interpolator + "_" + p.spec.derivatives;
                ctx.metrics["regression"][id + "/normal_angle_mean_deg"] = {{"value", p.metrics.normal_angle_degrees.mean}, {"kind", "error"}};
            }
        }
    }

    StudyInputs inputs_;
    std::vector<ReconstructionEntry> recons_;
    ProbeSpec probes_;
    int threads_ = 0;
    std::optional<RenderSpec> render_;
    std::vector<std::string> figures_;
    bool write_fields_ = true;
};

}  // namespace

std::unique_ptr<Experiment> make_reconstruction_experiment() { return std::make_unique<ReconstructionExperiment>(); }

}  // namespace sdf
