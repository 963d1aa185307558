// Queries: sdf_lattices.SDF, the bound object (harness/sampling/mesh_sdf.h: a mesh with its
// BVH, winding data and device upload, built once and queried many times), query() and
// its QueryResult, and sdf(), the one-liner. query() takes the path of sdf-query
// (point_query.h: a MeshSdf of the options codec's options): the same sampler, bit for bit.
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/parallel/parallel_for.h"
#include "harness/sampling/mesh_sdf.h"
#include "harness/sampling/multi_device_sampler.h"
#include "harness/sampling/sampler_table.h"
#include "python/src/common.h"
#include "python/src/field.h"
#include "python/src/mesh.h"
#include "python/src/task.h"

namespace sdf {
namespace {

using SdfHolder = std::shared_ptr<const MeshSdf>;

/// A query's results. The closest points and barycentric coordinates are computed from the
/// points and triangles on first access (most callers never read them), so the result keeps
/// the SDF and a copy of the points (own_points): the caller may reuse its array before.
/// With dtype float32 the float64 results are rounded to float32 at the end (round_to_float32).
struct QueryResult {
    py::array distance, gradient;  ///< float64, or float32 (dtype="float32")
    py::array_t<int32_t> triangle;
    py::object winding = py::none(), winding_error_bound = py::none();
    std::string sampler, sign;
    std::shared_ptr<const MeshSdf> sdf;
    PointsView points;
    py::object closest_point = py::none(), barycentric = py::none();
    SamplingTimings timings;
    bool float32 = false;

    void compute_closest_points();
};

/// `a` rounded to float32, element by element (the results are computed in double).
py::array round_to_float32(const py::array_t<double>& a) {
    py::array_t<float> out(std::vector<py::ssize_t>(a.shape(), a.shape() + a.ndim()));
    const double* in = a.data();
    float* o = out.mutable_data();
    const int64_t n = int64_t(a.size());
    py::gil_scoped_release release;
    parallel_for(n, int64_t(1) << 16, 0, [&](int64_t b, int64_t e) {
        for (int64_t i = b; i < e; ++i) o[i] = float(in[i]);
    });
    return out;
}

py::array with_dtype(const py::array_t<double>& a, bool float32) { return float32 ? round_to_float32(a) : py::array(a); }

void QueryResult::compute_closest_points() {
    if (!closest_point.is_none()) return;
    const py::ssize_t rows = triangle.size();
    py::array_t<double> point({rows, py::ssize_t(3)}), weights({rows, py::ssize_t(3)});
    {
        double* p = point.mutable_data();
        double* w = weights.mutable_data();
        const int32_t* t = triangle.data();
        py::gil_scoped_release release;
        sdf->closest_points(points.points, t, p, w, sdf->options().threads);
    }
    closest_point = with_dtype(point, float32);
    barycentric = with_dtype(weights, float32);
}

/// The `dtype` argument: "float64" (the default) or "float32" (or NumPy's dtypes of them);
/// true for float32; ValueError otherwise.
bool float32_argument(const py::object& dtype) {
    std::string name;
    try {
        name = py::str(py::module_::import("numpy").attr("dtype")(dtype).attr("name"));
    } catch (py::error_already_set&) {
        name = "";
    }
    if (name != "float32" && name != "float64")
        throw std::invalid_argument("dtype: expected \"float64\" or \"float32\", got " + std::string(py::repr(dtype)));
    return name == "float32";
}

/// Binds `mesh` for the sampler keywords of query()/SDF()/sdf(); the build runs as a task (Ctrl-C).
SdfHolder bind_mesh_sdf(const py::handle& mesh_in, const SamplerKeywords& k) {
    const MeshHolder mesh = mesh_argument(mesh_in);
    TaskOptions task;
    task.total = int64_t(mesh->triangles().size());
    task.label = "building '" + mesh->name() + "'";
    return run_task([&] { return std::make_shared<const MeshSdf>(mesh, k.options, k.unsigned_distance); }, task);
}

/// `view` made independent of the caller's array `caller` (a copy in its dtype, rows of three
/// in a row) where it reads that array in place; one pass over the points, far below a query's cost.
void own_points(PointsView& view, const py::object& caller) {
    if (view.keep.ptr() != caller.ptr()) return;  // already a copy (a conversion of a list or another dtype)
    const HostPoints& in = view.points;
    const py::ssize_t rows = py::ssize_t(in.count);
    py::array copy = in.float32 ? py::array(py::array_t<float>({rows, py::ssize_t(3)}))
                                : py::array(py::array_t<double>({rows, py::ssize_t(3)}));
    if (in.float32) {
        const float* src = static_cast<const float*>(in.xyz);
        float* dst = static_cast<float*>(copy.mutable_data());
        for (int64_t i = 0; i < in.count; ++i)
            for (int k = 0; k < 3; ++k) dst[3 * i + k] = src[i * in.row_stride + k * in.column_stride];
    } else {
        const double* src = static_cast<const double*>(in.xyz);
        double* dst = static_cast<double*>(copy.mutable_data());
        for (int64_t i = 0; i < in.count; ++i)
            for (int k = 0; k < 3; ++k) dst[3 * i + k] = src[i * in.row_stride + k * in.column_stride];
    }
    view.points = HostPoints{copy.data(), in.float32, in.count, 3, 1};
    view.keep = copy;
}

/// The `winding` argument: False/None (none), True or "fast" (the fast evaluation, with its
/// error bound), "exact" (the direct sum); ValueError otherwise.
std::optional<MeshSdf::Winding> winding_argument(const py::object& winding) {
    if (winding.is_none()) return std::nullopt;
    const std::string type = py::str(py::type::of(winding).attr("__name__"));
    if (py::isinstance<py::bool_>(winding) || type == "bool_")  // Python's or NumPy's
        return py::bool_(winding) ? std::optional<MeshSdf::Winding>(MeshSdf::Winding::Fast) : std::nullopt;
    if (py::isinstance<py::str>(winding)) {
        const std::string w = winding.cast<std::string>();
        if (w == "fast") return MeshSdf::Winding::Fast;
        if (w == "exact") return MeshSdf::Winding::Exact;
    }
    throw std::invalid_argument("winding: expected False, True (the same as \"fast\"), \"fast\" or \"exact\", got " +
                                std::string(py::repr(winding)));
}

/// A query's points and float64 columns, before the search (with the GIL).
QueryResult start_query(const SdfHolder& sdf, const py::object& points_in) {
    QueryResult q;
    q.sdf = sdf;
    q.points = points_view(points_in, "points");
    const py::ssize_t rows = py::ssize_t(q.points.points.count);
    q.distance = py::array_t<double>({rows});
    q.gradient = py::array_t<double>({rows, py::ssize_t(3)});
    q.triangle = py::array_t<int32_t>({rows});
    return q;
}

HostQueryResults columns_of(QueryResult& q) {
    return {static_cast<double*>(q.distance.mutable_data()), static_cast<double*>(q.gradient.mutable_data()),
            q.triangle.mutable_data()};
}

/// After the search: the points made the result's own, the names, the dtype.
void finish_query(QueryResult& q, const py::object& points_in, bool float32) {
    own_points(q.points, points_in);
    q.sampler = q.sdf->sampler_name();
    q.sign = q.sdf->sign_mode();
    q.float32 = float32;
    if (float32) {
        q.distance = round_to_float32(q.distance);
        q.gradient = round_to_float32(q.gradient);
    }
}

QueryResult query_bound(const std::shared_ptr<const MeshSdf>& sdf, const py::object& points_in,
                        const py::object& winding_in, const py::object& progress, bool float32 = false) {
    const std::optional<MeshSdf::Winding> winding = winding_argument(winding_in);
    QueryResult q = start_query(sdf, points_in);
    const HostPoints& points = q.points.points;
    const py::ssize_t rows = py::ssize_t(points.count);
    const HostQueryResults columns = columns_of(q);
    TaskOptions task;
    task.total = points.count;
    task.label = "querying '" + sdf->mesh().name() + "'";
    task.progress = progress;
    std::vector<double> winding_bounds;
    std::vector<double> winding_numbers = run_task([&] {
        sdf->query_host(points, columns, &q.timings);
        if (!winding) return std::vector<double>{};
        return sdf->winding_numbers(gather_points(points, "points", sdf->options().threads), sdf->options().threads,
                                    *winding, *winding == MeshSdf::Winding::Fast ? &winding_bounds : nullptr);
    }, task);
    finish_query(q, points_in, float32);
    if (winding)
        q.winding = new_array<double>({rows}, [&](double* w) { std::copy(winding_numbers.begin(), winding_numbers.end(), w); });
    if (!winding_bounds.empty())
        q.winding_error_bound =
            new_array<double>({rows}, [&](double* b) { std::copy(winding_bounds.begin(), winding_bounds.end(), b); });
    return q;
}

/// Many SDFs, each with its points, in one call: every query_host in turn, with the GIL
/// released once (each query already runs on every thread), so that the results are each
/// SDF's own query's, bit for bit.
std::vector<QueryResult> query_batch(const std::vector<SdfHolder>& sdfs, const std::vector<py::object>& points,
                                     const py::object& progress, bool float32) {
    if (sdfs.size() != points.size())
        throw std::invalid_argument("query_batch: expected as many point arrays as SDFs, got " + std::to_string(points.size()) +
                                    " point arrays for " + std::to_string(sdfs.size()) + " SDFs");
    std::vector<QueryResult> results;
    results.reserve(sdfs.size());
    TaskOptions task;
    for (size_t i = 0; i < sdfs.size(); ++i) {
        if (!sdfs[i]) throw py::type_error("query_batch: sdfs[" + std::to_string(i) + "] is None; expected an sdf_lattices.SDF");
        try {
            results.push_back(start_query(sdfs[i], points[i]));
        } catch (const py::type_error& e) {
            throw py::type_error("query_batch: points[" + std::to_string(i) + "]: " + std::string(e.what()));
        } catch (const std::invalid_argument& e) {
            throw std::invalid_argument("query_batch: points[" + std::to_string(i) + "]: " + e.what());
        }
        task.total += results.back().points.points.count;
    }
    task.label = "querying " + std::to_string(sdfs.size()) + " meshes";
    task.progress = progress;
    std::vector<HostQueryResults> columns;
    for (QueryResult& q : results) columns.push_back(columns_of(q));
    run_task([&] {
        for (size_t i = 0; i < results.size(); ++i) results[i].sdf->query_host(results[i].points.points, columns[i], &results[i].timings);
        return 0;
    }, task);
    for (size_t i = 0; i < results.size(); ++i) finish_query(results[i], points[i], float32);
    return results;
}

/// A sequence's items; TypeError naming `argument` for anything else (a single array, a string).
std::vector<py::object> object_list(const py::object& sequence, const std::string& argument) {
    if (!py::isinstance<py::sequence>(sequence) || py::isinstance<py::str>(sequence) || py::isinstance<py::array>(sequence))
        throw py::type_error(argument + ": expected a list or tuple (one item per mesh), got " +
                             std::string(py::str(py::type::of(sequence).attr("__name__"))));
    std::vector<py::object> items;
    for (const py::handle item : py::reinterpret_borrow<py::sequence>(sequence)) items.push_back(py::reinterpret_borrow<py::object>(item));
    return items;
}

/// A sequence of SDF objects; TypeError naming the first item that is not one.
std::vector<SdfHolder> sdf_list(const py::object& sequence) {
    std::vector<SdfHolder> sdfs;
    for (const py::object& item : object_list(sequence, "sdfs")) {
        if (!py::isinstance<MeshSdf>(item))
            throw py::type_error("sdfs[" + std::to_string(sdfs.size()) + "]: expected an sdf_lattices.SDF, got " +
                                 std::string(py::str(py::type::of(item).attr("__name__"))));
        sdfs.push_back(item.cast<std::shared_ptr<MeshSdf>>());
    }
    return sdfs;
}

std::string query_repr(const QueryResult& r) {
    std::ostringstream s;
    s << "<sdf_lattices.QueryResult: " << r.distance.size() << " point" << (r.distance.size() == 1 ? "" : "s")
      << ", sign '" << r.sign << "', sampler '" << r.sampler << "'";
    if (r.distance.size() > 0) {
        const auto range = [&](const auto* d) {
            const auto [lo, hi] = std::minmax_element(d, d + r.distance.size());
            s << ", distance in [" << *lo << ", " << *hi << "]";
        };
        if (r.float32)
            range(static_cast<const float*>(r.distance.data()));
        else
            range(static_cast<const double*>(r.distance.data()));
    }
    s << (r.winding.is_none() ? "" : ", with winding numbers") << ">";
    return s.str();
}

std::string sdf_repr(const MeshSdf& s) {
    std::ostringstream o;
    o << "<sdf_lattices.SDF of mesh '" << s.mesh().name() << "' (" << s.mesh().triangles().size() << " triangles): sampler '"
      << s.sampler_name() << "', sign '" << s.sign_mode() << "', precision " << precision_name(s.options().precision)
      << ", built in " << s.build_seconds() << " s>";
    return o.str();
}

}  // namespace

void bind_query(py::module_& m) {
    py::class_<QueryResult>(m, "QueryResult", "Exact results of a query, one row per point, in input order.")
        .def_readonly("distance", &QueryResult::distance,
                      "(N,) float64 (float32 with dtype=\"float32\"): signed distance, negative inside (sign='none': "
                      "the unsigned distance).")
        .def_readonly("gradient", &QueryResult::gradient,
                      "(N, 3) float64 (float32 with dtype=\"float32\"): the exact unit gradient (sign='none': pointing "
                      "away from the surface).")
        .def_readonly("triangle", &QueryResult::triangle,
                      "(N,) int32: the closest triangle, 0-based, in the caller's face order (the faces given to Mesh, or the file's).")
        .def_property_readonly("closest_point", [](QueryResult& r) { return (r.compute_closest_points(), r.closest_point); },
                               "(N, 3) float64 (float32 with dtype=\"float32\"): the closest point on the mesh (computed on first access, from the query's own copy "
                               "of the points: changing the points array after the query changes nothing).")
        .def_property_readonly("barycentric", [](QueryResult& r) { return (r.compute_closest_points(), r.barycentric); },
                      "(N, 3) float64 (float32 with dtype=\"float32\"): the closest point's weights of the closest face's three vertices, in the "
                      "caller's order: closest_point = sum_k barycentric[:, k] * vertices[faces[triangle, k]], with the caller's "
                      "vertices and faces, or a file's as Mesh.input_vertices and Mesh.input_faces.")
        .def_readonly("winding", &QueryResult::winding,
                      "(N,) float64: the winding number (about 1 inside, 0 outside); None unless asked for. "
                      "winding=True or \"fast\": Barill et al.'s fast evaluation of the generalized winding number "
                      "(beta 2, order 2, the winding sign's), NOT exact: within winding_error_bound of it (a rigorous "
                      "bound of the far-field truncation, rounding aside; measured up to 0.05 off near overlapping "
                      "parts). winding=\"exact\": the generalized winding number itself, the direct sum of every "
                      "triangle's exact solid angle (Van Oosterom & Strackee), O(triangles) per point.")
        .def_readonly("winding_error_bound", &QueryResult::winding_error_bound,
                      "(N,) float64: with the fast winding number, a rigorous bound of its error per point: "
                      "|winding - exact| <= winding_error_bound, rounding aside. None otherwise.")
        .def_readonly("sign", &QueryResult::sign,
                      "The sign mode actually used: 'pseudonormal', 'winding' (sign='auto' resolved for the mesh) or 'none'.")
        .def_readonly("sampler", &QueryResult::sampler, "The sampler that computed them, e.g. 'cpu/bvh/brick'.")
        .def_property_readonly("timings_seconds", [](const QueryResult& r) {
            py::dict d;
            d["total"] = r.timings.total;
            d["kernel"] = r.timings.kernel;
            d["upload"] = r.timings.upload;
            d["download"] = r.timings.download;
            return d;
        }, "The query's timings, seconds: total (the sampler's whole call), and on the GPU kernel (device time of the "
           "sort, search and sign), upload and download (the transfers); 0 where the sampler does not measure them (the CPU's, CUDA brute force).")
        .def_property_readonly("search_certificate", [](const QueryResult& r) {
            py::dict d;
            d["points"] = r.timings.certified_points;
            d["reranked"] = r.timings.reranked_points;
            d["full_double"] = r.timings.full_double_points;
            return d;
        }, "The certified float search's counts (precision 'float', the default; zero for 'double', the reference): "
           "points certified, those re-ranked in double (several candidates within the float error bound, a vertex's "
           "fan of exact ties for most), and those sent to a further search (more candidates than a list holds).")
        .def_property_readonly("devices", [](const QueryResult& r) {
            // plan_device_split depends only on the count, the devices and the threshold, all
            // fixed when the SDF was made: this is the plan the query's sampler followed.
            const SamplerOptions& o = r.sdf->options();
            return json_to_python(plan_device_split(r.points.points.count, -1, sampler_device_count(o), o.min_points_per_device).to_json());
        }, "How the points went over the SDF's devices (SDF(..., devices=...)): {'count': devices requested, 'used', "
           "'split', 'min_points_per_device' (the split threshold), 'why_not' or 'why_fewer'}; a query of fewer than "
           "2 x min_points_per_device points runs on the first device.")
        .def("__len__", [](const QueryResult& r) { return r.distance.size(); })
        .def("__repr__", &query_repr);

    static const std::string sdf_doc = R"(A mesh bound to a sampler: built once, queried many times.

SDF(mesh, **sampler)

Building it prepares everything a query of the mesh needs (its BVH, the winding data when
the sign is the winding number's, the GPU upload), so that query() and sample() only
search: a query of one point costs microseconds. mesh: an sdf_lattices.Mesh, a mesh file
path, (vertices, faces) arrays, an object with vertices and faces arrays (trimesh), or an
Open3D TriangleMesh (legacy or tensor). Results equal query()'s and sample()'s with the
same options, bit for bit. Thread-safe (calls on one object run one at a time).

)" + sampler_keywords_doc();
    py::class_<MeshSdf, std::shared_ptr<MeshSdf>>(m, "SDF", sdf_doc.c_str())
        .def(py::init([](const py::object& mesh, const py::kwargs& sampler) {
                 return std::const_pointer_cast<MeshSdf>(bind_mesh_sdf(mesh, read_sampler_keywords("SDF()", sampler, {"mesh"})));
             }),
             py::arg("mesh"))
        .def("query", [](const std::shared_ptr<MeshSdf>& s, const py::object& points, const py::object& winding,
                         const py::object& progress, const py::object& dtype) {
                 return query_bound(s, points, winding, progress, float32_argument(dtype));
             },
             py::arg("points"), py::arg("winding") = false, py::arg("progress") = py::none(), py::arg("dtype") = "float64",
             R"(query(points, winding=False, progress=None, dtype="float64") -> QueryResult

Distance, gradient, closest triangle, closest point and barycentric coordinates of points
((N, 3) array), and with winding=True (or "fast") the fast winding number with its error
bound, with winding="exact" the exact generalized winding number. progress: True (a
tqdm bar when tqdm is installed, else lines on sys.stderr), or a callable progress(done,
total). Ctrl-C stops a long query within a fraction of a second (KeyboardInterrupt).
dtype="float32" gives distance, gradient, closest point and barycentric coordinates as
float32, half the bytes: they are still computed exactly in double and rounded to float32
at the end (winding numbers stay float64).)")
        .def("refit", [](const std::shared_ptr<MeshSdf>& s, const py::array& new_vertices) {
                 const MeshHolder mesh = refit_mesh(std::const_pointer_cast<PreparedMesh>(s->shared_mesh()), new_vertices);
                 TaskOptions task;
                 task.total = int64_t(mesh->triangles().size());
                 task.label = "refitting '" + mesh->name() + "'";
                 const bool unsigned_distance = s->sign_mode() == "none";
                 return std::const_pointer_cast<MeshSdf>(run_task([&] {
                     return std::make_shared<const MeshSdf>(mesh, s->options(), unsigned_distance);
                 }, task));
             },
             py::arg("new_vertices"),
             R"(refit(new_vertices) -> SDF

The SDF of the same mesh with its vertices moved (a deforming mesh of the same topology):
new_vertices has one row per input vertex (Mesh.input_vertices: the rows the faces index),
the faces stay. The result is a new SDF with this one's sampler options, equal bit for bit
to SDF(Mesh(new_vertices, mesh.input_faces, weld_tolerance=..., check_intersections=...),
same options). What the faces alone decide is kept from the first preparation and not
derived again (the welds, the degenerate triangles dropped, the edge adjacency, boundary,
non-manifold and orientation counts, the shells); what the positions decide is made again
(the signed volume and the outward flip, normals and pseudonormals, bounds, the
self-intersection check and so the sign's choice, the BVH, the winding data and the GPU
upload). ValueError, naming the vertex or triangle, where the new positions would weld or
drop otherwise than the first preparation (two vertices welded or no longer welded, a
triangle newly degenerate or no longer degenerate): build a new SDF then. Triangle numbers
and vertex gradients keep referring to the same input faces.
This SDF is unchanged, and results already returned stay valid.)")
        .def("sample", &sample_bound, py::arg("lattice") = lattice_type_name(LatticeType::CC), py::arg("resolution") = py::none(),
             py::arg("samples") = py::none(), py::arg("margin") = py::none(), py::arg("bounds") = py::none(),
             py::arg("spacing") = py::none(), py::arg("origin") = py::none(), py::arg("progress") = py::none(),
             R"(sample(lattice="cc", resolution=None, samples=None, margin=None, bounds=None, spacing=None, origin=None, progress=None) -> Field

Samples the lattice framed by the arguments (as sdf_lattices.sample, which see) on this
process, with the bound sampler.)")
        .def("_query_device",
             [](const MeshSdf& s, uintptr_t xyz, int64_t count, bool float32, int64_t row, int64_t column, int device,
                uintptr_t stream, uintptr_t distance, uintptr_t gradient, uintptr_t triangle) {
                 DevicePoints points{reinterpret_cast<const void*>(xyz), float32, count, row, column, device,
                                     reinterpret_cast<void*>(stream)};
                 DeviceQueryResults results{reinterpret_cast<double*>(distance), reinterpret_cast<double*>(gradient),
                                            reinterpret_cast<int32_t*>(triangle)};
                 py::gil_scoped_release release;
                 s.query_device(points, results);
             },
             py::arg("xyz"), py::arg("count"), py::arg("float32"), py::arg("row_stride"), py::arg("column_stride"),
             py::arg("device"), py::arg("stream"), py::arg("distance"), py::arg("gradient"), py::arg("triangle"),
             "Device pointers in and out (sdf_lattices._gpu calls it for GPU tensors; not for direct use).")
        .def_property_readonly("backend", [](const MeshSdf& s) { return s.options().backend; },
                               "The bound sampler's backend, 'cpu' or 'cuda'.")
        .def_property_readonly("device", [](const MeshSdf& s) { return s.options().device; }, "The CUDA device ordinal.")
        .def_property_readonly("mesh", [](const MeshSdf& s) { return std::const_pointer_cast<PreparedMesh>(s.shared_mesh()); },
                               "The Mesh it was built for.")
        .def_property_readonly("sampler", &MeshSdf::sampler_name, "The bound sampler, e.g. 'cpu/bvh/brick'.")
        .def_property_readonly("sign", &MeshSdf::sign_mode,
                               "The sign mode used: 'pseudonormal', 'winding' or 'none' ('auto' resolved for the mesh).")
        .def_property_readonly("sign_reason", &MeshSdf::sign_reason, "Why that sign mode (auto's reason).")
        .def_property_readonly("precision", [](const MeshSdf& s) { return precision_name(s.options().precision); },
                               "The search precision, 'float' or 'double'.")
        .def_property_readonly("build_seconds", &MeshSdf::build_seconds,
                               "Wall time of the build (BVH, winding data, upload), seconds.")
        .def("__repr__", &sdf_repr);

    static const std::string query_doc = R"(query(mesh, points, progress=None, winding=False, dtype="float64", **sampler) -> QueryResult

Exact signed distance, gradient, closest triangle, closest point and barycentric
coordinates of points ((N, 3) array), computed as `sdf-query` computes them (the same
sampler; equal to the last bit for the same options). It builds an SDF(mesh, **sampler) for
the call: to query one mesh many times, build the SDF once. mesh: an sdf_lattices.Mesh, a
mesh file path, (vertices, faces) arrays, an object with vertices and faces arrays
(trimesh), or an Open3D TriangleMesh. progress: True or a callable progress(done, total);
winding=True (or "fast") adds the fast winding number and its error bound, winding="exact"
the exact generalized winding number (see QueryResult.winding); dtype="float32" rounds
distance, gradient, closest point and barycentric coordinates to float32 at the end (see
SDF.query). The GIL is released while computing; Ctrl-C stops it.
The search runs in the precision keyword's precision; the winner is always evaluated in
double.

)" + sampler_keywords_doc();
    m.def("query", [](const py::object& mesh, const py::object& points, const py::object& progress, const py::object& winding,
                      const py::object& dtype, const py::kwargs& sampler) {
              const bool float32 = float32_argument(dtype);
              const SdfHolder s = bind_mesh_sdf(
                  mesh, read_sampler_keywords("query()", sampler, {"mesh", "points", "progress", "winding", "dtype"}));
              return query_bound(s, points, winding, progress, float32);
          },
          py::arg("mesh"), py::arg("points"), py::arg("progress") = py::none(), py::arg("winding") = false,
          py::arg("dtype") = "float64", query_doc.c_str());

    static const std::string query_batch_doc = R"(query_batch(sdfs, points, progress=None, dtype="float64") -> list

A batch of meshes in one call: sdfs[i].query(points[i]) for every i, as a list of
QueryResult, equal to those queries bit for bit. One native call with the GIL released
once, the SDFs queried in turn (each query runs on every thread; on the GPU each runs on its
SDF's device). GPU points (PyTorch, CuPy, JAX) give DeviceQueryResults, in one native call
without Python between the meshes. sdfs: a sequence of SDF; points: a sequence of (N_i, 3)
arrays, as many; progress and dtype as in SDF.query.)";
    m.def("query_batch", [](const py::object& sdfs, const py::object& points, const py::object& progress,
                            const py::object& dtype) {
              return query_batch(sdf_list(sdfs), object_list(points, "points"), progress, float32_argument(dtype));
          },
          py::arg("sdfs"), py::arg("points"), py::arg("progress") = py::none(), py::arg("dtype") = "float64",
          query_batch_doc.c_str());
    m.def("_query_device_batch", [](const py::object& sdf_objects, const std::vector<py::tuple>& calls) {
              const std::vector<SdfHolder> sdfs = sdf_list(sdf_objects);
              if (sdfs.size() != calls.size()) throw std::invalid_argument("_query_device_batch: as many calls as SDFs");
              std::vector<std::pair<DevicePoints, DeviceQueryResults>> work;
              for (const py::tuple& c : calls) {
                  if (c.size() != 10) throw std::invalid_argument("_query_device_batch: a call is 10 numbers");
                  const auto address = [&](size_t k) { return reinterpret_cast<void*>(c[k].cast<uintptr_t>()); };
                  work.push_back({DevicePoints{address(0), c[2].cast<bool>(), c[1].cast<int64_t>(), c[3].cast<int64_t>(),
                                               c[4].cast<int64_t>(), c[5].cast<int>(), address(6)},
                                  DeviceQueryResults{static_cast<double*>(address(7)), static_cast<double*>(address(8)),
                                                     static_cast<int32_t*>(address(9))}});
              }
              py::gil_scoped_release release;
              for (size_t i = 0; i < sdfs.size(); ++i)
                  if (work[i].first.count > 0) sdfs[i]->query_device(work[i].first, work[i].second);
          },
          py::arg("sdfs"), py::arg("calls"),
          "Device pointers of many SDFs' queries, run in one call (sdf_lattices._gpu's query_batch; not for direct use): "
          "each call is (xyz, count, float32, row_stride, column_stride, device, stream, distance, gradient, triangle).");

    static const std::string sdf_function_doc = R"(sdf(mesh, points, progress=None, dtype="float64", **sampler) -> numpy.ndarray

The signed distance of points ((N, 3) array) to mesh, (N,) float64: the one-liner
SDF(mesh, **sampler).query(points, progress=progress).distance. mesh: anything SDF takes
(an sdf_lattices.Mesh, a file path, (vertices, faces), trimesh, Open3D). progress: None or
False (silent), True (a bar or lines on stderr), or a callable progress(done, total).
dtype="float32": the distances computed exactly in double, rounded to float32 at the end.

)" + sampler_keywords_doc();
    m.def("sdf", [](const py::object& mesh, const py::object& points, const py::object& progress, const py::object& dtype,
                    const py::kwargs& sampler) {
              const bool float32 = float32_argument(dtype);
              const SdfHolder s =
                  bind_mesh_sdf(mesh, read_sampler_keywords("sdf()", sampler, {"mesh", "points", "progress", "dtype"}));
              return query_bound(s, points, py::bool_(false), progress, float32).distance;
          },
          py::arg("mesh"), py::arg("points"), py::arg("progress") = py::none(), py::arg("dtype") = "float64",
          sdf_function_doc.c_str());
}

}  // namespace sdf
