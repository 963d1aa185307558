// Meshes: sdf_lattices.Mesh (a PreparedMesh: from arrays or from a file, as sdf-query loads
// and prepares it), load_mesh and cuda_available.
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>

#include "core/mesh/load_mesh.h"
#include "core/mesh/prepared_mesh.h"
#include "harness/config/mesh_spec.h"
#include "harness/sampling/sampler_table.h"
#include "python/src/common.h"
#include "python/src/mesh.h"
#include "python/src/task.h"

namespace sdf {
namespace {

/// The preparation's warnings, raised as MeshWarning at the caller's line.
void warn_about(const PreparedMesh& prepared) {
    const std::vector<std::string> warnings = prepared.warnings();
    if (warnings.empty()) return;
    const py::module_ module = py::module_::import("sdf_lattices._warnings");
    const py::object category = module.attr("MeshWarning"), warn = module.attr("warn_at_caller");
    for (const std::string& w : warnings) warn(w, category);
}

/// Prepares `mesh` as sdf-query does, with the GIL released (Ctrl-C stops the intersection
/// check of a large mesh); the preparation's warnings are raised as MeshWarning.
MeshHolder prepare(TriangleMesh mesh, double weld_tolerance, bool check_intersections) {
    MeshPreparationOptions o;
    o.weld_tolerance = weld_tolerance;
    o.detect_intersections = check_intersections;
    o.keep_input = true;     // Mesh.input_vertices and input_faces: the numbering of query results
    o.keep_topology = true;  // SDF.refit
    if (!(weld_tolerance >= 0)) throw std::invalid_argument("weld_tolerance: expected a distance >= 0");
    TaskOptions task;
    task.total = int64_t(mesh.triangles.size());
    task.label = "preparing '" + mesh.name + "'";
    MeshHolder prepared = run_task([&] { return std::make_shared<PreparedMesh>(prepare_mesh(mesh, o)); }, task);
    warn_about(*prepared);
    return prepared;
}

MeshHolder load_prepared(const std::string& path, double weld_tolerance, bool check_intersections) {
    TaskOptions task;
    task.total = kBackgroundItems;  // a file of any size: Ctrl-C stays honoured
    task.label = "loading " + path;
    TriangleMesh m = run_task([&] { return load_mesh(mesh_spec_from_argument(path), data_search_path(), "."); }, task);
    return prepare(std::move(m), weld_tolerance, check_intersections);
}

/// `vertices_in` as finite (N, 3) coordinates; TypeError or ValueError naming `argument`.
std::vector<Vec3d> vertices_argument(const py::array& vertices_in, const std::string& argument) {
    if (std::string("iuf").find(vertices_in.dtype().kind()) == std::string::npos)
        throw py::type_error(argument + ": expected an array of real numbers of shape (N, 3), got dtype " +
                             std::string(py::str(vertices_in.dtype())));
    const DoubleArray vertices = DoubleArray::ensure(vertices_in);
    if (!vertices) throw py::type_error(argument + " must be a numeric array");
    return points_from_array(vertices, argument);
}

MeshHolder mesh_from_arrays(const py::array& vertices_in, const py::array& faces_in, const std::string& name,
                              double weld_tolerance, bool check_intersections) {
    const char kind = faces_in.dtype().kind();
    if (kind != 'i' && kind != 'u')
        throw py::type_error("faces: expected an integer array of shape (M, 3), got dtype " +
                             std::string(py::str(faces_in.dtype())));
    std::vector<Vec3d> vertex_positions = vertices_argument(vertices_in, "vertices");
    const auto faces = py::array_t<int64_t, py::array::c_style | py::array::forcecast>::ensure(faces_in);
    if (!faces) throw py::type_error("faces must be a numeric array");
    TriangleMesh m;
    m.name = name;
    m.source = "arrays";
    m.vertices = std::move(vertex_positions);
    if (faces.ndim() != 2 || faces.shape(1) != 3)
        throw std::invalid_argument("faces: expected an array of shape (M, 3) of vertex indices");
    const int64_t nv = int64_t(m.vertices.size());
    const auto refuse_index = [&](py::ssize_t i, int c, const std::string& value) {
        throw std::invalid_argument("faces[" + std::to_string(i) + ", " + std::to_string(c) + "] = " + value +
                                    " is not a vertex index; expected 0 <= index < " + std::to_string(nv));
    };
    if (kind == 'u' && faces_in.dtype().itemsize() == 8) {  // uint64 beyond int64's range would read negative
        const auto u = py::array_t<uint64_t, py::array::c_style | py::array::forcecast>::ensure(faces_in);
        const auto uf = u.unchecked<2>();
        for (py::ssize_t i = 0; i < u.shape(0); ++i)
            for (int c = 0; c < 3; ++c)
                if (uf(i, c) >= uint64_t(nv)) refuse_index(i, c, std::to_string(uf(i, c)));
    }
    const auto f = faces.unchecked<2>();
    m.triangles.resize(size_t(faces.shape(0)));
    for (py::ssize_t i = 0; i < faces.shape(0); ++i)
        for (int c = 0; c < 3; ++c) {
            if (f(i, c) < 0 || f(i, c) >= nv) refuse_index(i, c, std::to_string(f(i, c)));
            (&m.triangles[size_t(i)].x)[c] = int(f(i, c));
        }
    m.content_sha256 = geometry_sha256(m);
    return prepare(std::move(m), weld_tolerance, check_intersections);
}

std::string mesh_repr(const PreparedMesh& m) {
    const MeshReport& r = m.report();
    return "<sdf_lattices.Mesh '" + m.name() + "': " + std::to_string(m.vertices().size()) + " vertices, " +
           std::to_string(m.triangles().size()) + " triangles, " + std::to_string(r.components) + " component(s), " +
           (r.closed() ? "closed" : "open") + ", " + (r.consistently_oriented() ? "consistently oriented" : "inconsistent orientation") +
           ">";
}

}  // namespace

MeshHolder refit_mesh(const MeshHolder& mesh, const py::array& new_vertices) {
    if (!mesh->refittable()) throw std::invalid_argument("refit: mesh '" + mesh->name() + "' was not prepared by this module");
    const size_t rows = mesh->input_vertices().size();
    TriangleMesh m;
    m.name = mesh->name();
    m.source = "arrays";
    m.vertices = vertices_argument(new_vertices, "new_vertices");
    if (m.vertices.size() != rows)
        throw std::invalid_argument("new_vertices: expected " + std::to_string(rows) +
                                    " rows (one per input vertex: Mesh.input_vertices, the rows the faces index), got " +
                                    std::to_string(m.vertices.size()));
    m.triangles = mesh->input_triangles();
    m.content_sha256 = geometry_sha256(m);
    TaskOptions task;
    task.total = int64_t(m.triangles.size());
    task.label = "refitting '" + m.name + "'";
    // The topology of the first preparation is kept (core/mesh/prepared_mesh.h): ValueError
    // where the new positions would weld or drop otherwise.
    MeshHolder refitted = run_task([&] { return std::make_shared<PreparedMesh>(refit_prepared_mesh(*mesh, m)); }, task);
    warn_about(*refitted);
    return refitted;
}

MeshHolder mesh_argument(const py::handle& mesh) {
    if (py::isinstance<PreparedMesh>(mesh)) return mesh.cast<MeshHolder>();
    return py::module_::import("sdf_lattices._adapters").attr("as_mesh")(mesh).cast<MeshHolder>();
}

void bind_mesh(py::module_& m) {
    py::class_<PreparedMesh, MeshHolder>(m, "Mesh", R"(A triangle mesh prepared for exact signed distance: welded, cleaned
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
        .def_property_readonly("input_vertices", [](const PreparedMesh& p) {
            return vec3_array(p.input_vertices().data(), p.input_vertices().size(), {py::ssize_t(p.input_vertices().size())});
        }, "(N_in, 3) float64: the vertices as given (the arrays, or as read from the file), before welding.")
        .def_property_readonly("input_faces", [](const PreparedMesh& p) {
            const auto& t = p.input_triangles();
            return new_array<int32_t>({py::ssize_t(t.size()), 3}, [&](int32_t* out) {
                for (size_t i = 0; i < t.size(); ++i) {
                    out[3 * i] = t[i].x;
                    out[3 * i + 1] = t[i].y;
                    out[3 * i + 2] = t[i].z;
                }
            });
        }, "(M_in, 3) int32: the triangles as given (a file's polygons triangulated), indices into input_vertices: "
           "the numbering of query()'s .triangle and .barycentric, so that closest_point = sum_k barycentric[:, k] * "
           "input_vertices[input_faces[triangle, k]] (up to rounding; up to weld_tolerance where vertices were welded).")
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
                               "True when pseudonormal signs are exact everywhere, the rule sign='auto' follows: closed, manifold, consistently oriented, one shell, self-intersections checked and none.")
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
            d["slivers_within_rounding"] = r.slivers_within_rounding;
            d["closed"] = r.closed();
            d["consistently_oriented"] = r.consistently_oriented();
            d["sign_reliable"] = r.sign_reliable();
            return d;
        }, "The whole preparation report as a dict (every count of core/mesh/prepared_mesh.h's MeshReport).")
        .def("__repr__", &mesh_repr);

    m.def("cuda_available", &cuda_backend_available,
          "True when this build has the CUDA backend and a GPU is present (what backend=\"auto\" picks).");

    // The formats from their one table (core/mesh/load_mesh.h).
    static const std::string load_mesh_doc = R"(load_mesh(path, weld_tolerance=0.0, check_intersections=True) -> Mesh

Loads and prepares a mesh file as sdf-query does: )" + mesh_formats_supported() + R"(, found in the
current directory and then on the data search path ($SDF_DATA_PATH, data/meshes,
../shared/meshes); or a procedural shape, "shape:sphere", "shape:box", "shape:torus",
"shape:pawn", "shape:soccer_ball".)";
    m.def("load_mesh", &load_prepared, py::arg("path"), py::arg("weld_tolerance") = 0.0,
          py::arg("check_intersections") = true, load_mesh_doc.c_str());
}

}  // namespace sdf
