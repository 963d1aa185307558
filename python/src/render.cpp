// Rendering: sdf_lattices.render, the field's reconstruction ray-cast as sdf-render does.
#include <stdexcept>
#include <string>
#include <vector>

#include "core/mesh/prepared_mesh.h"
#include "core/raycast/views.h"
#include "harness/config/render_spec.h"
#include "harness/render/image_buffer.h"
#include "harness/render/render_backend.h"
#include "python/src/common.h"
#include "python/src/field.h"
#include "python/src/mesh.h"
#include "python/src/task.h"

namespace sdf {
namespace {

/// render()'s view, size and caster arguments as a config's "render" object, read by its one
/// codec (harness/config/render_spec.h): the checks, defaults and messages of configs and
/// sdf-render.
RenderSpec render_spec_of(const std::string& view, const py::object& size, const std::string& backend,
                          const std::string& precision, const py::object& eye, const py::object& target,
                          const std::vector<double>& up, double fov) {
    nlohmann::json j = {{"fov", fov}, {"backend", backend}, {"precision", precision}, {"reference", false}};
    if (py::isinstance<py::int_>(size)) j["size"] = size.cast<int64_t>();
    else j["size"] = size.cast<std::vector<int64_t>>();
    if (!eye.is_none() || !target.is_none()) {
        if (eye.is_none() || target.is_none()) throw std::invalid_argument("eye and target: both needed, 3 numbers each");
        j["views"] = {{{"name", "camera"}, {"eye", eye.cast<std::vector<double>>()},
                       {"target", target.cast<std::vector<double>>()}, {"up", up}, {"fov", fov}}};
    } else {
        j["views"] = {view};
    }
    return render_spec_from_json(j, "render()");
}

py::array_t<float> render(Field& field, const std::string& view, const py::object& size, const std::string& interpolator,
                          const std::string& derivatives, const std::string& backend, const std::string& precision,
                          const py::object& eye, const py::object& target, const std::vector<double>& up, double fov,
                          const py::object& mesh_in, int threads, const py::object& progress) {
    const MeshHolder mesh = mesh_in.is_none() ? nullptr : mesh_argument(mesh_in);
    const RenderSpec spec = render_spec_of(view, size, backend, precision, eye, target, up, fov);
    const ViewRequest& v = spec.views.front();
    const int width = spec.width, height = spec.height;
    const std::shared_ptr<const Reconstruction> recon = field.reconstruction(interpolator, derivatives, 0.5, "lattice", threads);
    RenderOptions o = render_options(spec);
    o.threads = threads;
    o.progress = false;  // to the Python callback (task.h)
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
