// Queries: sdf_lattices.query and its QueryResult, the one point-query path of sdf-query
// (harness/sampling/point_query.h).
#include <stdexcept>
#include <string>
#include <vector>

#include "harness/sampling/point_query.h"
#include "harness/sampling/sampler_table.h"
#include "python/src/common.h"

namespace sdf {
namespace {

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

}  // namespace

void bind_query(py::module_& m) {
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

}

}  // namespace sdf
