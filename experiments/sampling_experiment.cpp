/// @file sampling_experiment.cpp
/// @brief Kind "sampling": sample a mesh's exact signed distance on each configured lattice
/// (through the field cache), write the fields into the run directory, and summarise
/// counts, timing and pairs per second.
///
///   "output": {"dtype": "float32" | "float64", "nrrd": false, "uint8": false,
///              "formats": ["vdb", "vti", "npy", "npz"], "vdb_band": 3}
/// Field files are named <mesh>-<lattice label> (lattice_spec.h: "box-cc-8x8x8"); "formats"
/// adds the volume formats of harness/io/volume_formats.h beside them.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <ostream>
#include <sstream>

#include "core/lattice/lattice_fitting.h"
#include "harness/study/field_source.h"
#include "harness/study/study_inputs.h"
#include "harness/distributed/distributed.h"
#include "harness/experiment/experiment.h"
#include "harness/io/field_file.h"
#include "harness/io/volume_formats.h"

namespace sdf {
namespace {

class SamplingExperiment final : public Experiment {
public:
    void configure(JsonReader& config, const RunContext& context) override {
        inputs_ = read_study_inputs(config, context);
        JsonReader out = config.optional_object("output");
        dtype_ = out.choice("dtype", {"float32", "float64"}, "float32") == "float32" ? FieldDtype::Float32 : FieldDtype::Float64;
        nrrd_ = out.optional<bool>("nrrd", false, "true or false");
        uint8_ = out.optional<bool>("uint8", false, "true or false");
        read_volume_formats(out);
        out.finish();
        // A band the field files cannot store is refused in the plan, not after sampling.
        try {
            require_representable_band(inputs_.sampler.band_width, dtype_, "band_width");
        } catch (const std::invalid_argument& e) {
            config.fail("sampler", std::string(e.what()) + " (output.dtype \"" +
                                       (dtype_ == FieldDtype::Float32 ? "float32" : "float64") + "\")");
        }
    }

    MemoryNeed memory_need(const RunContext&) const override {
        // One lattice at a time: each field is written and released before the next.
        return lattice_memory_need(inputs_, kSamplingBytesPerPoint, /*all_at_once=*/false, "sampling");
    }

    std::vector<std::string> plan(const RunContext& ctx) const override {
        std::ostringstream quiet;
        const PreparedMesh mesh = load_prepared_mesh(inputs_, quiet);
        FieldSource source(ctx, inputs_.sampler);
        std::vector<std::string> lines = {"mesh " + mesh.name() + " (" + mesh.source() + ", " +
                                          with_commas(int64_t(mesh.triangles().size())) + " triangles)"};
        for (size_t i = 0; i < inputs_.lattices.size(); ++i) {
            const Lattice lattice = build_lattice(inputs_.lattices[i], mesh.bounds(), inputs_.margin);
            lines.push_back("sample " + mesh.name() + " on " + lattice_spec_notation(inputs_.lattices[i]) + " (" +
                            with_commas(lattice.num_points()) + " points) with " + inputs_.sampler.backend + "/" +
                            inputs_.sampler.method + ": " + source.status(mesh, lattice) + "; write fields/" +
                            mesh.name() + "-" + inputs_.lattice_labels[i] + ".json" + planned_formats());
        }
        return lines;
    }

    void run(RunContext& ctx) override {
        std::ostream& log = *ctx.log;
        const auto shared_mesh = std::make_shared<const PreparedMesh>(load_prepared_mesh(inputs_, log));
        const PreparedMesh& mesh = *shared_mesh;
        const MeshProvenance described = describe_prepared_mesh(mesh);
        ctx.metrics["mesh"] = described;
        ctx.inputs["mesh"] = described;
        FieldSource source(ctx, inputs_.sampler);
        const std::string fields_dir = (std::filesystem::path(ctx.output_dir) / "fields").string();
        for (size_t i = 0; i < inputs_.lattices.size(); ++i) {
            const Lattice lattice = build_lattice(inputs_.lattices[i], mesh.bounds(), inputs_.margin);
            ObtainedField got = source.get(shared_mesh, lattice, inputs_.lattice_labels[i], log);
            SampledField& field = got.field;
            field.mesh = described;
            const std::string stem = mesh.name() + "-" + inputs_.lattice_labels[i];
            FieldWriteOptions wo;
            wo.dtype = dtype_;
            // In a distributed run, every rank writes its slabs of a field it sampled (MPI-IO).
            write_sampled_field(fields_dir + "/" + stem + ".json", field, wo);
            if (nrrd_ && lattice.type == LatticeType::CC) export_nrrd(fields_dir + "/" + stem + ".nrrd", field, true);
            if (uint8_) export_uint8(fields_dir + "/" + stem + ".u8.raw", field);
            for (VolumeFormat format : formats_)
                write_field_as(field, fields_dir + "/" + stem + "." + volume_format_name(format), format, volume_options_);
            ctx.inputs["fields"].push_back({{"name", stem}, {"cache_key", got.cache_key}});
            summarise(log, ctx, mesh, got, stem);
        }
    }

private:
    /// "formats": names from the one table (volume_formats.h), each at most once; "vdb"
    /// only where the build has OpenVDB, refused here rather than after sampling.
    void read_volume_formats(JsonReader& out) {
        const std::string expected = "an array of volume format names (" + volume_format_names() + ")";
        const auto names = out.optional<std::vector<std::string>>("formats", {}, expected);
        for (const std::string& name : names) {
            VolumeFormat format{};
            try {
                format = volume_format_from_name(name);
            } catch (const std::invalid_argument& e) {
                out.fail("formats", e.what());
            }
            if (std::find(formats_.begin(), formats_.end(), format) != formats_.end())
                out.fail("formats", "\"" + name + "\" is listed twice");
            if (!volume_format_available(format))
                out.fail("formats", "\"" + name + "\" needs OpenVDB, which this build lacks (install libopenvdb-dev, "
                                    "scripts/install-deps, and configure again)");
            formats_.push_back(format);
        }
        volume_options_.dtype = dtype_;
        volume_options_.vdb_band = out.optional<double>("vdb_band", 3.0, "the OpenVDB narrow band's half-width in spacings (> 0)");
        if (!(volume_options_.vdb_band > 0))
            out.fail("vdb_band", "expected the OpenVDB narrow band's half-width in spacings (> 0), got " +
                                     out.raw("vdb_band").dump());
    }

    std::string planned_formats() const {
        std::string text;
        for (VolumeFormat format : formats_) text += std::string(text.empty() ? " and " : ", ") + volume_format_name(format);
        return text;
    }

    void summarise(std::ostream& log, RunContext& ctx, const PreparedMesh& mesh, const ObtainedField& got,
                   const std::string& stem) {
        const SampledField& f = got.field;
        const auto [lo, hi] = std::minmax_element(f.distance.begin(), f.distance.end());
        const int64_t inside = std::count_if(f.distance.begin(), f.distance.end(), [](double d) { return d < 0; });
        const SamplingTimings& t = f.timings;
        char line[512];
        std::snprintf(line, sizeof line,
                      "%s %s: %s points x %s triangles = %.3g pairs in %.3f s (%s, %s threads, %s%s): %.3g pairs/s\n"
                      "    distance in [%.6g, %.6g], %s points inside\n",
                      lattice_type_name(f.lattice.type), lattice_notation(f.lattice).c_str(),
                      with_commas(f.size()).c_str(), with_commas(int64_t(mesh.triangles().size())).c_str(),
                      t.point_triangle_pairs, t.kernel,
                      (f.sampler.backend.empty() ? std::string("?/?") : f.sampler.backend + "/" + f.sampler.kernel).c_str(),
                      f.sampler.details.value("threads", nlohmann::json(0)).dump().c_str(), precision_name(f.precision),
                      got.from_cache ? ", from the cache" : "", t.pairs_per_second(), *lo, *hi, with_commas(inside).c_str());
        log << line;
        nlohmann::json entry = got.describe();
        entry["name"] = stem;
        entry["upload_seconds"] = t.upload;
        entry["download_seconds"] = t.download;
        entry["pairs"] = t.point_triangle_pairs;
        entry["distance_min"] = *lo;
        entry["distance_max"] = *hi;
        entry["points_inside"] = inside;
        ctx.metrics["fields"].push_back(entry);
        ctx.metrics["regression"][stem + "/points"] = {{"value", f.size()}, {"kind", "exact"}};
    }

    StudyInputs inputs_;
    FieldDtype dtype_ = FieldDtype::Float32;
    bool nrrd_ = false, uint8_ = false;
    std::vector<VolumeFormat> formats_;
    VolumeWriteOptions volume_options_;
};

}  // namespace

std::unique_ptr<Experiment> make_sampling_experiment() { return std::make_unique<SamplingExperiment>(); }

}  // namespace sdf
