/// @file sampling_experiment.cpp
/// @brief Kind "sampling": sample a mesh's exact signed distance on each configured lattice,
/// write the fields, and summarise counts, timing and pairs per second.
///
///   "output": {"dtype": "float32" | "float64", "nrrd": false, "uint8": false}
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <ostream>

#include "cpu_reference/lattice/lattice_fitting.h"
#include "experiments/common/study_inputs.h"
#include "experiments/experiment.h"
#include "harness/config/sampler_spec.h"
#include "harness/io/field_file.h"
#include "harness/sampling/make_sampler.h"

namespace sdf {
namespace {

std::string with_commas(int64_t v) {
    std::string s = std::to_string(v);
    for (int i = int(s.size()) - 3; i > 0; i -= 3) s.insert(size_t(i), ",");
    return s;
}

class SamplingExperiment final : public Experiment {
public:
    void configure(JsonReader& config, const RunContext& context) override {
        inputs_ = read_study_inputs(config, context);
        if (config.has("output")) {
            JsonReader out = config.object("output");
            dtype_ = out.choice("dtype", {"float32", "float64"}, "float32") == "float32" ? FieldDtype::Float32
                                                                                       : FieldDtype::Float64;
            nrrd_ = out.optional<bool>("nrrd", false, "true or false");
            uint8_ = out.optional<bool>("uint8", false, "true or false");
            out.finish();
        }
    }

    std::vector<std::string> plan() const override {
        std::vector<std::string> lines;
        for (const LatticeSpec& l : inputs_.lattices)
            lines.push_back("sample " + inputs_.mesh.label() + " on " + lattice_type_name(l.type) + " " +
                            (l.samples > 0 ? "~" + with_commas(l.samples) + " points"
                                           : std::to_string(l.resolution.x) + "x" + std::to_string(l.resolution.y) +
                                                 "x" + std::to_string(l.type == LatticeType::BCC ? 2 * l.resolution.z
                                                                                                 : l.resolution.z)) +
                            " with " + inputs_.sampler.backend + "/" + inputs_.sampler.method);
        return lines;
    }

    void run(RunContext& ctx) override {
        std::ostream& log = *ctx.log;
        const PreparedMesh mesh = load_prepared_mesh(inputs_, log);
        const nlohmann::json mesh_json = describe_mesh(mesh);
        ctx.metrics["mesh"] = mesh_json;
        auto sampler = make_sampler(inputs_.sampler);
        const std::string fields_dir = (std::filesystem::path(ctx.output_dir) / "fields").string();
        for (const LatticeSpec& spec : inputs_.lattices) {
            const Lattice lattice = build_lattice(spec, mesh.bounds, inputs_.margin);
            SampledField field = sampler->sample(mesh, lattice);
            field.mesh = mesh_json;
            const std::string stem = mesh.name + "-" + lattice_type_name(lattice.type) + "-" + lattice_notation(lattice);
            FieldWriteOptions wo;
            wo.dtype = dtype_;
            write_field(fields_dir + "/" + stem + ".json", field, wo);
            if (nrrd_ && lattice.type == LatticeType::CC) export_nrrd(fields_dir + "/" + stem + ".nrrd", field, true);
            if (uint8_) export_uint8(fields_dir + "/" + stem + ".u8.raw", field);
            summarise(log, ctx, sampler->name(), mesh, field, stem);
        }
    }

private:
    void summarise(std::ostream& log, RunContext& ctx, const std::string& sampler_name, const PreparedMesh& mesh,
                   const SampledField& f, const std::string& stem) {
        const auto [lo, hi] = std::minmax_element(f.distance.begin(), f.distance.end());
        const int64_t inside = std::count_if(f.distance.begin(), f.distance.end(), [](double d) { return d < 0; });
        const SamplingTimings& t = f.timings;
        char line[512];
        std::snprintf(line, sizeof line,
                      "%s %s: %s points x %s triangles = %.3g pairs in %.3f s (%s, %s threads, %s): %.3g pairs/s\n"
                      "    distance in [%.6g, %.6g], %s points inside\n",
                      lattice_type_name(f.lattice.type), lattice_notation(f.lattice).c_str(),
                      with_commas(f.size()).c_str(), with_commas(int64_t(mesh.triangles.size())).c_str(),
                      t.point_triangle_pairs, t.kernel, sampler_name.c_str(),
                      f.sampler.value("threads", nlohmann::json(0)).dump().c_str(), precision_name(f.precision),
                      t.pairs_per_second(), *lo, *hi, with_commas(inside).c_str());
        log << line;
        ctx.metrics["fields"].push_back({{"name", stem},
                                         {"lattice", lattice_to_json(f.lattice)},
                                         {"sampler", f.sampler},
                                         {"seconds", t.total},
                                         {"kernel_seconds", t.kernel},
                                         {"upload_seconds", t.upload},
                                         {"download_seconds", t.download},
                                         {"pairs", t.point_triangle_pairs},
                                         {"pairs_per_second", t.pairs_per_second()},
                                         {"distance_min", *lo},
                                         {"distance_max", *hi},
                                         {"points_inside", inside}});
    }

    StudyInputs inputs_;
    FieldDtype dtype_ = FieldDtype::Float32;
    bool nrrd_ = false, uint8_ = false;
};

}  // namespace

std::unique_ptr<Experiment> make_sampling_experiment() { return std::make_unique<SamplingExperiment>(); }

}  // namespace sdf
