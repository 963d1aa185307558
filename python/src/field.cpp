// Fields: sdf_lattices.Field, sample (as run-experiment samples a lattice) and read_field.
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "harness/study/field_source.h"
#include "harness/config/json_reader.h"
#include "harness/config/lattice_spec.h"
#include "harness/config/sampler_spec.h"
#include "harness/distributed/distributed.h"
#include "harness/io/field_file.h"
#include "harness/resources/memory_budget.h"
#include "harness/sampling/sampler_table.h"
#include "python/src/common.h"
#include "python/src/field.h"
#include "python/src/mesh.h"
#include "python/src/task.h"

namespace sdf {
namespace {

/// An integer argument given as any Python or NumPy integer (anything with __index__, not
/// bool), else a TypeError or ValueError naming it. The config parser checks its range.
int64_t integer_argument(const py::handle& value, const std::string& what) {
    if (PyBool_Check(value.ptr()) || !PyIndex_Check(value.ptr()))
        throw py::type_error("sample(): " + what + " must be an integer (Python or NumPy), got " +
                             std::string(Py_TYPE(value.ptr())->tp_name) + " " + std::string(py::repr(value)));
    const py::object index = py::reinterpret_steal<py::object>(PyNumber_Index(value.ptr()));
    if (!index) throw py::error_already_set();
    int overflow = 0;
    const long long n = PyLong_AsLongLongAndOverflow(index.ptr(), &overflow);
    if (overflow != 0) throw py::value_error("sample(): " + what + " " + std::string(py::repr(value)) + " is out of range");
    return n;
}

/// A number argument (float, int or NumPy scalar), else a TypeError naming it: not
/// pybind11's "Unable to cast Python instance to C++ type".
double number_argument(const py::object& value, const std::string& what) {
    if (PyBool_Check(value.ptr()) || !PyNumber_Check(value.ptr()) || PyComplex_Check(value.ptr()))
        throw py::type_error(what + ": expected a number, got " + std::string(Py_TYPE(value.ptr())->tp_name) + " " +
                             std::string(py::repr(value)));
    const double v = PyFloat_AsDouble(value.ptr());
    if (v == -1.0 && PyErr_Occurred()) throw py::error_already_set();
    return v;
}

/// The "lattice" object of a config, from sample()'s arguments, parsed by the config's own
/// parser: the same checks and messages as run-experiment's, key path "sample(): lattice".
LatticeSpec lattice_spec_from_arguments(const std::string& type, const py::object& resolution, const py::object& samples,
                                        const py::object& margin, LatticeStorage storage = LatticeStorage::Dense) {
    nlohmann::json j = {{"type", type}};
    if (!resolution.is_none()) {
        std::vector<int64_t> r;
        if (py::isinstance<py::sequence>(resolution) && !py::isinstance<py::str>(resolution)) {  // NumPy arrays too
            for (const py::handle item : resolution) r.push_back(integer_argument(item, "resolution[" + std::to_string(r.size()) + "]"));
        } else {
            const int64_t n = integer_argument(resolution, "resolution");
            const LatticeKind* kind = find_lattice_kind(type);  // unknown: parse_lattice_spec names it
            r = kind && kind->type == LatticeType::BCC ? std::vector<int64_t>{n, n, 2 * n} : std::vector<int64_t>{n, n, n};
        }
        j["resolution"] = r;
    }
    if (!samples.is_none()) j["samples"] = integer_argument(samples, "samples");
    if (!margin.is_none()) j["margin"] = number_argument(margin, "margin");
    JsonReader reader(j, "sample()", "lattice");
    LatticeSpec spec = parse_lattice_spec(reader, storage);
    reader.finish();
    return spec;
}

/// Three finite numbers named `argument`.
Vec3d vec3_argument(const py::object& value, const std::string& argument) {
    std::vector<double> v;
    try {
        v = value.cast<std::vector<double>>();
    } catch (const py::cast_error&) {
        throw py::type_error(argument + ": expected 3 numbers");
    }
    if (v.size() != 3 || !std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2]))
        throw std::invalid_argument(argument + ": expected 3 finite numbers");
    return {v[0], v[1], v[2]};
}

/// ((xmin, ymin, zmin), (xmax, ymax, zmax)) with min < max on every axis.
Bounds3 bounds_argument(const py::object& value) {
    std::vector<py::object> corners;
    try {
        corners = value.cast<std::vector<py::object>>();
    } catch (const py::cast_error&) {
        throw py::type_error("bounds: expected ((xmin, ymin, zmin), (xmax, ymax, zmax))");
    }
    if (corners.size() != 2) throw std::invalid_argument("bounds: expected ((xmin, ymin, zmin), (xmax, ymax, zmax))");
    Bounds3 b;
    b.min = vec3_argument(corners[0], "bounds[0]");
    b.max = vec3_argument(corners[1], "bounds[1]");
    if (!(b.min.x < b.max.x && b.min.y < b.max.y && b.min.z < b.max.z))
        throw std::invalid_argument("bounds: expected min < max on every axis");
    return b;
}

/// The lattice of `type` with origin bounds.min and `spacing` whose points cover `bounds`:
/// ceil(extent / h) + 1 points per axis (the primary grid for BCC).
Lattice lattice_covering(LatticeType type, const Bounds3& bounds, double spacing, LatticeStorage storage) {
    Lattice l;
    l.type = type;
    l.origin = bounds.min;
    l.spacing = spacing;
    const Vec3d extent = bounds.max - bounds.min;
    const double cells[3] = {extent.x / spacing, extent.y / spacing, extent.z / spacing};
    int n[3];
    for (int k = 0; k < 3; ++k) {
        // 1e-9: an extent that is a whole number of spacings up to rounding gets no extra point.
        const double points = std::ceil(cells[k] * (1 - 1e-9)) + 1;
        if (!(points <= double(1 << 30)))
            throw std::invalid_argument("spacing: " + number_text(spacing) + " gives more than 2^30 points along an axis");
        n[k] = std::max(2, int(points));
    }
    l.resolution = {n[0], n[1], n[2]};
    checked_lattice_points(type, l.resolution, storage);
    return l;
}

}  // namespace

Lattice frame_lattice(const LatticeArguments& a, const Bounds3& mesh_bounds) {
    const LatticeType type = lattice_type_named(choose("lattice", a.type, lattice_type_names()));
    const bool framed = !a.bounds.is_none() || !a.spacing.is_none() || !a.origin.is_none();
    const double margin = a.margin.is_none() ? 0.1 : number_argument(a.margin, "margin");
    if (!(margin >= 0 && std::isfinite(margin)))
        throw std::invalid_argument("margin: expected a finite, non-negative fraction of the mesh's largest extent, got " +
                                    number_text(margin));
    const double spacing = a.spacing.is_none() ? 0.0 : number_argument(a.spacing, "spacing");
    if (!framed)
        return build_lattice(lattice_spec_from_arguments(a.type, a.resolution, a.samples, py::none(), a.storage), mesh_bounds,
                             margin, a.storage);
    // A lattice framed by the caller: bounds and spacing or resolution, or origin, spacing
    // and resolution; spacing alone covers the mesh's box grown by the margin.
    if (!a.samples.is_none()) throw std::invalid_argument("samples: not with bounds, spacing or origin (give resolution or spacing)");
    if (!a.bounds.is_none() && !a.margin.is_none())
        throw std::invalid_argument("margin: not with bounds (bounds frame the lattice as given)");
    if (!a.spacing.is_none() && !(spacing >= std::numeric_limits<double>::min() && std::isfinite(spacing)))
        throw std::invalid_argument("spacing: expected a finite distance > 0 (and not subnormal), got " + number_text(spacing));
    Int3 resolution{};
    if (!a.resolution.is_none())
        resolution = lattice_spec_from_arguments(a.type, a.resolution, py::none(), py::none(), a.storage).resolution;
    if (!a.origin.is_none()) {
        if (!a.bounds.is_none()) throw std::invalid_argument("origin: not with bounds (the origin is bounds[0])");
        if (a.spacing.is_none() || a.resolution.is_none())
            throw std::invalid_argument("origin: needs spacing and resolution as well");
        Lattice l;
        l.type = type;
        l.origin = vec3_argument(a.origin, "origin");
        l.spacing = spacing;
        l.resolution = resolution;
        checked_lattice_points(type, resolution, a.storage);
        return l;
    }
    Bounds3 box;
    if (!a.bounds.is_none()) {
        box = bounds_argument(a.bounds);
    } else {
        const Vec3d e = mesh_bounds.max - mesh_bounds.min;
        const double grow = margin * std::max({e.x, e.y, e.z});
        box.min = mesh_bounds.min - Vec3d(grow);
        box.max = mesh_bounds.max + Vec3d(grow);
    }
    if (a.spacing.is_none() == a.resolution.is_none())
        throw std::invalid_argument("bounds: give exactly one of spacing and resolution");
    if (!a.spacing.is_none()) return lattice_covering(type, box, spacing, a.storage);
    if (resolution.x < 2 || resolution.y < 2 || resolution.z < 2)
        throw std::invalid_argument("resolution: expected at least 2 points per axis with bounds");
    // The widest axis decides the (isotropic) spacing; the lattice starts at bounds[0].
    const Vec3d e = box.max - box.min;
    const double h = std::max({e.x / (resolution.x - 1), e.y / (resolution.y - 1), e.z / (resolution.z - 1)});
    Lattice l;
    l.type = type;
    l.origin = box.min;
    l.spacing = h;
    l.resolution = resolution;
    return l;
}

Field field_for_mesh(SampledField field, const PreparedMesh& mesh) {
    field.mesh = describe_prepared_mesh(mesh);
    return Field(std::move(field));
}

/// sample(), with a std::bad_alloc turned into a message naming the mesh, the lattice and the
/// bytes it needed.
template <typename Work>
SampledField sample_reporting_memory(const std::string& mesh, const Lattice& lattice, Work work) {
    try {
        return work();
    } catch (const std::bad_alloc&) {
        throw std::runtime_error(out_of_memory_message("sample() of " + mesh + " on " + lattice_notation(lattice),
                                                       whole_lattice_sampling_need(lattice, mesh).host_bytes));
    }
}

Field sample_bound(const MeshSdf& sdf, const std::string& lattice, const py::object& resolution, const py::object& samples,
                   const py::object& margin, const py::object& bounds, const py::object& spacing, const py::object& origin,
                   const py::object& progress) {
    const Lattice l = frame_lattice({lattice, resolution, samples, margin, bounds, spacing, origin}, sdf.mesh().bounds());
    // The memory plan of run-experiment: refused with the figures, before anything is allocated.
    require_host_memory(whole_lattice_sampling_need(l, sdf.mesh().name()), "SDF.sample()");
    TaskOptions task;
    task.total = l.num_points();
    task.label = "sampling '" + sdf.mesh().name() + "'";
    task.progress = progress;
    SampledField field = sample_reporting_memory(sdf.mesh().name(), l, [&] { return run_task([&] { return sdf.sample(l); }, task); });
    return field_for_mesh(std::move(field), sdf.mesh());
}

py::tuple Field::reconstruct(const py::object& points_in, const std::string& interpolator, const std::string& derivatives,
                             double sigma2, const std::string& sigma_units, int threads, const std::string& outside) {
    choose("outside", outside, {"nan", "clamp", "error"});
    const DoubleArray array = points_argument(points_in);  // bad points are named before anything is built
    const std::shared_ptr<const Reconstruction> r = reconstruction(interpolator, derivatives, sigma2, sigma_units, threads);
    const auto [points, samples] = reconstruct_points(array, [&](const std::vector<Vec3d>& p) { return r->evaluate(p, threads); });
    return reconstruction_arrays(points, samples, r->domain(), outside);
}

py::object Field::points() const {
    return per_grid([&](const Grid& g, const std::vector<py::ssize_t>& shape) -> py::object {
        const int64_t n = int64_t(g.resolution.x) * g.resolution.y * g.resolution.z;
        std::vector<py::ssize_t> vec3_shape = shape;
        vec3_shape.push_back(3);
        // Written straight into the array: no second host buffer of n points to fill and copy.
        return new_array<double>(vec3_shape, [&](double* out) {
            for (int64_t i = 0; i < n; ++i) {
                const Vec3d p = lattice().position(g.first + i);
                out[3 * i] = p.x, out[3 * i + 1] = p.y, out[3 * i + 2] = p.z;
            }
        });
    });
}

namespace {

/// "float64 array" or the Python type, for messages.
std::string dtype_text(const py::object& o) {
    if (py::isinstance<py::array>(o)) return "an array of dtype " + std::string(py::str(py::array(o).dtype()));
    return std::string(Py_TYPE(o.ptr())->tp_name);
}

/// Refuses arrays of strings, objects, complex numbers or booleans, which NumPy would
/// otherwise convert (or truncate) to numbers without a word.
void require_real_dtype(const py::object& o, const std::string& name) {
    const py::array a = py::array::ensure(o);
    if (!a) throw py::type_error(name + ": expected a numeric array, got " + dtype_text(o));
    if (std::string("iuf").find(a.dtype().kind()) == std::string::npos)
        throw py::type_error(name + ": expected an array of real numbers (integer or float dtype), got " +
                             (py::isinstance<py::array>(o) ? dtype_text(o) : "values of dtype " + std::string(py::str(a.dtype()))));
}

/// A Field from arrays: values (and optionally gradient and triangle) per grid, as Field's
/// arrays are shaped, on the lattice of origin and spacing.
Field field_from_arrays(const py::object& values, const py::object& origin, double spacing, const std::string& lattice,
                        const py::object& gradient, const py::object& triangle) {
    const bool bcc = lattice_type_named(choose("lattice", lattice, lattice_type_names())) == LatticeType::BCC;
    if (!(spacing >= std::numeric_limits<double>::min() && std::isfinite(spacing)))
        throw std::invalid_argument("spacing: expected a finite distance > 0 (and not subnormal), got " + number_text(spacing));
    // Every channel as a list of C-order arrays, one per grid.
    const auto grids_of = [&](const py::object& channel, const std::string& name) {
        std::vector<py::object> out;
        if (bcc) {
            if (!py::isinstance<py::tuple>(channel) && !py::isinstance<py::list>(channel))
                throw py::type_error(name + ": a BCC field takes (primary, secondary) arrays");
            for (const py::handle h : channel) out.push_back(py::reinterpret_borrow<py::object>(h));
            if (out.size() != 2) throw std::invalid_argument(name + ": a BCC field takes (primary, secondary) arrays");
        } else {
            out.push_back(channel);
        }
        return out;
    };
    const std::vector<py::object> v = grids_of(values, "values");
    for (const py::object& o : v) require_real_dtype(o, "values");
    std::vector<DoubleArray> va;
    for (const py::object& o : v) va.push_back(DoubleArray::ensure(o));
    for (size_t k = 0; k < va.size(); ++k)
        if (!va[k] || va[k].ndim() != 3)
            throw std::invalid_argument("values: expected 3-D arrays of shape (nz, ny, nx)" + std::string(bcc ? " per grid" : ""));
    SampledField f;
    f.lattice.type = bcc ? LatticeType::BCC : LatticeType::CC;
    f.lattice.spacing = spacing;
    f.lattice.resolution = {int(va[0].shape(2)), int(va[0].shape(1)), int(va[0].shape(0))};
    checked_lattice_points(f.lattice.type, f.lattice.resolution);
    if (bcc) {
        const Int3 s = f.lattice.secondary_resolution();
        if (va[1].shape(0) != s.z || va[1].shape(1) != s.y || va[1].shape(2) != s.x)
            throw std::invalid_argument("values: the secondary grid must have shape (nz-1, ny-1, nx-1) of the primary's (nz, ny, nx)");
    }
    f.lattice.origin = vec3_argument(origin, "origin");
    for (const Vec3d& corner : {f.lattice.domain_min(), f.lattice.domain_max()})
        if (!std::isfinite(corner.x) || !std::isfinite(corner.y) || !std::isfinite(corner.z))
            throw std::invalid_argument("origin, spacing: the lattice's far corner (origin + spacing x (resolution - 1)) "
                                        "is not finite");
    const size_t points = size_t(f.lattice.num_points());
    f.distance.reserve(points);
    for (const DoubleArray& a : va) f.distance.insert(f.distance.end(), a.data(), a.data() + a.size());
    if (!gradient.is_none()) {
        const std::vector<py::object> g = grids_of(gradient, "gradient");
        f.gradient.reserve(points);
        for (size_t k = 0; k < g.size(); ++k) {
            require_real_dtype(g[k], "gradient");
            const DoubleArray a = DoubleArray::ensure(g[k]);
            if (!a || a.ndim() != 4 || a.shape(3) != 3 || a.shape(0) != va[k].shape(0) || a.shape(1) != va[k].shape(1) ||
                a.shape(2) != va[k].shape(2))
                throw std::invalid_argument("gradient: expected the values' shape + (3,)");
            const size_t first = f.gradient.size(), n = size_t(a.size() / 3);
            f.gradient.resize(first + n);
            for (size_t i = 0; i < n; ++i) f.gradient[first + i] = {a.data()[3 * i], a.data()[3 * i + 1], a.data()[3 * i + 2]};
        }
    }
    if (!triangle.is_none()) {
        const std::vector<py::object> t = grids_of(triangle, "triangle");
        f.closest_triangle.reserve(points);
        for (size_t k = 0; k < t.size(); ++k) {
            if (!py::isinstance<py::array>(t[k]) || std::string("iu").find(py::array(t[k]).dtype().kind()) == std::string::npos)
                throw py::type_error("triangle: expected integer arrays (0-based triangle indices, -2 outside a narrow band), got " +
                                     dtype_text(t[k]));
            const auto a = py::array_t<int32_t, py::array::c_style | py::array::forcecast>::ensure(t[k]);
            if (!a || a.ndim() != 3 || a.shape(0) != va[k].shape(0) || a.shape(1) != va[k].shape(1) || a.shape(2) != va[k].shape(2))
                throw std::invalid_argument("triangle: expected integer arrays of the values' shape");
            for (py::ssize_t i = 0; i < a.size(); ++i)
                if (a.data()[i] < -2)
                    throw std::invalid_argument("triangle: entry " + std::to_string(i) + " is " + std::to_string(a.data()[i]) +
                                                "; expected a triangle index >= 0, or -2 (outside a narrow band)");
            f.closest_triangle.insert(f.closest_triangle.end(), a.data(), a.data() + a.size());
        }
    }
    f.precision = Precision::Double;
    f.sampler.details = {{"source", "arrays"}};
    return Field(std::move(f));
}

/// sign="none": |d| and gradients pointing away from the surface (the field was sampled with
/// the pseudonormal sign, whose magnitudes are every mode's), the sign recorded as asked.
void make_field_unsigned(SampledField& field) {
    make_unsigned(field);
    field.sampler.details["sign"] = {{"requested", "none"}, {"mode", "none"}, {"reason", "unsigned distance requested"}};
}

/// sample()'s own arguments; every other keyword is the sampler's (read_sampler_keywords).
const std::vector<std::string> kSampleArguments = {"mesh",    "lattice", "resolution", "samples",  "margin", "bounds",
                                                   "spacing", "origin",  "progress",   "distributed"};

Field sample(const py::object& mesh_in, const std::string& lattice, const py::object& resolution, const py::object& samples,
             const py::object& margin, const py::object& bounds, const py::object& spacing, const py::object& origin,
             const py::object& progress, bool distributed, const py::kwargs& sampler) {
    const MeshHolder mesh = mesh_argument(mesh_in);
    const bool collective = distributed && distributed_active();
    bool unsigned_distance = false;
    // Under MPI a bad argument is this rank's failure in the collective exchange, raised on
    // every rank there (no rank waits for one that gave up); alone, it is raised here.
    std::function<SamplingRequest()> setup;
    try {
        const Lattice l = frame_lattice({lattice, resolution, samples, margin, bounds, spacing, origin}, mesh->bounds());
        const SamplerKeywords k = read_sampler_keywords("sample()", sampler, kSampleArguments);
        const SamplerOptions options = k.options;
        unsigned_distance = k.unsigned_distance;
        setup = [l, options, name = mesh->name()] {
            // The memory plan of run-experiment: refused with the figures, before anything is allocated.
            require_host_memory(whole_lattice_sampling_need(l, name), "sample()");
            return SamplingRequest{l, options};
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
    if (!collective) {
        const SamplingRequest request = setup();
        TaskOptions task;
        task.total = request.lattice.num_points();
        task.label = "sampling '" + mesh->name() + "'";
        task.progress = progress;
        // The front ends' one field path (harness/study/field_source.h): no cache, this
        // process's sampler; an allocation that fails names the mesh, the lattice and the bytes.
        FieldSource source(nullptr, request.options, "sample()", SamplerReach::ThisProcess);
        std::ostream no_log(nullptr);
        SampledField field = run_task([&] {
            return source.get(mesh, request.lattice, "sample() of '" + mesh->name() + "'", no_log).field;
        }, task);
        if (unsigned_distance) make_field_unsigned(field);
        return field_for_mesh(std::move(field), *mesh);
    }
    TaskOptions task;
    task.background = false;  // MPI stays on the thread that started it
    SampledField field = run_task([&] { return sample_collectively(mesh, setup); }, task);
    if (unsigned_distance) make_field_unsigned(field);
    return field_for_mesh(std::move(field), *mesh);
}

Field read_field_file(const std::string& path) {
    TaskOptions task;
    task.total = kBackgroundItems;
    task.label = "reading " + path;
    return run_task([&] { return Field(read_field(path)); }, task);
}

}  // namespace

void bind_field(py::module_& m) {
    // "'cc' or 'bcc': ...", from the lattice table.
    static const std::string lattice_doc = [] {
        std::string names;
        const std::vector<std::string> all = lattice_type_names();
        for (size_t i = 0; i < all.size(); ++i)
            names += (i == 0 ? "" : i + 1 == all.size() ? " or " : ", ") + ("'" + all[i] + "'");
        return names + ": the lattice kind's name (lattice_kinds()).";
    }();
    py::class_<Field>(m, "Field", R"(A sampled field on a CC or BCC lattice: signed distance, exact gradient and
closest triangle at every lattice point, with the lattice and provenance. values, gradient
and triangle are read-only views of the field's memory (no copy; each keeps the field alive;
.copy() gives a writable array), in z, y, x order: CC values have shape (nz, ny, nx); a BCC
field (thesis notation Rx x Ry x 2Rz) is its two CC sub-grids, a tuple (primary
(Rz, Ry, Rx), secondary (Rz-1, Ry-1, Rx-1)), the secondary grid's origin h/2 further along
every axis.

Field(values, origin, spacing, lattice="cc", gradient=None, triangle=None) makes a field of
your own arrays, shaped as above (BCC: (primary, secondary) tuples), on the lattice of
origin (the first primary point) and spacing h: it reconstructs, renders and writes as a
sampled one.)")
        .def(py::init(&field_from_arrays), py::arg("values"), py::arg("origin"), py::arg("spacing"), py::arg("lattice") = lattice_type_name(LatticeType::CC),
             py::arg("gradient") = py::none(), py::arg("triangle") = py::none())
        .def("points", &Field::points,
             "points() -> array or (primary, secondary): the world position of every lattice point, shape (nz, ny, nx, 3) per grid.")
        .def_property_readonly("lattice", [](const Field& f) { return lattice_type_name(f.lattice().type); },
                               lattice_doc.c_str())
        .def_property_readonly("origin", [](const Field& f) {
            const Vec3d o = f.lattice().origin;
            return py::make_tuple(o.x, o.y, o.z);
        }, "World position (x, y, z) of the first (primary) lattice point, values[0, 0, 0].")
        .def_property_readonly("spacing", [](const Field& f) { return f.lattice().spacing; },
                               "h: the distance between neighbouring primary points along an axis.")
        .def_property_readonly("resolution", [](const Field& f) {
            const Int3 r = f.lattice().resolution;
            const int nz = f.lattice().type == LatticeType::BCC ? 2 * r.z : r.z;
            return py::make_tuple(r.x, r.y, nz);
        }, "(nx, ny, nz) for CC; (Rx, Ry, 2Rz), the thesis's notation, for BCC: x first, while the arrays "
           "(values, gradient, triangle) are indexed [z, y, x], shape (nz, ny, nx).")
        .def_property_readonly("notation", [](const Field& f) { return lattice_notation(f.lattice()); },
                               "'32x32x32' or, BCC, '26x26x52'.")
        .def_property_readonly("num_points", [](const Field& f) { return f.lattice().num_points(); }, "Lattice points in all.")
        .def_property_readonly("grid_origins", &Field::grid_origins,
                               "The origin of each CC sub-grid: one tuple (CC), or (primary, secondary) (BCC).")
        .def_property_readonly("lattice_info", [](const Field& f) { return json_to_python(lattice_to_json(f.lattice())); },
                               "The lattice as a field file's header stores it (dict).")
        .def_property_readonly("values", &Field::values,
                               "Signed distance (or the stored scalar), float64, read-only views as described above, indexed "
                               "[z, y, x]: values[k, j, i] is the point origin + spacing * (i, j, k), while origin and "
                               "resolution are (x, y, z).")
        .def_property_readonly("gradient", &Field::gradient, "Gradient, float64, shape (..., 3) per sub-grid (read-only views); None when absent.")
        .def_property_readonly("triangle", &Field::triangle, "Closest triangle per point, int32 (read-only views); None when absent.")
        .def_property_readonly("precision", [](const Field& f) { return precision_name(f.field().precision); },
                               "The search precision it was sampled with.")
        .def_property_readonly("sampler", [](const Field& f) { return json_to_python(nlohmann::json(f.field().sampler)); },
                               "How it was sampled (backend, method, kernel, threads, sign, ...), as recorded in field files.")
        .def_property_readonly("mesh", [](const Field& f) { return json_to_python(nlohmann::json(f.field().mesh)); }, "The mesh it was sampled from (dict).")
        .def_property_readonly("seconds", [](const Field& f) { return f.field().timings.total; }, "Sampling wall time, seconds.")
        .def("write", &Field::write, py::arg("path"), py::arg("dtype") = "float32", py::arg("overwrite") = false,
             py::arg("closest_triangle") = true,
             R"(write(path, dtype="float32", overwrite=False, closest_triangle=True)

Writes the field in the format of path's extension: ".json" is the project's field file
(header plus raw channels, docs/field-format.md; read by sdf-eval, sdf-render and read_field).
Files are written atomically; an existing file is kept unless overwrite=True. Under mpirun
every rank holds the field: write it from one rank (if sl.distributed()["rank"] == 0).)")
        .def("reconstruct", &Field::reconstruct, py::arg("points"), py::arg("interpolator") = "", py::arg("derivatives") = "",
             py::arg("sigma2") = 0.5, py::arg("sigma_units") = "lattice", py::arg("threads") = 0, py::arg("outside") = "nan",
             R"(reconstruct(points, interpolator="", derivatives="", sigma2=0.5, sigma_units="lattice", threads=0, outside="nan") -> (values, gradients)

The reconstruction at points ((N, 3) array), as sdf-eval computes it: values (N,) and world
gradients (N, 3). interpolator: a name of docs/reconstruction.md (default bcc_cubic for BCC,
tricubic_lm for CC); derivatives: "true", "fd" or "fd_weighted" (default: "true" where the
interpolator uses derivatives and the field has gradients, else "fd"). outside: what points
outside the lattice's domain get: "nan" (the default: NaN value and gradient), "clamp" (the
reconstruction at the nearest point of the domain, as sdf-eval gives) or "error"
(ValueError naming the first such point). The last reconstruction is kept for the next call.)")
        .def("__repr__", [](const Field& f) {
            return "<sdf_lattices.Field " + std::string(lattice_type_name(f.lattice().type)) + " " +
                   lattice_notation(f.lattice()) + ", " + std::to_string(f.lattice().num_points()) + " points>";
        });

    static const std::string sample_doc = R"(sample(mesh, lattice="cc", resolution=None, samples=None, margin=None, bounds=None, spacing=None, origin=None, progress=None, distributed=True, **sampler) -> Field

Samples the exact signed distance on a CC or BCC lattice. Fitted around the mesh, as
run-experiment does (its config parser checks these arguments, as the keys "lattice" and
"sampler"): give resolution or samples; resolution is (nx, ny, nz) for CC, (Rx, Ry, 2Rz)
for BCC, or one int n for (n, n, n) / (n, n, 2n); samples is a target point count for a
cubic lattice; margin (default 0.1): the fraction of the mesh's largest extent added on
every side (run-experiment's "domain": {"margin"}), the lattice centred on the grown box.
Framed by you: bounds=((xmin, ymin, zmin), (xmax, ymax, zmax)) with spacing=h (the first
point at bounds[0], enough points per axis to reach bounds[1]) or with resolution (the
widest axis decides h, the first point at bounds[0]); spacing alone frames the mesh's box
grown by margin; origin, spacing and resolution give the lattice exactly. BCC's spacing is
its primary grid's. mesh: anything SDF takes.
progress: True (tqdm when installed, else lines on sys.stderr) or a callable progress(done,
total). The GIL is released while sampling; Ctrl-C stops it within a fraction of a second.

Under `mpirun -np N python3 script.py` (see distributed()), sample() is collective: every rank
must call it with the same mesh and arguments. Rank 0 cuts the lattice into one slab of
z-planes per rank, balanced as run-experiment's are, every rank samples its slab, and every
rank returns the whole field, bit for bit the one a single process samples; its
sampler["distributed"] records the slabs, hosts and per-rank seconds. A failure on any rank
(or arguments that differ from rank 0's) raises on every rank. distributed=False samples on
this rank alone (no other rank takes part).)" "\n\n" + sampler_keywords_doc();
    m.def("sample", &sample, py::arg("mesh"), py::arg("lattice") = lattice_type_name(LatticeType::CC), py::arg("resolution") = py::none(),
          py::arg("samples") = py::none(), py::arg("margin") = py::none(), py::arg("bounds") = py::none(),
          py::arg("spacing") = py::none(), py::arg("origin") = py::none(), py::arg("progress") = py::none(),
          py::arg("distributed") = true, sample_doc.c_str());

    m.def("read_field_file", &read_field_file, py::arg("path"),
          R"(read_field_file(path) -> Field

Reads a field file (NAME.json and its channels, docs/field-format.md): CC or BCC, with or
without gradient and closest-triangle channels. sdf_lattices.read_field reads every format
Field.write writes.)");

}

}  // namespace sdf
