/// @file common.h
/// @brief What every binding file of the module's extension (sdf_lattices._core) shares:
/// checked argument names, NumPy arrays in and out, JSON as Python objects.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/sampling/host_query.h"
#include "core/sampling/sampled_field.h"
#include "core/sampling/sampler_options.h"

namespace sdf {
namespace py = pybind11;

using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

/// The shortest text that reads back as `v`, for messages (std::to_string writes 1e-300 as
/// 0.000000).
std::string number_text(double v);

/// `value` when it is one of `choices`, else ValueError naming the argument and the choices
/// (as the config reader words it: core/quoted_alternatives.h).
const std::string& choose(const std::string& argument, const std::string& value, const std::vector<std::string>& choices);

/// `value` as a float64 array (NumPy arrays of any numeric dtype, nested sequences);
/// TypeError naming the argument "points" and the type otherwise.
DoubleArray points_argument(const py::object& value);

/// Raises MemoryError with `message` (which says what ran out of memory, and how much).
[[noreturn]] void raise_memory_error(const std::string& message);

/// An (N, 3) array of finite doubles as points; ValueError naming `argument` otherwise.
std::vector<Vec3d> points_from_array(const DoubleArray& a, const std::string& argument);

/// Points as a host query reads them (core/sampling/host_query.h): an (N, 3) float32 or
/// float64 array where it is, with its strides (no copy); any other numeric array or
/// sequence as a float64 copy, which `keep` holds, as it holds the caller's array. TypeError
/// or ValueError naming `argument` for anything else (shape, dtype).
struct PointsView {
    py::array keep;
    HostPoints points;
};
PointsView points_view(const py::object& value, const std::string& argument);

/// A new C-order array of `shape` filled from `fill(pointer)`.
template <typename T, typename Fill>
py::array_t<T> new_array(const std::vector<py::ssize_t>& shape, Fill fill) {
    py::array_t<T> a(shape);
    fill(a.mutable_data());
    return a;
}

/// n vectors as a float64 array of `shape` + (3,).
py::array_t<double> vec3_array(const Vec3d* v, size_t n, std::vector<py::ssize_t> shape);

/// JSON (provenance, reports) as Python dicts and lists, through the json module.
py::object json_to_python(const nlohmann::json& j);

/// The sampler options of a call's keywords (sampler_keywords.cpp): every keyword the call
/// does not name itself is a key of the one options codec (harness/config/sampler_spec.h),
/// read as a config's "sampler" object ("auto" resolved, every check and message the
/// config's; an unknown keyword names the nearest key and lists `arguments`, the call's own
/// names, and the codec's). sign="none" asks for unsigned distance.
struct SamplerKeywords {
    SamplerOptions options;
    bool unsigned_distance = false;
};
SamplerKeywords read_sampler_keywords(const std::string& call, const py::kwargs& keywords,
                                      const std::vector<std::string>& arguments);

/// The docstrings' paragraph on the sampler keywords, generated from the codec's table.
const std::string& sampler_keywords_doc();

/// The sign names the module takes: the sign modes' table, then "none" (unsigned distance).
std::vector<std::string> sign_names_with_none();

// The binding files, one per job; module.cpp calls them in this order.
void bind_mesh(py::module_& m);
void bind_query(py::module_& m);
void bind_field(py::module_& m);
void bind_render(py::module_& m);
void bind_distributed(py::module_& m);

}  // namespace sdf
