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

namespace sdf {
namespace py = pybind11;

using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

/// "'a', 'b', 'c'"
std::string quoted_list(const std::vector<std::string>& names);

/// `value` when it is one of `choices`, else ValueError naming the argument and the choices.
const std::string& choose(const std::string& argument, const std::string& value, const std::vector<std::string>& choices);

Precision precision_from_name(const std::string& name);

/// `value` as a float64 array (NumPy arrays of any numeric dtype, nested sequences);
/// TypeError naming the argument "points" and the type otherwise.
DoubleArray points_argument(const py::object& value);

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

// The binding files, one per job; module.cpp calls them in this order.
void bind_mesh(py::module_& m);
void bind_query(py::module_& m);
void bind_field(py::module_& m);
void bind_render(py::module_& m);
void bind_distributed(py::module_& m);

}  // namespace sdf
