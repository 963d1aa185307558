// The sampler keywords of sample(), query(), SDF() and sdf(): the keywords a call does not
// name itself become a JSON object that the one options codec reads
// (harness/config/sampler_spec.h), as run-experiment reads a config's "sampler". So the
// accepted names are the codec's table (core/sampling/sampler_options.h), an unknown keyword
// is refused naming it, the nearest name and every accepted one, and every value is checked
// with the config's message.
#include <stdexcept>
#include <string>
#include <vector>

#include "harness/config/json_reader.h"
#include "harness/config/sampler_spec.h"
#include "python/src/common.h"

namespace sdf {
namespace {

/// A keyword's value as JSON: bool, integer (Python or NumPy), float, str, None, or for a key
/// that takes a list (devices=[0, 1]) a list or tuple of those; the codec then checks it
/// against the key's domain.
nlohmann::json keyword_json(const std::string& call, const std::string& key, const py::handle& value) {
    PyObject* v = value.ptr();
    if (value.is_none()) return nullptr;
    static const nlohmann::json defaults = sampler_options_to_json(SamplerOptions{});
    if ((PyList_Check(v) || PyTuple_Check(v)) && defaults.contains(key) && defaults.at(key).is_array()) {
        nlohmann::json items = nlohmann::json::array();
        for (const py::handle item : value) {
            if (PyList_Check(item.ptr()) || PyTuple_Check(item.ptr()))
                throw py::type_error(call + ": key '" + key + "': expected a flat list, got " + std::string(py::repr(value)));
            items.push_back(keyword_json(call, key, item));
        }
        return items;
    }
    if (PyBool_Check(v)) return v == Py_True;
    if (PyIndex_Check(v)) {
        int overflow = 0;
        const py::object index = py::reinterpret_steal<py::object>(PyNumber_Index(v));
        if (!index) throw py::error_already_set();
        const long long n = PyLong_AsLongLongAndOverflow(index.ptr(), &overflow);
        if (overflow != 0) throw py::value_error(call + ": key '" + key + "': " + std::string(py::repr(value)) + " is out of range");
        return int64_t(n);
    }
    if (PyFloat_Check(v) || py::hasattr(value, "__float__")) return value.cast<double>();
    if (PyUnicode_Check(v)) return value.cast<std::string>();
    throw py::type_error(call + ": key '" + key + "': expected a str, a number or a bool, got " +
                         std::string(Py_TYPE(v)->tp_name) + " " + std::string(py::repr(value)));
}

}  // namespace

std::vector<std::string> sign_names_with_none() {
    std::vector<std::string> names = sign_mode_names();
    names.push_back("none");
    return names;
}

SamplerKeywords read_sampler_keywords(const std::string& call, const py::kwargs& keywords,
                                      const std::vector<std::string>& arguments) {
    nlohmann::json j = nlohmann::json::object();
    for (const auto& [key, value] : keywords) {
        const std::string name = py::str(key);
        j[name] = keyword_json(call, name, value);
    }
    if (j.contains("progress"))  // the codec's field: the module reports progress to Python (task.h)
        throw std::invalid_argument(call + ": key 'progress': progress goes to Python, through the progress= argument of "
                                           "query(), SDF.query(), sample() and SDF.sample()");
    SamplerKeywords out;
    {
        // "none" (unsigned distance) is the module's sign beyond the sign modes: the sampler
        // then runs with the pseudonormal sign, whose magnitudes are every mode's (mesh_sdf.h).
        JsonReader signs(j, call);
        if (signs.choice("sign", sign_names_with_none(), sign_mode_name(SignMode::Auto)) == "none") {
            out.unsigned_distance = true;
            j["sign"] = sign_mode_name(SignMode::Pseudonormal);
        }
    }
    j["progress"] = false;
    JsonReader reader(j, call);
    for (const std::string& a : arguments) reader.accept(a);  // named in "did you mean" and the valid list
    out.options = parse_sampler_options(reader);
    return out;
}

const std::string& sampler_keywords_doc() {
    static const std::string doc = [] {
        const nlohmann::json defaults = sampler_options_to_json(SamplerOptions{});
        std::string keys;
        for (const auto& [key, value] : defaults.items())
            if (key != "progress") keys += (keys.empty() ? "" : ", ") + key + "=" + value.dump();
        return "Sampler keywords, as the keys of a config's \"sampler\" object (the same names, defaults, checks and "
               "messages; docs/harness.md, \"Defaults\"): " + keys + ". sign: \"auto\", \"pseudonormal\", "
               "\"winding\" (docs/winding.md) or \"none\" (unsigned distance); backend \"auto\" is cuda when this "
               "build has it and a GPU is present, else cpu; band_width applies to lattices. An unknown keyword raises "
               "ValueError naming it and the accepted ones.";
    }();
    return doc;
}

}  // namespace sdf
