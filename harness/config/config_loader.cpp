#include "harness/config/config_loader.h"

#include <algorithm>
#include <filesystem>

#include "harness/config/json_reader.h"

namespace sdf {
namespace fs = std::filesystem;

namespace {

constexpr int kMaxDepth = 16;

nlohmann::json load_chain(const std::string& path, std::vector<std::string>& files) {
    const std::string absolute = fs::weakly_canonical(fs::absolute(path)).string();
    if (std::find(files.begin(), files.end(), absolute) != files.end()) {
        std::string chain;
        for (const auto& f : files) chain += f + " -> ";
        throw ConfigError(files.back() + ": key 'parent': inheritance cycle: " + chain + absolute);
    }
    if (int(files.size()) >= kMaxDepth)
        throw ConfigError(files.back() + ": key 'parent': more than " + std::to_string(kMaxDepth) + " levels of parents");
    const std::string shown = files.empty() ? path : absolute;
    nlohmann::json config = read_json_file(shown, "config file");
    files.push_back(absolute);
    if (!config.is_object()) throw ConfigError(shown + ": the config: expected a JSON object, got " + config.dump());
    if (!config.contains("parent")) return config;
    const nlohmann::json& parent = config.at("parent");
    if (!parent.is_string() || parent.get<std::string>().empty())
        throw ConfigError(shown + ": key 'parent': expected the path of a parent config (relative to this file), got " +
                          parent.dump());
    fs::path parent_path = parent.get<std::string>();
    if (parent_path.is_relative()) parent_path = fs::path(absolute).parent_path() / parent_path;
    if (!fs::is_regular_file(parent_path))
        throw ConfigError(shown + ": key 'parent': " + parent_path.string() + " is not a config file");
    nlohmann::json base = load_chain(parent_path.string(), files);
    config.erase("parent");
    return merge_config(base, config);
}

}  // namespace

std::string LoadedConfig::label() const {
    if (files.size() <= 1) return path;
    std::string parents;
    for (size_t i = 1; i < files.size(); ++i) parents += (i > 1 ? ", " : "") + files[i];
    return path + " (inheriting from " + parents + ")";
}

nlohmann::json merge_config(const nlohmann::json& parent, const nlohmann::json& child) {
    if (!parent.is_object() || !child.is_object()) return child;
    nlohmann::json out = parent;
    for (const auto& [key, value] : child.items()) {
        if (value.is_null()) out.erase(key);
        else if (value.is_object() && out.contains(key) && out[key].is_object()) out[key] = merge_config(out[key], value);
        else out[key] = value;
    }
    return out;
}

LoadedConfig load_config(const std::string& path) {
    LoadedConfig c;
    c.path = path;
    c.as_written = read_json_file(path, "config file");
    c.merged = load_chain(path, c.files);
    return c;
}

}  // namespace sdf
