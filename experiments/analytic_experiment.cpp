/// @file analytic_experiment.cpp
/// @brief Kind "analytic": reconstruction of analytic functions (no mesh, no sampler), via
/// run_analytic_study() of core/reconstruction/analytic_study.h.
///
///   "table_4_1": {"function": "marschner_lobb", "resolution": [111, 111, 222],
///                 "probes_per_axis": 256, "margin": 2.0, "sigma2": 0.5, "sigma_units": "lattice"}
///     thesis Table 4-1, ML row: bcc_cubic with plain ("fd") and Gaussian-weighted
///     ("fd_weighted") least-squares derivatives; the thesis's numbers beside ours.
///   "convergence": {"function": "trig", "samples": [4096, 32768, 262144],
///                   "interpolators": ["catmull_rom", "bcc_cubic/true", ...],
///                   "probes_per_axis": 64, "margin": 2.0, "padding": 0, "probes": "grid"}
///     error versus sample count, CC and BCC lattices of matched counts over [-1,1]^3.
///     padding: lattice spacings the sampled lattices extend beyond [-1,1]^3 (the samples
///     counted are still those over [-1,1]^3, and the probes stay in it): with padding above
///     the margin every filter is measured at the same probes, away from its boundary
///     treatment. probes: "grid" (cell centres) or "random" (as many uniformly random
///     points, the same for every filter; analytic_study.h says why). Every point also
///     records the filter's cost: prepare_seconds (derivative arrays or prefilter) and
///     eval_ns_per_point (one thread, analytic_study.h).
///   "threads": 0
/// margin: probes stay this many spacings inside the interpolator's domain (2 keeps every
/// BCC derivative fit centred: analytic_study.h). At least one of the two studies is needed.
#include <cstdio>
#include <ostream>

#include "core/lattice/lattice_fitting.h"
#include "core/reconstruction/analytic_study.h"
#include "harness/study/study_inputs.h"
#include "experiments/common/thesis_tables.h"
#include "harness/experiment/experiment.h"

namespace sdf {
namespace {

struct Table41Spec {
    bool enabled = false;
    std::string function = "marschner_lobb";
    Int3 resolution{111, 111, 111};  ///< BCC primary
    int probes_per_axis = 256;
    double margin = 2.0, sigma2 = 0.5;
    SigmaUnits units = SigmaUnits::LatticeUnits;
};

struct CurveSpec {
    std::string id;  ///< "bcc_cubic/true"
    ReconstructionSpec spec;
};

struct ConvergenceSpec {
    bool enabled = false;
    std::string function = "trig";
    std::vector<int64_t> samples;
    std::vector<CurveSpec> curves;
    int probes_per_axis = 64;
    double margin = 2.0;
    int padding = 0;
    bool random_probes = false;
};

std::string function_choice(JsonReader& r, const std::string& fallback) {
    return r.choice("function", {"marschner_lobb", "trig"}, fallback);
}

int probes_per_axis(JsonReader& r, int fallback) {
    const int n = r.optional<int>("probes_per_axis", fallback, "probes per axis (2 to 2048)");
    if (n < 2 || n > 2048) r.fail("probes_per_axis", "expected 2 to 2048, got " + std::to_string(n));
    return n;
}

double margin_of(JsonReader& r) {
    const double m = r.optional<double>("margin", 2.0, "a margin in lattice spacings (>= 0)");
    if (!(m >= 0)) r.fail("margin", "expected a non-negative number of spacings, got " + std::to_string(m));
    return m;
}

CurveSpec parse_curve(JsonReader& r, const std::string& text) {
    const std::string name = text.substr(0, text.find('/'));
    CurveSpec c;
    c.id = text;
    try {
        c.spec.interpolator = parse_interpolator(name);
        c.spec.derivatives = text.find('/') == std::string::npos
                                 ? default_derivative_source(c.spec.interpolator, true)
                                 : parse_derivative_source(text.substr(text.find('/') + 1));
        Lattice probe;
        probe.type = interpolator_lattice(c.spec.interpolator);
        probe.resolution = {8, 8, 8};
        validate_reconstruction(c.spec, probe, true);
    } catch (const std::invalid_argument& e) {
        r.fail("interpolators", "\"" + text + "\": " + e.what() + " (entries are \"interpolator\" or \"interpolator/derivatives\")");
    }
    if (text.find('/') == std::string::npos) c.id = text + "/" + derivative_source_name(c.spec.derivatives);
    return c;
}

class AnalyticExperiment final : public Experiment {
public:
    void configure(JsonReader& config, const RunContext&) override {
        threads_ = config.optional<int>("threads", 0, "a thread count (0 = all cores)");
        if (threads_ < 0) config.fail("threads", "expected 0 (all cores) or a positive count, got " + std::to_string(threads_));
        if (config.has("table_4_1")) read_table(config.object("table_4_1"));
        if (config.has("convergence")) read_convergence(config.object("convergence"));
        if (!table_.enabled && !conv_.enabled)
            config.fail("table_4_1", "missing; an analytic study needs \"table_4_1\", \"convergence\" or both");
    }

    std::vector<std::string> plan(const RunContext&) const override {
        std::vector<std::string> lines;
        if (table_.enabled) {
            Lattice l;
            l.type = LatticeType::BCC;
            l.resolution = table_.resolution;
            for (const char* src : {"fd", "fd_weighted"})
                lines.push_back("Table 4-1: " + table_.function + " on BCC " + lattice_notation(l) + " over [-1,1]^3, bcc_cubic/" +
                                src + ", " + std::to_string(table_.probes_per_axis) + "^3 probes " +
                                nlohmann::json(table_.margin).dump() + " spacings inside");
        }
        if (conv_.enabled)
            for (const CurveSpec& c : conv_.curves) {
                std::string counts;
                for (int64_t n : conv_.samples)
                    counts += (counts.empty() ? "" : ", ") + std::to_string(cubic_resolution_for_samples(interpolator_lattice(c.spec.interpolator), n)) + "^3";
                lines.push_back("convergence: " + conv_.function + " with " + c.id + " on " +
                                lattice_type_name(interpolator_lattice(c.spec.interpolator)) + " lattices " + counts +
                                " (" + std::to_string(conv_.probes_per_axis) + "^3 probes each" +
                                (conv_.random_probes ? " at random" : "") +
                                (conv_.padding ? ", lattices padded by " + std::to_string(conv_.padding) + " spacings" : "") + ")");
            }
        return lines;
    }

    void run(RunContext& ctx) override {
        if (table_.enabled) run_table(ctx);
        if (conv_.enabled) run_convergence(ctx);
    }

private:
    void read_table(JsonReader r) {
        table_.enabled = true;
        table_.function = function_choice(r, "marschner_lobb");
        const auto res = r.optional<std::vector<int>>("resolution", {111, 111, 222}, "a BCC resolution [Rx, Ry, 2Rz]");
        if (res.size() != 3 || res[0] < 4 || res[1] < 4 || res[2] < 8 || res[2] % 2 != 0 || res[0] != res[1] ||
            res[0] != res[2] / 2)
            r.fail("resolution", "expected a cubic BCC resolution [R, R, 2R] with R >= 4 (the lattice spans [-1,1]^3), got " +
                                     nlohmann::json(res).dump());
        table_.resolution = {res[0], res[1], res[2] / 2};
        table_.probes_per_axis = probes_per_axis(r, 256);
        table_.margin = margin_of(r);
        if (table_.resolution.x < 2 * table_.margin + 5)
            r.fail("margin", "leaves no probe box on a " + std::to_string(table_.resolution.x) + "^3 primary grid, got " +
                                 nlohmann::json(table_.margin).dump());
        table_.sigma2 = r.optional<double>("sigma2", 0.5, "sigma^2 of the Gaussian weights");
        if (!(table_.sigma2 > 0)) r.fail("sigma2", "expected a positive number, got " + std::to_string(table_.sigma2));
        table_.units = r.choice("sigma_units", {"lattice", "spacing"}, "lattice") == "lattice" ? SigmaUnits::LatticeUnits
                                                                                              : SigmaUnits::Spacing;
        r.finish();
    }

    void read_convergence(JsonReader r) {
        conv_.enabled = true;
        conv_.function = function_choice(r, "trig");
        conv_.samples = r.optional<std::vector<int64_t>>("samples", {4096, 32768, 262144}, "an array of sample counts");
        if (conv_.samples.empty()) r.fail("samples", "expected at least one sample count, got []");
        for (int64_t n : conv_.samples)
            if (n < 64 || n > 50000000) r.fail("samples", "expected sample counts from 64 to 50,000,000, got " + std::to_string(n));
        const std::vector<std::string> names = r.optional<std::vector<std::string>>(
            "interpolators", {"trilinear", "catmull_rom", "tricubic_lm/true", "tricubic_lm/fd", "bcc_linear", "bcc_cubic/true", "bcc_cubic/fd"},
            "an array of \"interpolator\" or \"interpolator/derivatives\"");
        if (names.empty()) r.fail("interpolators", "expected at least one interpolator, got []");
        for (const std::string& n : names) conv_.curves.push_back(parse_curve(r, n));
        conv_.probes_per_axis = probes_per_axis(r, 64);
        conv_.margin = margin_of(r);
        conv_.padding = r.optional<int>("padding", 0, "lattice spacings beyond [-1,1]^3 (0 to 32)");
        if (conv_.padding < 0 || conv_.padding > 32)
            r.fail("padding", "expected 0 to 32 lattice spacings, got " + std::to_string(conv_.padding));
        conv_.random_probes = r.choice("probes", {"grid", "random"}, "grid") == "random";
        for (const CurveSpec& c : conv_.curves)
            for (int64_t n : conv_.samples) {
                const int res = cubic_resolution_for_samples(interpolator_lattice(c.spec.interpolator), n);
                if (res < 2 * conv_.margin + 5)
                    r.fail("samples", std::to_string(n) + " samples give " + c.id + " a " + std::to_string(res) +
                                          "^3 lattice, too small for probes " + nlohmann::json(conv_.margin).dump() +
                                          " spacings inside it; use more samples or a smaller \"margin\"");
            }
        r.finish();
    }

    AnalyticStudyResult study(const std::string& function, LatticeType type, Int3 res, const ReconstructionSpec& rs,
                              int probes, double margin, int padding = 0, bool random_probes = false) const {
        AnalyticStudySpec s;
        s.function = function;
        s.lattice = type;
        s.resolution = res;
        s.reconstruction = rs;
        s.probes_per_axis = probes;
        s.margin = margin;
        s.padding = padding;
        s.random_probes = random_probes;
        s.threads = threads_;
        return run_analytic_study(s);
    }

    void run_table(RunContext& ctx) {
        std::ostream& log = *ctx.log;
        ReconstructionSpec rs{kind_of<BccCubic>(), DerivativeSource::FiniteDifferences};
        rs.sigma2 = table_.sigma2;
        rs.sigma_units = table_.units;
        log << "Table 4-1 (" << table_.function << "), plain least squares ..." << std::endl;
        const AnalyticStudyResult plain = study(table_.function, LatticeType::BCC, table_.resolution, rs, table_.probes_per_axis, table_.margin);
        rs.derivatives = DerivativeSource::FiniteDifferencesWeighted;
        log << "Table 4-1 (" << table_.function << "), Gaussian-weighted least squares ..." << std::endl;
        const AnalyticStudyResult weighted = study(table_.function, LatticeType::BCC, table_.resolution, rs, table_.probes_per_axis, table_.margin);
        const double ratio = weighted.rms / plain.rms;
        const ThesisTable41Row& th = kThesisTable41[0];
        char line[400];
        std::snprintf(line, sizeof line,
                      "  %-10s %12s %12s %12s %12s\n  %-10s %12.5g %12.5g %12.5f %12.4f\n  %-10s %12.5g %12.5g %12.5f %12.4f\n"
                      "  weighted / plain (RMS): %.4f; thesis %.3f / %.3f = %.4f (norm not defined there)\n",
                      "", "RMS", "max |e|", "RMS x 255", "L2 x 255", "plain", plain.rms, plain.max_abs, plain.rms_255,
                      plain.l2_norm_255, "weighted", weighted.rms, weighted.max_abs, weighted.rms_255, weighted.l2_norm_255,
                      ratio, th.weighted, th.plain, th.weighted / th.plain);
        log << line;
        ctx.metrics["table_4_1"] = {{"function", table_.function},
                                    {"lattice", plain.lattice},
                                    {"margin_spacings", table_.margin},
                                    {"sigma2", table_.sigma2},
                                    {"sigma_units", sigma_units_name(table_.units)},
                                    {"plain", to_json(plain)},
                                    {"weighted", to_json(weighted)},
                                    {"ratio_rms", ratio},
                                    {"thesis", {{"dataset", th.dataset}, {"plain", th.plain}, {"weighted", th.weighted},
                                                {"ratio", th.weighted / th.plain}}}};
        nlohmann::json& reg = ctx.metrics["regression"];
        reg["table_4_1/plain/rms"] = {{"value", plain.rms}, {"kind", "error"}};
        reg["table_4_1/weighted/rms"] = {{"value", weighted.rms}, {"kind", "error"}};
        reg["table_4_1/ratio_rms"] = {{"value", ratio}, {"kind", "error"}};
    }

    void run_convergence(RunContext& ctx) {
        std::ostream& log = *ctx.log;
        log << "error versus samples (" << conv_.function << "):\n";
        for (const CurveSpec& c : conv_.curves) {
            const LatticeType type = interpolator_lattice(c.spec.interpolator);
            nlohmann::json curve = {{"id", c.id}, {"lattice_type", lattice_type_name(type)}, {"points", nlohmann::json::array()}};
            for (int64_t n : conv_.samples) {
                const int r = cubic_resolution_for_samples(type, n);
                const AnalyticStudyResult res =
                    study(conv_.function, type, {r, r, r}, c.spec, conv_.probes_per_axis, conv_.margin, conv_.padding,
                          conv_.random_probes);
                char line[240];
                std::snprintf(line, sizeof line,
                              "  %-26s %-12s %10s points: RMS %.4e  max %.4e  gradient RMS %.4e  %6.1f ns/point\n",
                              c.id.c_str(), res.lattice.c_str(), with_commas(res.lattice_points).c_str(), res.rms, res.max_abs,
                              res.gradient_rms, res.eval_ns_per_point);
                log << line;
                nlohmann::json p = to_json(res);
                p["samples_requested"] = n;
                curve["points"].push_back(p);
                ctx.metrics["regression"]["convergence/" + c.id + "/" + std::to_string(n) + "/rms"] = {{"value", res.rms},
                                                                                                        {"kind", "error"}};
            }
            ctx.metrics["convergence"]["function"] = conv_.function;
            ctx.metrics["convergence"]["curves"].push_back(curve);
        }
    }

    int threads_ = 0;
    Table41Spec table_;
    ConvergenceSpec conv_;
};

}  // namespace

std::unique_ptr<Experiment> make_analytic_experiment() { return std::make_unique<AnalyticExperiment>(); }

}  // namespace sdf
