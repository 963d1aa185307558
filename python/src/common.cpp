#include "python/src/common.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <stdexcept>

#include "core/quoted_alternatives.h"
#include "harness/resources/memory_budget.h"

namespace sdf {

const std::string& choose(const std::string& argument, const std::string& value, const std::vector<std::string>& choices) {
    if (std::find(choices.begin(), choices.end(), value) == choices.end())
        throw std::invalid_argument(argument + ": unknown value \"" + value + "\"; expected one of " + quoted_alternatives(choices));
    return value;
}

DoubleArray points_argument(const py::object& value) {
    const bool is_array = py::isinstance<py::array>(value);
    const auto refuse = [&] {
        return py::type_error("points: expected an (N, 3) array of numbers, got " +
                              std::string(py::str(py::type::of(value).attr("__name__"))) +
                              (is_array ? " of dtype " + std::string(py::str(py::array(value).dtype())) : ""));
    };
    if (is_array && std::string("biuf").find(py::array(value).dtype().kind()) == std::string::npos) throw refuse();
    if (is_array) {
        // A numeric array converts unless memory runs out: say so, with the size (ensure()
        // would swallow NumPy's MemoryError and leave a TypeError about the type).
        const py::array in = py::reinterpret_borrow<py::array>(value);
        const std::string converting = "points: out of memory converting " + std::to_string(in.size()) + " values of dtype " +
                                       std::string(py::str(in.dtype())) + " to float64 (" +
                                       format_bytes(uint64_t(in.size()) * sizeof(double)) + ")";
        // The size checked before NumPy allocates: where the kernel overcommits memory, an
        // allocation larger than the machine succeeds and the copy is then killed, not refused.
        const bool copies = !(in.dtype().is(py::dtype::of<double>()) && (in.flags() & py::array::c_style));
        const uint64_t available = host_memory_available();
        if (copies && available > 0 && uint64_t(in.size()) > available / sizeof(double))
            raise_memory_error(converting + ", more than the " + format_bytes(available) + " available");
        try {
            return DoubleArray::ensure(py::module_::import("numpy").attr("asarray")(value, "float64", "C"));
        } catch (py::error_already_set& e) {
            if (!e.matches(PyExc_MemoryError)) throw;
            raise_memory_error(converting);
        }
    }
    DoubleArray a = DoubleArray::ensure(value);
    if (!a) throw refuse();
    return a;
}

void raise_memory_error(const std::string& message) {
    PyErr_SetString(PyExc_MemoryError, message.c_str());
    throw py::error_already_set();
}

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

namespace {
void require_rows_of_three(const py::array& a, const std::string& argument) {
    if (a.ndim() == 2 && a.shape(1) == 3) return;
    std::string shape = "(";
    for (py::ssize_t k = 0; k < a.ndim(); ++k) shape += (k ? ", " : "") + std::to_string(a.shape(k));
    throw std::invalid_argument(argument + ": expected an array of shape (N, 3), got shape " + shape + (a.ndim() == 1 ? ",)" : ")"));
}
}  // namespace

PointsView points_view(const py::object& value, const std::string& argument) {
    PointsView v;
    const bool float32 = py::isinstance<py::array_t<float>>(value);
    if (float32 || py::isinstance<py::array_t<double>>(value)) {
        v.keep = py::reinterpret_borrow<py::array>(value);
        const py::ssize_t item = float32 ? py::ssize_t(sizeof(float)) : py::ssize_t(sizeof(double));
        // Strides that are not whole elements (a view into a structured array) are copied.
        if (v.keep.ndim() != 2 || v.keep.strides(0) % item != 0 || v.keep.strides(1) % item != 0) v.keep = points_argument(value);
    } else {
        v.keep = points_argument(value);
    }
    require_rows_of_three(v.keep, argument);
    const bool f32 = py::isinstance<py::array_t<float>>(v.keep);
    const py::ssize_t item = f32 ? py::ssize_t(sizeof(float)) : py::ssize_t(sizeof(double));
    v.points = HostPoints{v.keep.data(), f32, int64_t(v.keep.shape(0)), int64_t(v.keep.strides(0) / item),
                          int64_t(v.keep.strides(1) / item)};
    return v;
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

py::object json_to_python(const nlohmann::json& j) {
    return py::module_::import("json").attr("loads")(j.dump());
}

std::string number_text(double v) {
    char text[32];
    const auto end = std::to_chars(text, text + sizeof text, v).ptr;
    return std::string(text, end);
}

}  // namespace sdf
