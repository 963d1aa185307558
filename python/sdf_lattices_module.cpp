// The Python module sdf_lattices (pybind11): meshes, exact point queries, sampled CC/BCC
// fields, their reconstruction and ray-cast images, with NumPy arrays in and out.
//
// Every call goes through the harness's own code paths, so the module computes what the
// tools compute, bit for bit: load_mesh + prepare_mesh as sdf-query, query_points
// (harness/sampling/point_query.h) as sdf-query, the config's lattice and sampler parsers
// (harness/config/lattice_spec.h, sampler_spec.h) and the sampler table as run-experiment,
// read_field / write_field_file (harness/io) as the tools' files, Reconstruction as sdf-eval,
// render_reconstruction as sdf-render. Work on arrays runs with the GIL released; no Python
// code is called per point. C++ errors arrive as Python exceptions with the tools' messages:
// std::invalid_argument and ConfigError (sample()'s arguments, read by the config parser) as
// ValueError, every other std::exception (a file that cannot be read, a backend this machine
// lacks) as RuntimeError. Under mpirun, sample() is collective over the ranks
// (sample_collectively, harness/distributed/distributed.h; docs/distributed.md).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "core/lattice/lattice_fitting.h"
#include "core/mesh/prepared_mesh.h"
#include "core/raycast/views.h"
#include "core/reconstruction/reconstruction.h"
#include "harness/config/json_reader.h"
#include "harness/config/lattice_spec.h"
#include "harness/config/mesh_spec.h"
#include "harness/config/sampler_spec.h"
#include "harness/distributed/distributed.h"
#include "harness/io/field_file.h"
#include "harness/io/field_output.h"
#include "harness/provenance/version.h"
#include "harness/resources/memory_budget.h"
#include "harness/render/image_buffer.h"
#include "harness/render/render_backend.h"
#include "harness/sampling/point_query.h"
#include "harness/sampling/sampler_table.h"

namespace py = pybind11;

namespace sdf {
namespace {

using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

/// "'a', 'b', 'c'"
std::string quoted_list(const std::vector<std::string>& names) {
    std::string s;
    for (const std::string& n : names) s += (s.empty() ? "'" : ", '") + n + "'";
    return s;
}

/// `value` when it is one of `choices`, else ValueError naming the argument and the choices.
const std::string& choose(const std::string& argument, const std::string& value, const std::vector<std::string>& choices) {
    if (std::find(choices.begin(), choices.end(), value) == choices.end())
        throw std::invalid_argument(argument + ": unknown value '" + value + "'; expected one of " + quoted_list(choices));
    return value;
}

Precision precision_from_name(const std::string& name) {
    return choose("precision", name, {"float", "double"}) == "float" ? Precision::Float : Precision::Double;
}

/// An (N, 3) array of finite doubles as points; ValueError naming `argument` otherwise.
std::vector<Vec3d> points_from_array(const DoubleArray& a, const std::string& argument) {
    if (a.ndim() != 2 || a.shape(1) != 3) {
        std::string shape = "(";
        for (py::ssize_t k = 0; k < a.ndim(); ++k) shape += (k ? ", " : "") + std::to_string(a.shape(k));
        throw std::invalid_argument(argument + ": expected an array of shape (N, 3), got shape " + shape +
                                    (a.ndim() == 1 ? ",)" : ")"));
    }
    const auto v = a.unchecked<2>();
    std::vector<Vec3d> points(size_t(a.shape(0)));
    for (py::ssize_t i = 0; i < a.shape(0); ++i) {
        points[size_t(i)] = {v(i, 0), v(i, 1), v(i, 2)};
        if (!std::isfinite(v(i, 0)) || !std::isfinite(v(i, 1)) || !std::isfinite(v(i, 2)))
            throw std::invalid_argument(argument + ": row " + std::to_string(i) + " is not three finite numbers");
    }
    return points;
}

/// A new C-order array of `shape` filled from `fill(pointer)`.
template <typename T, typename Fill>
py::array_t<T> new_array(const std::vector<py::ssize_t>& shape, Fill fill) {
    py::array_t<T> a(shape);
    fill(a.mutable_data());
    return a;
}

py::array_t<double> vec3_array(const Vec3d* v, size_t n, std::vector<py::ssize_t> shape) {
    shape.push_back(3);
    return new_array<double>(shape, [&](double* out) {
        for (size_t i = 0; i < n; ++i) {
            out[3 * i] = v[i].x;
            out[3 * i + 1] = v[i].y;
            out[3 * i + 2] = v[i].z;
        }
    });
}

/// JSON (provenance, reports) as Python dicts and lists, through the json module.
py::object json_to_python(const nlohmann::json& j) {
    return py::module_::import("json").attr("loads")(j.dump());
}

// ---- Meshes ------------------------------------------------------------------------------

PreparedMesh prepare(const TriangleMesh& mesh, double weld_tolerance, bool check_intersections) {
    MeshPreparationOptions o;
    o.weld_tolerance = weld_tolerance;
    o.detect_intersections = check_intersections;
    if (!(weld_tolerance >= 0)) throw std::invalid_argument("weld_tolerance: expected a distance >= 0");
    py::gil_scoped_release release;
    return prepare_mesh(mesh, o);
}

PreparedMesh load_prepared(const std::string& path, double weld_tolerance, bool check_intersections) {
    TriangleMesh m;
    {
        py::gil_scoped_release release;
        m = load_mesh(mesh_spec_from_argument(path), data_search_path(), ".");
    }
    return prepare(m, weld_tolerance, check_intersections);
}

PreparedMesh mesh_from_arrays(const py::array& vertices_in, const py::array& faces_in, const std::string& name,
                              double weld_tolerance, bool check_intersections) {
    const char kind = faces_in.dtype().kind();
    if (kind != 'i' && kind != 'u')
        throw py::type_error("faces: expected an integer array of shape (M, 3), got dtype " +
                             std::string(py::str(faces_in.dtype())));
    const DoubleArray vertices = DoubleArray::ensure(vertices_in);
    const auto faces = py::array_t<int64_t, py::array::c_style | py::array::forcecast>::ensure(faces_in);
    if (!vertices || !faces) throw py::type_error("vertices and faces must be numeric arrays");
    TriangleMesh m;
    m.name = name;
    m.source = "arrays";
    m.vertices = points_from_array(vertices, "vertices");
    if (faces.ndim() != 2 || faces.shape(1) != 3)
        throw std::invalid_argument("faces: expected an array of shape (M, 3) of vertex indices");
    const auto f = faces.unchecked<2>();
    const int64_t nv = int64_t(m.vertices.size());
    m.triangles.resize(size_t(faces.shape(0)));
    for (py::ssize_t i = 0; i < faces.shape(0); ++i)
        for (int c = 0; c < 3; ++c) {
            if (f(i, c) < 0 || f(i, c) >= nv)
                throw std::invalid_argument("faces[" + std::to_string(i) + ", " + std::to_string(c) + "] = " +
                                            std::to_string(f(i, c)) + " is not a vertex index; expected 0 <= index < " +
                                            std::to_string(nv));
            (&m.triangles[size_t(i)].x)[c] = int(f(i, c));
        }
    m.content_sha256 = geometry_sha256(m);
    return prepare(m, weld_tolerance, check_intersections);
}

// ---- Queries -----------------------------------------------------------------------------

struct QueryResult {
    py::array_t<double> distance, gradient;
    py::array_t<int32_t> triangle;
    std::string sampler;
};

QueryResult query(const PreparedMesh& mesh, const DoubleArray& points_in, const std::string& backend,
                  const std::string& method, const std::string& sign, const std::string& precision,
                  const std::string& kernel, int threads, bool progress) {
    PointQueryOptions o;
    o.backend = choose("backend", backend, point_query_backends());
    o.method = choose("method", method, sampler_methods());
    o.kernel = kernel;
    o.sign = sign_mode_from_name(sign, "sign");
    o.precision = precision_from_name(precision);
    if (threads < 0) throw std::invalid_argument("threads: expected 0 (all cores) or a positive count");
    o.threads = threads;
    o.progress = progress;
    if (backend == "auto" && !kernel.empty())
        throw std::invalid_argument("kernel: needs backend 'cpu' or 'cuda' (auto takes each backend's default kernel)");
    const std::vector<Vec3d> points = points_from_array(points_in, "points");
    PointQueryResult r;
    {
        py::gil_scoped_release release;
        r = query_points(mesh, points, o);
    }
    const size_t n = r.samples.size();
    QueryResult out;
    out.sampler = r.sampler;
    out.distance = new_array<double>({py::ssize_t(n)}, [&](double* d) {
        for (size_t i = 0; i < n; ++i) d[i] = r.samples[i].distance;
    });
    out.gradient = new_array<double>({py::ssize_t(n), 3}, [&](double* g) {
        for (size_t i = 0; i < n; ++i) {
            g[3 * i] = r.samples[i].gradient.x;
            g[3 * i + 1] = r.samples[i].gradient.y;
            g[3 * i + 2] = r.samples[i].gradient.z;
        }
    });
    out.triangle = new_array<int32_t>({py::ssize_t(n)}, [&](int32_t* t) {
        for (size_t i = 0; i < n; ++i) t[i] = r.samples[i].triangle;
    });
    return out;
}

// ---- Fields ------------------------------------------------------------------------------

/// A sampled (or read) field with the reconstruction last asked for, kept for repeated calls.
class Field {
public:
    explicit Field(SampledField field) : field_(std::make_shared<const SampledField>(std::move(field))) {}

    const SampledField& field() const { return *field_; }
    const Lattice& lattice() const { return field_->lattice; }

    /// The CC sub-grids, each {shape (nz, ny, nx), first storage index}: one for CC, the
    /// primary and the secondary grid for BCC.
    struct Grid {
        Int3 resolution;
        int64_t first;
    };
    std::vector<Grid> grids() const {
        std::vector<Grid> g = {{lattice().resolution, 0}};
        if (lattice().type == LatticeType::BCC) g.push_back({lattice().secondary_resolution(), lattice().primary_count()});
        return g;
    }

    /// One array per grid (a tuple for BCC), each [nz, ny, nx] + `inner`.
    template <typename Make>
    py::object per_grid(Make make) const {
        std::vector<py::object> arrays;
        for (const Grid& g : grids()) arrays.push_back(make(g, std::vector<py::ssize_t>{g.resolution.z, g.resolution.y, g.resolution.x}));
        if (arrays.size() == 1) return arrays[0];
        return py::make_tuple(arrays[0], arrays[1]);
    }

    py::object values() const {
        return per_grid([&](const Grid& g, const std::vector<py::ssize_t>& shape) -> py::object {
            const double* src = field_->distance.data() + g.first;
            const int64_t n = int64_t(g.resolution.x) * g.resolution.y * g.resolution.z;
            return new_array<double>(shape, [&](double* out) { std::copy(src, src + n, out); });
        });
    }
    py::object gradient() const {
        if (field_->gradient.empty()) return py::none();
        return per_grid([&](const Grid& g, const std::vector<py::ssize_t>& shape) -> py::object {
            const size_t n = size_t(g.resolution.x) * size_t(g.resolution.y) * size_t(g.resolution.z);
            return vec3_array(field_->gradient.data() + g.first, n, shape);
        });
    }
    py::object triangle() const {
        if (field_->closest_triangle.empty()) return py::none();
        return per_grid([&](const Grid& g, const std::vector<py::ssize_t>& shape) -> py::object {
            const int32_t* src = field_->closest_triangle.data() + g.first;
            const int64_t n = int64_t(g.resolution.x) * g.resolution.y * g.resolution.z;
            return new_array<int32_t>(shape, [&](int32_t* out) { std::copy(src, src + n, out); });
        });
    }
    py::object grid_origins() const {
        std::vector<py::object> origins;
        for (const Grid& g : grids()) {
            const Vec3d o = lattice().position(g.first);
            origins.push_back(py::make_tuple(o.x, o.y, o.z));
        }
        return origins.size() == 1 ? origins[0] : py::make_tuple(origins[0], origins[1]);
    }

    void write(const std::string& path, const std::string& dtype, bool overwrite, bool closest_triangle) const {
        FieldWriteOptions o;
        o.dtype = choose("dtype", dtype, {"float32", "float64"}) == "float32" ? FieldDtype::Float32 : FieldDtype::Float64;
        o.overwrite = overwrite ? Overwrite::Allow : Overwrite::Forbid;
        o.closest_triangle = closest_triangle;
        py::gil_scoped_release release;
        write_field_file(path, *field_, o);
    }

    /// The reconstruction of these names (sdf-eval's defaults for an empty `derivatives`).
    std::shared_ptr<const Reconstruction> reconstruction(const std::string& interpolator_in, const std::string& derivatives,
                                                         double sigma2, const std::string& sigma_units, int threads) {
        const std::string interpolator =
            interpolator_in.empty() ? (lattice().type == LatticeType::BCC ? "bcc_cubic" : "tricubic_lm") : interpolator_in;
        ReconstructionSpec spec;
        spec.interpolator = parse_interpolator(interpolator);
        spec.derivatives = derivatives.empty() ? default_derivative_source(spec.interpolator, !field_->gradient.empty())
                                               : parse_derivative_source(derivatives);
        spec.sigma2 = sigma2;
        spec.sigma_units = choose("sigma_units", sigma_units, {"lattice", "spacing"}) == "lattice" ? SigmaUnits::LatticeUnits
                                                                                                    : SigmaUnits::Spacing;
        if (threads < 0) throw std::invalid_argument("threads: expected 0 (all cores) or a positive count");
        spec.threads = threads;
        const std::string key = describe(spec);
        if (!recon_ || recon_key_ != key) {
            std::shared_ptr<const SampledField> f = field_;
            std::shared_ptr<const Reconstruction> r;
            {
                py::gil_scoped_release release;
                r = std::make_shared<const Reconstruction>(*f, spec);
            }
            recon_ = r;
            recon_key_ = key;
        }
        return recon_;
    }

    py::tuple reconstruct(const DoubleArray& points_in, const std::string& interpolator, const std::string& derivatives,
                          double sigma2, const std::string& sigma_units, int threads) {
        const std::vector<Vec3d> points = points_from_array(points_in, "points");
        const std::shared_ptr<const Reconstruction> r = reconstruction(interpolator, derivatives, sigma2, sigma_units, threads);
        std::vector<ReconstructedSample<double>> samples;
        {
            py::gil_scoped_release release;
            samples = r->evaluate(points, threads);
        }
        const size_t n = samples.size();
        auto values = new_array<double>({py::ssize_t(n)}, [&](double* v) {
            for (size_t i = 0; i < n; ++i) v[i] = samples[i].value;
        });
        auto gradients = new_array<double>({py::ssize_t(n), 3}, [&](double* g) {
            for (size_t i = 0; i < n; ++i) {
                g[3 * i] = samples[i].gradient.x;
                g[3 * i + 1] = samples[i].gradient.y;
                g[3 * i + 2] = samples[i].gradient.z;
            }
        });
        return py::make_tuple(values, gradients);
    }

private:
    std::shared_ptr<const SampledField> field_;
    std::shared_ptr<const Reconstruction> recon_;
    std::string recon_key_;
};

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
        setup = [spec, options, margin, &mesh] {
            SamplingRequest request{build_lattice(spec, mesh.bounds(), margin), options};
            // The memory plan of run-experiment: refused with the figures, before anything is allocated.
            require_host_memory(whole_lattice_sampling_need(request.lattice, mesh.name()), "sample()");
            return request;
        };
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
        try {
            if (collective) {
                field = sample_collectively(mesh, setup);
            } else {
                const SamplingRequest request = setup();
                field = make_sampler(request.options)->sample(mesh, request.lattice);
            }
        } catch (const std::bad_alloc&) {
            throw std::runtime_error(out_of_memory_message("sample() of " + mesh.name() + " on a " + lattice + " lattice", 0));
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

// ---- Rendering ---------------------------------------------------------------------------

py::array_t<float> render(Field& field, const std::string& view, const py::object& size, const std::string& interpolator,
                          const std::string& derivatives, const std::string& backend, const std::string& precision,
                          const py::object& eye, const py::object& target, const std::vector<double>& up, double fov,
                          const PreparedMesh* mesh, int threads, bool progress) {
    int width = 512, height = 512;
    if (py::isinstance<py::int_>(size)) {
        width = height = size.cast<int>();
    } else {
        const auto wh = size.cast<std::vector<int>>();
        if (wh.size() != 2) throw std::invalid_argument("size: expected an int or (width, height)");
        width = wh[0];
        height = wh[1];
    }
    if (width < 1 || height < 1 || width > 16384 || height > 16384)
        throw std::invalid_argument("size: expected 1 to 16384 pixels per side");
    if (!(fov > 0 && fov < 180)) throw std::invalid_argument("fov: expected a field of view between 0 and 180 degrees (exclusive)");
    if (up.size() != 3) throw std::invalid_argument("up: expected 3 numbers");
    ViewRequest v;
    if (!eye.is_none() || !target.is_none()) {
        const auto e = eye.is_none() ? std::vector<double>{} : eye.cast<std::vector<double>>();
        const auto t = target.is_none() ? std::vector<double>{} : target.cast<std::vector<double>>();
        if (e.size() != 3 || t.size() != 3) throw std::invalid_argument("eye and target: both needed, 3 numbers each");
        v.name = "camera";
        v.explicit_camera = true;
        v.eye = {e[0], e[1], e[2]};
        v.target = {t[0], t[1], t[2]};
        v.up = {up[0], up[1], up[2]};
    } else {
        choose("view", view, named_view_names());
        v = named_view(view);
    }
    v.fov_y_degrees = fov;
    const std::shared_ptr<const Reconstruction> recon = field.reconstruction(interpolator, derivatives, 0.5, "lattice", threads);
    RenderOptions o;
    o.backend = choose("backend", backend, {"auto", "cpu", "cuda"});
    o.threads = threads;
    o.progress = progress;
    o.precision = precision_from_name(precision);
    ImageRgb image;
    {
        py::gil_scoped_release release;
        const CameraSpec camera = mesh ? resolve_view(v, mesh->vertices(), width, height)
                                       : resolve_view(v, field_solid_bounds(field.field()), width, height);
        image = shaded_image(render_reconstruction(*recon, camera, o));
    }
    return new_array<float>({height, width, 3}, [&](float* out) { std::copy(image.data.begin(), image.data.end(), out); });
}

std::string mesh_repr(const PreparedMesh& m) {
    const MeshReport& r = m.report();
    return "<sdf_lattices.Mesh '" + m.name() + "': " + std::to_string(m.vertices().size()) + " vertices, " +
           std::to_string(m.triangles().size()) + " triangles, " + std::to_string(r.components) + " component(s), " +
           (r.closed() ? "closed" : "open") + ", " + (r.consistently_oriented() ? "consistently oriented" : "inconsistent orientation") +
           ">";
}

}  // namespace
}  // namespace sdf

PYBIND11_MODULE(sdf_lattices, m) {
    using namespace sdf;
    m.doc() = R"(Exact signed distance fields of triangle meshes on CC and BCC lattices.

Meshes (load_mesh, Mesh), exact queries of arbitrary points (query), sampled fields
(sample, read_field, Field), their reconstruction (Field.reconstruct) and ray-cast images
(render), all with NumPy arrays. The same code as the command-line tools: query() equals
sdf-query, sample() equals a run-experiment field, bit for bit. Signed distance is negative
inside; gradients are unit vectors; triangles are 0-based in the input's face order.
Errors raise ValueError (a bad argument) or RuntimeError (a bad file, a missing backend)
with the tools' messages.)";
    // sample()'s arguments are read by the config parser: its ConfigError is a bad argument here.
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const ConfigError& e) {
            PyErr_SetString(PyExc_ValueError, e.what());
        }
    });
    // Under an MPI launcher every rank imports the module: it starts MPI (unless mpi4py or
    // another library did) and ends it at exit, as run-experiment does in main().
    if (start_collective_distribution() == "sdf_lattices") {
        py::module_::import("atexit").attr("register")(py::cpp_function([] {
            py::gil_scoped_release release;
            finish_collective_distribution();
        }));
        // A rank that ends with an uncaught exception would wait in MPI_Finalize for ranks
        // that wait for it: after the traceback, it ends every rank (as `python3 -m mpi4py`).
        if (distributed_active()) {
            py::module_ sys = py::module_::import("sys");
            const py::object previous = sys.attr("excepthook");
            sys.attr("excepthook") = py::cpp_function([previous](py::object type, py::object value, py::object traceback) {
                previous(type, value, traceback);
                py::module_ sys = py::module_::import("sys");
                for (const char* stream : {"stdout", "stderr"})
                    if (!sys.attr(stream).is_none()) sys.attr(stream).attr("flush")();
                abort_distributed(1);
            });
        }
    }
    m.attr("__version__") = project_version();
    m.attr("build_commit") = build_commit();

    py::class_<PreparedMesh>(m, "Mesh", R"(A triangle mesh prepared for exact signed distance: welded, cleaned
(degenerate triangles dropped), checked (boundary, non-manifold and inconsistent edges,
components, self-intersections), oriented outward where it is closed, with the
angle-weighted pseudonormals of the sign. Immutable.)")
        .def(py::init(&mesh_from_arrays), py::arg("vertices"), py::arg("faces"), py::arg("name") = "mesh",
             py::arg("weld_tolerance") = 0.0, py::arg("check_intersections") = true,
             R"(Mesh(vertices, faces, name="mesh", weld_tolerance=0.0, check_intersections=True)

vertices: (N, 3) array of finite coordinates; faces: (M, 3) integer array of 0-based vertex
indices. weld_tolerance merges vertices closer than it (0: only identical positions);
check_intersections looks for intersecting triangle pairs (costs about a BVH build).)")
        .def_property_readonly("name", &PreparedMesh::name, "Short name (the file name without extensions, or as given).")
        .def_property_readonly("source", &PreparedMesh::source, "File path, shape:NAME, or 'arrays'.")
        .def_property_readonly("sha256", &PreparedMesh::content_sha256, "SHA-256 of the file's bytes or of the geometry.")
        .def_property_readonly("vertices", [](const PreparedMesh& p) {
            return vec3_array(p.vertices().data(), p.vertices().size(), {py::ssize_t(p.vertices().size())});
        }, "(N, 3) float64: the prepared (welded) vertices.")
        .def_property_readonly("faces", [](const PreparedMesh& p) {
            const auto& t = p.triangles();
            return new_array<int32_t>({py::ssize_t(t.size()), 3}, [&](int32_t* out) {
                for (size_t i = 0; i < t.size(); ++i) {
                    out[3 * i] = t[i].x;
                    out[3 * i + 1] = t[i].y;
                    out[3 * i + 2] = t[i].z;
                }
            });
        }, "(M, 3) int32: the prepared triangles (indices into vertices), oriented outward where closed.")
        .def_property_readonly("source_triangle", [](const PreparedMesh& p) {
            const auto& s = p.source_triangle();
            return new_array<int32_t>({py::ssize_t(s.size())}, [&](int32_t* out) { std::copy(s.begin(), s.end(), out); });
        }, "(M,) int32: the input face index of each prepared triangle (the numbering of query()'s .triangle).")
        .def_property_readonly("bounds", [](const PreparedMesh& p) {
            const Bounds3& b = p.bounds();
            return py::make_tuple(py::make_tuple(b.min.x, b.min.y, b.min.z), py::make_tuple(b.max.x, b.max.y, b.max.z));
        }, "((xmin, ymin, zmin), (xmax, ymax, zmax)) of the triangles' vertices.")
        .def_property_readonly("closed", [](const PreparedMesh& p) { return p.report().closed(); },
                               "True when every edge has exactly two triangles (no boundary, no non-manifold edge).")
        .def_property_readonly("consistently_oriented", [](const PreparedMesh& p) { return p.report().consistently_oriented(); },
                               "True when no interior edge is traversed twice in the same direction.")
        .def_property_readonly("orientation", [](const PreparedMesh& p) {
            const MeshReport& r = p.report();
            if (!r.consistently_oriented()) return std::string("inconsistent");
            if (!r.closed()) return std::string("consistent (open: outward undefined)");
            return std::string(r.flipped ? "outward (flipped from inward)" : "outward");
        }, "'outward', 'outward (flipped from inward)', 'consistent (open: outward undefined)' or 'inconsistent'.")
        .def_property_readonly("components", [](const PreparedMesh& p) { return p.report().components; },
                               "Number of edge-connected pieces (shells).")
        .def_property_readonly("sign_reliable", [](const PreparedMesh& p) { return p.report().sign_reliable(); },
                               "True when pseudonormal signs are exact everywhere (closed and consistently oriented).")
        .def_property_readonly("warnings", &PreparedMesh::warnings,
                               "The preparation's warnings (open, non-manifold, inconsistent, flipped, intersecting), as the tools print them.")
        .def_property_readonly("report", [](const PreparedMesh& p) {
            const MeshReport& r = p.report();
            py::dict d;
            d["input_vertices"] = r.input_vertices;
            d["input_triangles"] = r.input_triangles;
            d["welded_vertices"] = r.welded_vertices;
            d["unreferenced_vertices"] = r.unreferenced_vertices;
            d["degenerate_triangles"] = r.degenerate_triangles;
            d["boundary_edges"] = r.boundary_edges;
            d["nonmanifold_edges"] = r.nonmanifold_edges;
            d["inconsistent_edges"] = r.inconsistent_edges;
            d["components"] = r.components;
            d["signed_volume"] = r.signed_volume;
            d["flipped"] = r.flipped;
            d["intersections_checked"] = r.intersections_checked;
            d["self_intersecting_pairs"] = r.self_intersecting_pairs;
            d["shell_intersecting_pairs"] = r.shell_intersecting_pairs;
            d["overlapping_shells"] = r.overlapping_shells;
            d["closed"] = r.closed();
            d["consistently_oriented"] = r.consistently_oriented();
            d["sign_reliable"] = r.sign_reliable();
            return d;
        }, "The whole preparation report as a dict (every count of core/mesh/prepared_mesh.h's MeshReport).")
        .def("__repr__", &mesh_repr);

    m.def("cuda_available", &cuda_backend_available,
          "True when this build has the CUDA backend and a GPU is present (what backend=\"auto\" picks).");

    m.def("load_mesh", &load_prepared, py::arg("path"), py::arg("weld_tolerance") = 0.0,
          py::arg("check_intersections") = true,
          R"(load_mesh(path, weld_tolerance=0.0, check_intersections=True) -> Mesh

Loads and prepares a mesh file as sdf-query does: OBJ, PLY (ASCII and binary), STL (ASCII and
binary), OFF, each optionally gzip-compressed, found in the current directory and then on the
data search path ($SDF_DATA_PATH, data/meshes, ../shared/meshes); or a procedural shape,
"shape:sphere", "shape:box", "shape:torus", "shape:pawn", "shape:soccer_ball".)");

    py::class_<QueryResult>(m, "QueryResult", "Exact results of query(), one row per point, in input order.")
        .def_readonly("distance", &QueryResult::distance, "(N,) float64: signed distance, negative inside.")
        .def_readonly("gradient", &QueryResult::gradient, "(N, 3) float64: the exact unit gradient.")
        .def_readonly("triangle", &QueryResult::triangle, "(N,) int32: the closest triangle, 0-based, in the input's face order.")
        .def_readonly("sampler", &QueryResult::sampler, "The sampler that computed them, e.g. 'cpu/bvh/brick'.")
        .def("__len__", [](const QueryResult& r) { return r.distance.size(); });

    m.def("query", &query, py::arg("mesh"), py::arg("points"), py::arg("backend") = "auto", py::arg("method") = "bvh",
          py::arg("sign") = "auto", py::arg("precision") = "float", py::arg("kernel") = "", py::arg("threads") = 0,
          py::arg("progress") = false,
          R"(query(mesh, points, backend="auto", method="bvh", sign="auto", precision="float", kernel="", threads=0, progress=False) -> QueryResult

Exact signed distance, gradient and closest triangle of points ((N, 3) array), computed as
`sdf-query` computes them (the same function; equal to the last bit for the same options).
backend: "auto" (cuda when a GPU is present, else cpu), "cpu" or "cuda"; method: "bvh" or
"brute_force"; sign: "auto", "pseudonormal" or "winding" (docs/winding.md); precision: the
search's, "float" or "double" (the winner is always evaluated in double). The GIL is
released while computing.)");

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

    m.def("distributed", [] { return json_to_python(distributed_info()); },
          R"(distributed() -> dict

This process's place in an MPI run: mpi (whether the module was built with MPI), started_by
("sdf_lattices" when the module started MPI, "another library" when it found MPI running,
e.g. started by mpi4py, None when there is no MPI), rank, size, host, and under MPI
local_rank, local_size (the ranks on this host), threads (each rank's share of the host's
cores, used for threads=0), gpus_on_host and gpu; on rank 0 of several, processes: every
rank's description. The module starts MPI at import when an MPI launcher's environment is
present (mpirun, mpiexec, srun) and ends it at exit, so every rank must import it.)");

    m.def("read_field", &read_field_file, py::arg("path"),
          R"(read_field(path) -> Field

Reads a field file (NAME.json and its channels, docs/field-format.md): CC or BCC, with or
without gradient and closest-triangle channels.)");

    m.def("render", &render, py::arg("field"), py::arg("view") = "three_quarter", py::arg("size") = 512,
          py::arg("interpolator") = "", py::arg("derivatives") = "", py::arg("backend") = "auto",
          py::arg("precision") = "float", py::arg("eye") = py::none(), py::arg("target") = py::none(),
          py::arg("up") = std::vector<double>{0, 1, 0}, py::arg("fov") = 30.0, py::arg("mesh") = nullptr,
          py::arg("threads") = 0, py::arg("progress") = false,
          R"(render(field, view="three_quarter", size=512, interpolator="", derivatives="", backend="auto", precision="float", eye=None, target=None, up=(0, 1, 0), fov=30, mesh=None, threads=0, progress=False) -> image

Ray-casts the field's reconstruction as sdf-render does and returns the shaded image, float32
of shape (height, width, 3), values in [0, 1], row 0 at the top. view: a named view
(docs/raycast.md), or eye and target (and up) for an explicit camera; size: an int or
(width, height); mesh frames the view by its vertices (else the field's solid is framed).)");
}
