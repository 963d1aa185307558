#include "harness/config/sweep.h"

#include <regex>
#include <stdexcept>

#include "harness/config/json_reader.h"

namespace sdf {
namespace {

struct Axis {
    std::string key;
    std::vector<nlohmann::json> values;
    std::vector<std::string> labels;
};

std::string sanitised(std::string s) {
    for (char& c : s)
        if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-')) c = '_';
    return s;
}

std::string scalar_text(const nlohmann::json& v) {
    if (v.is_string()) return v.get<std::string>();
    if (v.is_boolean() || v.is_number()) return v.dump();
    return "";
}

/// The last name of a key path: "lattices[0].resolution" -> "resolution".
std::string leaf_of(const std::string& key) {
    std::string leaf = key.substr(key.rfind('.') == std::string::npos ? 0 : key.rfind('.') + 1);
    return leaf.substr(0, leaf.find('['));
}

Axis read_axis(const std::string& key, const nlohmann::json& spec, const std::string& file) {
    const std::string where = file + ": key 'sweep." + key + "'";
    Axis axis{key, {}, {}};
    nlohmann::json values = spec;
    nlohmann::json labels;
    if (spec.is_object()) {
        for (const auto& [k, v] : spec.items())
            if (k != "values" && k != "labels")
                throw ConfigError(where + ": unknown key '" + k + "'; expected \"values\" and optionally \"labels\"");
        if (!spec.contains("values")) throw ConfigError(where + ": missing \"values\"");
        values = spec.at("values");
        if (spec.contains("labels")) labels = spec.at("labels");
    }
    if (!values.is_array() || values.empty())
        throw ConfigError(where + ": expected a non-empty array of values (or {\"values\": [...], \"labels\": [...]}), got " +
                          values.dump());
    if (!labels.is_null() && (!labels.is_array() || labels.size() != values.size()))
        throw ConfigError(where + ".labels': expected an array of " + std::to_string(values.size()) +
                          " labels, one per value, got " + labels.dump());
    for (size_t i = 0; i < values.size(); ++i) {
        std::string label;
        if (!labels.is_null()) {
            if (!labels[i].is_string() || !std::regex_match(labels[i].get<std::string>(), std::regex("[A-Za-z0-9][A-Za-z0-9_.-]*")))
                throw ConfigError(where + ".labels': expected labels of letters, digits, '.', '_' or '-', got " + labels[i].dump());
            label = labels[i].get<std::string>();
        } else {
            const std::string short_form = sweep_value_label(values[i]);
            label = leaf_of(key) + "_" + (short_form.empty() ? std::to_string(i + 1) : short_form);
        }
        for (const std::string& l : axis.labels)
            if (l == label)
                throw ConfigError(where + ": two values get the label \"" + label + "\"; give \"labels\" to tell them apart");
        axis.values.push_back(values[i]);
        axis.labels.push_back(label);
    }
    return axis;
}

}  // namespace

std::string sweep_value_label(const nlohmann::json& value) {
    if (value.is_array()) {
        std::string out;
        for (const auto& v : value) {
            const std::string t = scalar_text(v);
            if (t.empty()) return "";
            out += (out.empty() ? "" : "x") + t;
        }
        return sanitised(out);
    }
    return sanitised(scalar_text(value));
}

void set_at_key_path(nlohmann::json& j, const std::string& key_path, const nlohmann::json& value) {
    static const std::regex token("([^.\\[\\]]+)|\\[([0-9]+)\\]|(\\.)");
    nlohmann::json* node = &j;
    std::string walked;
    size_t pos = 0;
    bool expect_name = true;
    while (pos < key_path.size()) {
        std::smatch m;
        const std::string rest = key_path.substr(pos);
        if (!std::regex_search(rest, m, token, std::regex_constants::match_continuous))
            throw std::invalid_argument("cannot parse the key path at \"" + rest + "\"");
        pos += size_t(m.length(0));
        if (m[3].matched) {
            if (expect_name) throw std::invalid_argument("empty name before '.'");
            expect_name = true;
            continue;
        }
        if (m[1].matched) {
            if (!expect_name) throw std::invalid_argument("expected '.' or '[' after \"" + walked + "\"");
            if (node->is_null()) *node = nlohmann::json::object();
            if (!node->is_object())
                throw std::invalid_argument("\"" + walked + "\" is " + node->dump() + ", not an object");
            node = &(*node)[m[1].str()];
            walked += (walked.empty() ? "" : ".") + m[1].str();
        } else {
            const size_t i = std::stoul(m[2].str());
            if (!node->is_array() || i >= node->size())
                throw std::invalid_argument("\"" + walked + "\" has no entry [" + std::to_string(i) + "] (it is " +
                                            (node->is_null() ? std::string("absent") : node->dump()) + ")");
            node = &(*node)[i];
            walked += "[" + std::to_string(i) + "]";
        }
        expect_name = false;
    }
    if (walked.empty() || expect_name) throw std::invalid_argument("empty or incomplete key path");
    *node = value;
}

std::vector<SweepPoint> expand_sweep(const nlohmann::json& config, const std::string& file, const std::string& name) {
    nlohmann::json base = config;
    if (!base.contains("sweep")) return {SweepPoint{name, nlohmann::json::object(), base}};
    const nlohmann::json sweep = base.at("sweep");
    base.erase("sweep");
    if (!sweep.is_object() || sweep.empty())
        throw ConfigError(file + ": key 'sweep': expected an object {\"key.path\": [values...]}, got " + sweep.dump());
    std::vector<Axis> axes;
    for (const auto& [key, spec] : sweep.items()) {
        const std::string root = key.substr(0, key.find_first_of(".["));
        if (root == "name" || root == "kind" || root == "sweep" || root == "parent")
            throw ConfigError(file + ": key 'sweep." + key + "': \"" + root + "\" cannot be swept (each point is named after "
                              "the config's name, and all points share one kind)");
        axes.push_back(read_axis(key, spec, file));
    }
    std::vector<SweepPoint> points;
    std::vector<size_t> index(axes.size(), 0);
    while (true) {
        SweepPoint p{name, nlohmann::json::object(), base};
        for (size_t a = 0; a < axes.size(); ++a) {
            const nlohmann::json& v = axes[a].values[index[a]];
            try {
                set_at_key_path(p.config, axes[a].key, v);
            } catch (const std::invalid_argument& e) {
                throw ConfigError(file + ": key 'sweep." + axes[a].key + "': " + e.what());
            }
            p.parameters[axes[a].key] = v;
            p.name += "-" + axes[a].labels[index[a]];
        }
        points.push_back(std::move(p));
        // Next combination, the last axis fastest.
        size_t a = axes.size();
        while (a > 0 && ++index[a - 1] == axes[a - 1].values.size()) index[--a] = 0;
        if (a == 0) break;
    }
    return points;
}

}  // namespace sdf
