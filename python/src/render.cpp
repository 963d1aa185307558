// Rendering: sdf_lattices.render, the field's reconstruction ray-cast as sdf-render does.
#include <stdexcept>
#include <string>
#include <vector>

#include "core/mesh/prepared_mesh.h"
#include "core/raycast/views.h"
#include "harness/render/image_buffer.h"
#include "harness/render/render_backend.h"
#include "python/src/common.h"
#include "python/src/field.h"
#include "python/src/mesh.h"
#include "python/src/task.h"

namespace sdf {
namespace {

py::array_t<float> render(Field& field, const std::string& view, const py::object& size, const std::string& interpolator,
                          const std::string& derivatives, const std::string& backend, const std::string& precision,
                          const py::object& eye, const py::object& target, const std::vector<double>& up, double fov,
                          const py::object& mesh_in, int threads, const py::object& progress) {
    const MeshHolder mesh = mesh_in.is_none() ? nullptr : mesh_argument(mesh_in);
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
    o.progress = false;  // to the Python callback (task.h)
    o.precision = precision_from_name(precision);
    TaskOptions task;
    task.total = int64_t(width) * height;
    task.label = "rendering";
    task.progress = progress;
    const ImageRgb image = run_task([&] {
        const CameraSpec camera = mesh ? resolve_view(v, mesh->vertices(), width, height)
                                       : resolve_view(v, field_solid_bounds(field.field()), width, height);
        return shaded_image(render_reconstruction(*recon, camera, o));
    }, task);
    return new_array<float>({height, width, 3}, [&](float* out) { std::copy(image.data.begin(), image.data.end(), out); });
}

}  // namespace

void bind_render(py::module_& m) {
    m.def("render", &render, py::arg("field"), py::arg("view") = "three_quarter", py::arg("size") = 512,
          py::arg("interpolator") = "", py::arg("derivatives") = "", py::arg("backend") = "auto",
          py::arg("precision") = "float", py::arg("eye") = py::none(), py::arg("target") = py::none(),
          py::arg("up") = std::vector<double>{0, 1, 0}, py::arg("fov") = 30.0, py::arg("mesh") = py::none(),
          py::arg("threads") = 0, py::arg("progress") = py::none(),
          R"(render(field, view="three_quarter", size=512, interpolator="", derivatives="", backend="auto", precision="float", eye=None, target=None, up=(0, 1, 0), fov=30, mesh=None, threads=0, progress=None) -> image

Ray-casts the field's reconstruction as sdf-render does and returns the shaded image, float32
of shape (height, width, 3), values in [0, 1], row 0 at the top. view: a named view
(docs/raycast.md), or eye and target (and up) for an explicit camera; size: an int or
(width, height); mesh frames the view by its vertices (else the field's solid is framed).)");
}

}  // namespace sdf
