#include "python/src/task.h"

namespace sdf {

py::object progress_reporter(const py::object& progress, const std::string& label, int64_t total) {
    if (progress.is_none() || (py::isinstance<py::bool_>(progress) && !progress.cast<bool>())) return py::none();
    return py::module_::import("sdf_lattices._progress").attr("reporter")(progress, label, total);
}

void raise_warnings(const std::vector<std::string>& warnings) {
    if (warnings.empty()) return;
    const py::module_ module = py::module_::import("sdf_lattices._warnings");
    const py::object category = module.attr("SdfWarning"), warn = module.attr("warn_at_caller");
    for (const std::string& text : warnings) warn(text, category);  // at the caller's line
}

}  // namespace sdf
