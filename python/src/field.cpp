// Fields: sdf_lattices.Field, sample (as run-experiment samples a lattice) and read_field.
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "harness/config/json_reader.h"
#include "harness/config/lattice_spec.h"
#include "harness/config/sampler_spec.h"
#include "harness/distributed/distributed.h"
#include "harness/io/field_file.h"
#include "harness/sampling/sampler_table.h"
#include "python/src/common.h"
#include "python/src/field.h"

namespace sdf {
namespace {

/// The "lattice" object of a config, from sample()'s arguments, parsed by the config's own
/// parser: the same checks and messages as run-experiment's, key path "sample(): lattice".
LatticeSpec lattice_spec_from_arguments(const std::string& type, const py::object& resolution, const py::object& samples,
                                        const py::object& margin) {
    nlohmann::json j = {{"type", type}};
    if (!resolution.is_none()) {
        std::vector<int> r;
        if (py::isinstance<py::int_>(resolution)) {
            const int n = resolution.cast<int>();
            r = type == "bcc" ? std::vector<int>{n, n, 2 * n} : std::vector<int>{n, n, n};
        } else {
            r = resolution.cast<std::vector<int>>();
        }
        j["resolution"] = r;
    }
    if (!samples.is_none()) j["samples"] = samples.cast<int64_t>();
    if (!margin.is_none()) j["margin"] = margin.cast<double>();
    JsonReader reader(j, "sample()", "lattice");
    LatticeSpec spec = parse_lattice_spec(reader);
    reader.finish();
    return spec;
}

Field sample(const PreparedMesh& mesh, const std::string& lattice, const py::object& resolution, const py::object& samples,
             double margin, const std::string& backend, const std::string& method, const std::string& kernel,
             const std::string& sign, const std::string& precision, int threads, const std::string& bcc_strategy,
             bool progress, bool distributed) {
    const bool collective = distributed && distributed_active();
    // Under MPI a bad argument is this rank's failure in the collective exchange, raised on
    // every rank there (no rank waits for one that gave up); alone, it is raised here.
    std::function<SamplingRequest()> setup;
    try {
        choose("lattice", lattice, {"cc", "bcc"});
        if (!(margin >= 0)) throw std::invalid_argument("margin: expected a non-negative fraction of the mesh's largest extent");
        const LatticeSpec spec = lattice_spec_from_arguments(lattice, resolution, samples, py::none());
        nlohmann::json s = {{"backend", backend}, {"method", method},   {"sign", sign},
                            {"precision", precision}, {"threads", threads}, {"bcc_strategy", bcc_strategy},
                            {"progress", progress}};
        if (!kernel.empty()) s["kernel"] = kernel;
        JsonReader reader(s, "sample()", "sampler");
        const SamplerOptions options = parse_sampler_options(reader);
        setup = [spec, options, margin, &mesh] { return SamplingRequest{build_lattice(spec, mesh.bounds(), margin), options}; };
    } catch (const py::error_already_set& e) {
        if (!collective) throw;
        const auto error = std::make_exception_ptr(std::invalid_argument(e.what()));  // no Python object past the GIL
        setup = [error]() -> SamplingRequest { std::rethrow_exception(error); };
    } catch (...) {
        if (!collective) throw;
        const std::exception_ptr error = std::current_exception();
        setup = [error]() -> SamplingRequest { std::rethrow_exception(error); };
    }
    SampledField field;
    {
        py::gil_scoped_release release;
        if (collective) {
            field = sample_collectively(mesh, setup);
        } else {
            const SamplingRequest request = setup();
            field = make_sampler(request.options)->sample(mesh, request.lattice);
        }
    }
    const MeshReport& r = mesh.report();
    field.mesh = {{"name", mesh.name()},
                  {"source", mesh.source()},
                  {"sha256", mesh.content_sha256()},
                  {"vertices", mesh.vertices().size()},
                  {"triangles", mesh.triangles().size()},
                  {"components", r.components},
                  {"sign_reliable", r.sign_reliable()}};
    return Field(std::move(field));
}

Field read_field_file(const std::string& path) {
    py::gil_scoped_release release;
    return Field(read_field(path));
}

}  // namespace

void bind_field(py::module_& m) {
    py::class_<Field>(m, "Field", R"(A sampled field on a CC or BCC lattice: signed distance, exact gradient and
closest triangle at every lattice point, with the lattice and provenance. Arrays are copies
in z, y, x order: CC values have shape (nz, ny, nx); a BCC field (thesis notation
Rx x Ry x 2Rz) is its two CC sub-grids, a tuple (primary (Rz, Ry, Rx), secondary
(Rz-1, Ry-1, Rx-1)), the secondary grid's origin h/2 further along every axis.)")
        .def_property_readonly("lattice", [](const Field& f) { return f.lattice().type == LatticeType::BCC ? "bcc" : "cc"; },
                               "'cc' or 'bcc'.")
        .def_property_readonly("origin", [](const Field& f) {
            const Vec3d o = f.lattice().origin;
            return py::make_tuple(o.x, o.y, o.z);
        }, "World position of the first (primary) lattice point.")
        .def_property_readonly("spacing", [](const Field& f) { return f.lattice().spacing; },
                               "h: the distance between neighbouring primary points along an axis.")
        .def_property_readonly("resolution", [](const Field& f) {
            const Int3 r = f.lattice().resolution;
            return f.lattice().type == LatticeType::BCC ? py::make_tuple(r.x, r.y, 2 * r.z) : py::make_tuple(r.x, r.y, r.z);
        }, "(nx, ny, nz) for CC; (Rx, Ry, 2Rz), the thesis's notation, for BCC.")
        .def_property_readonly("notation", [](const Field& f) { return lattice_notation(f.lattice()); },
                               "'32x32x32' or, BCC, '26x26x52'.")
        .def_property_readonly("num_points", [](const Field& f) { return f.lattice().num_points(); }, "Lattice points in all.")
        .def_property_readonly("grid_origins", &Field::grid_origins,
                               "The origin of each CC sub-grid: one tuple (CC), or (primary, secondary) (BCC).")
        .def_property_readonly("lattice_info", [](const Field& f) { return json_to_python(lattice_to_json(f.lattice())); },
                               "The lattice as a field file's header stores it (dict).")
        .def_property_readonly("values", &Field::values, "Signed distance (or the stored scalar), float64 arrays as described above.")
        .def_property_readonly("gradient", &Field::gradient, "Gradient, float64, shape (..., 3) per sub-grid; None when absent.")
        .def_property_readonly("triangle", &Field::triangle, "Closest triangle per point, int32; None when absent.")
        .def_property_readonly("precision", [](const Field& f) { return precision_name(f.field().precision); },
                               "The search precision it was sampled with.")
        .def_property_readonly("sampler", [](const Field& f) { return json_to_python(f.field().sampler); },
                               "How it was sampled (backend, method, kernel, threads, sign, ...), as recorded in field files.")
        .def_property_readonly("mesh", [](const Field& f) { return json_to_python(f.field().mesh); }, "The mesh it was sampled from (dict).")
        .def_property_readonly("seconds", [](const Field& f) { return f.field().timings.total; }, "Sampling wall time, seconds.")
        .def("write", &Field::write, py::arg("path"), py::arg("dtype") = "float32", py::arg("overwrite") = false,
             py::arg("closest_triangle") = true,
             R"(write(path, dtype="float32", overwrite=False, closest_triangle=True)

Writes the field in the format of path's extension: ".json" is the project's field file
(header plus raw channels, docs/field-format.md; read by sdf-eval, sdf-render and read_field).
Files are written atomically; an existing file is kept unless overwrite=True. Under mpirun
every rank holds the field: write it from one rank (if sl.distributed()["rank"] == 0).)")
        .def("reconstruct", &Field::reconstruct, py::arg("points"), py::arg("interpolator") = "", py::arg("derivatives") = "",
             py::arg("sigma2") = 0.5, py::arg("sigma_units") = "lattice", py::arg("threads") = 0,
             R"(reconstruct(points, interpolator="", derivatives="", sigma2=0.5, sigma_units="lattice", threads=0) -> (values, gradients)

The reconstruction at points ((N, 3) array), as sdf-eval computes it: values (N,) and world
gradients (N, 3). interpolator: a name of docs/reconstruction.md (default bcc_cubic for BCC,
tricubic_lm for CC); derivatives: "true", "fd" or "fd_weighted" (default: "true" where the
interpolator uses derivatives and the field has gradients, else "fd"). Points outside the
domain are clamped into it. The last reconstruction is kept for the next call.)")
        .def("__repr__", [](const Field& f) {
            return "<sdf_lattices.Field " + std::string(f.lattice().type == LatticeType::BCC ? "bcc " : "cc ") +
                   lattice_notation(f.lattice()) + ", " + std::to_string(f.lattice().num_points()) + " points>";
        });

    m.def("sample", &sample, py::arg("mesh"), py::arg("lattice") = "cc", py::arg("resolution") = py::none(),
          py::arg("samples") = py::none(), py::arg("margin") = 0.1, py::arg("backend") = "auto", py::arg("method") = "bvh",
          py::arg("kernel") = "", py::arg("sign") = "auto", py::arg("precision") = "float", py::arg("threads") = 0,
          py::arg("bcc_strategy") = "two_grids", py::arg("progress") = false, py::arg("distributed") = true,
          R"(sample(mesh, lattice="cc", resolution=None, samples=None, margin=0.1, backend="auto", method="bvh", kernel="", sign="auto", precision="float", threads=0, bcc_strategy="two_grids", progress=False, distributed=True) -> Field

Samples the exact signed distance on a lattice fitted around the mesh, as run-experiment
does (its config parser checks these arguments, as the keys "lattice" and "sampler").
Give resolution or samples: resolution is (nx, ny, nz) for CC, (Rx, Ry, 2Rz) for BCC, or one
int n for (n, n, n) / (n, n, 2n); samples is a target point count for a cubic lattice.
margin: the fraction of the mesh's largest extent added on every side (run-experiment's
"domain": {"margin"}). The GIL is released while sampling.

Under `mpirun -np N python3 script.py` (see distributed()), sample() is collective: every rank
must call it with the same mesh and arguments. Rank 0 cuts the lattice into one slab of
z-planes per rank, balanced as run-experiment's are, every rank samples its slab, and every
rank returns the whole field, bit for bit the one a single process samples; its
sampler["distributed"] records the slabs, hosts and per-rank seconds. A failure on any rank
(or arguments that differ from rank 0's) raises on every rank. distributed=False samples on
this rank alone (no other rank takes part).)");


    m.def("read_field", &read_field_file, py::arg("path"),
          R"(read_field(path) -> Field

Reads a field file (NAME.json and its channels, docs/field-format.md): CC or BCC, with or
without gradient and closest-triangle channels.)");

}

}  // namespace sdf
