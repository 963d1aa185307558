// The tools' sampler options (--method, --backend, --kernel, ...), read through the one codec
// of SamplerOptions (harness/config/sampler_spec.h): each flag keeps the text it was given,
// only the flags given become keys of a JSON object, and sampler_options_from_json reads that
// object as it reads a config's "sampler". So absent flags take the struct's defaults (the
// defaults of every config and Python call), "auto" is resolved where configs resolve it, and
// every check and message is the config's. Help texts show the codec's defaults and choices.
#pragma once

#include <CLI/CLI.hpp>

#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "harness/config/sampler_spec.h"

namespace sdf {

class SamplerCli {
public:
    /// Adds `flag` for the codec's key `key` (a field of core/sampling/sampler_options.h).
    CLI::Option* add(CLI::App& app, const std::string& flag, const std::string& key, const std::string& help) {
        const nlohmann::json defaults = sampler_options_to_json(SamplerOptions{});
        if (!defaults.contains(key)) throw std::logic_error("SamplerCli: no sampler option '" + key + "'");
        std::string& text = texts_[key];
        CLI::Option* option = app.add_option(flag, text, help);
        const nlohmann::json& d = defaults.at(key);
        option->type_name(d.is_string() ? "TEXT" : d.is_boolean() ? "BOOL" : d.is_number_integer() ? "INT" : d.is_array() ? "LIST" : "FLOAT");
        if (!(d.is_string() && d.get<std::string>().empty()))
            option->default_str(d.is_string() ? d.get<std::string>() : d.dump());
        const std::vector<std::string> choices = sampler_option_choices(key);
        if (!choices.empty()) option->check(CLI::IsMember(choices));
        options_.emplace_back(key, option);
        return option;
    }

    /// The flags given, as the codec's JSON: names stay strings, numbers and booleans become
    /// JSON numbers and booleans when they read as such (else the codec names the bad text).
    nlohmann::json given() const {
        const nlohmann::json defaults = sampler_options_to_json(SamplerOptions{});
        nlohmann::json j = nlohmann::json::object();
        for (const auto& [key, option] : options_) {
            if (option->count() == 0) continue;
            const std::string& text = texts_.at(key);
            if (defaults.at(key).is_string() || defaults.at(key).is_array()) {  // a list's text ("0,1", "all") too
                j[key] = text;
            } else {
                nlohmann::json parsed = nlohmann::json::parse(text, nullptr, false);
                j[key] = parsed.is_discarded() || parsed.is_structured() ? nlohmann::json(text) : parsed;
            }
        }
        return j;
    }

    /// The options of the flags given plus `extra` keys (e.g. "progress"), or a ConfigError
    /// naming the key and what was expected.
    SamplerOptions options(const nlohmann::json& extra = nlohmann::json::object()) const {
        nlohmann::json j = given();
        for (const auto& [key, value] : extra.items()) j[key] = value;
        return sampler_options_from_json(j, "the command line");
    }

private:
    std::map<std::string, std::string> texts_;  ///< stable addresses for CLI11
    std::vector<std::pair<std::string, CLI::Option*>> options_;
};

}  // namespace sdf
