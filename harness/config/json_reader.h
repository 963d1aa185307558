/// @file json_reader.h
/// @brief Strict, self-describing reading of JSON configs: every key is typed, every error
/// names the file, the key path and what was expected, and unknown keys are rejected with
/// the nearest valid key suggested.
///
///   JsonReader r(json, file);            // root object
///   int n = r.required<int>("threads", "a thread count");
///   JsonReader s = r.object("sampler");  // nested, path "sampler"
///   r.finish();                          // throws on keys nobody asked for
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace sdf {

/// A config error: the message already holds file, key and expectation.
class ConfigError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// Parses a JSON file; syntax errors name the file, line and column.
nlohmann::json read_json_file(const std::string& path);

class JsonReader {
public:
    JsonReader(const nlohmann::json& value, std::string file, std::string path = "");

    bool has(const std::string& key) const;
    const nlohmann::json& raw(const std::string& key);  ///< marks the key as used

    /// Typed access; `expected` describes the value for error messages ("a positive integer").
    template <typename T>
    T required(const std::string& key, const std::string& expected);
    template <typename T>
    T optional(const std::string& key, const T& fallback, const std::string& expected);
    /// A string that must be one of `choices`.
    std::string choice(const std::string& key, const std::vector<std::string>& choices, const std::string& fallback);

    JsonReader object(const std::string& key);            ///< required nested object
    std::vector<JsonReader> objects(const std::string& key);  ///< required array of objects

    /// Throws ConfigError for a key nobody asked about, suggesting the nearest known key.
    void finish(const std::vector<std::string>& also_allowed = {}) const;

    [[noreturn]] void fail(const std::string& key, const std::string& message) const;
    std::string key_path(const std::string& key) const;
    const std::string& file() const { return file_; }
    const std::string& path() const { return path_; }
    const nlohmann::json& json() const { return value_; }

private:
    template <typename T>
    T convert(const std::string& key, const nlohmann::json& v, const std::string& expected) const;

    const nlohmann::json& value_;
    std::string file_, path_;
    mutable std::vector<std::string> known_;  ///< every key asked about
};

/// Levenshtein distance (for "did you mean").
int edit_distance(const std::string& a, const std::string& b);
/// The candidate nearest to `word`, or "" when none is close enough to be a likely typo.
std::string nearest_match(const std::string& word, const std::vector<std::string>& candidates);

// ---- template definitions ---------------------------------------------------------------

template <typename T>
T JsonReader::convert(const std::string& key, const nlohmann::json& v, const std::string& expected) const {
    try {
        if constexpr (std::is_same_v<T, bool>) {
            if (!v.is_boolean()) throw std::invalid_argument("");
        } else if constexpr (std::is_integral_v<T>) {
            if (!v.is_number_integer()) throw std::invalid_argument("");
        } else if constexpr (std::is_floating_point_v<T>) {
            if (!v.is_number()) throw std::invalid_argument("");
        } else if constexpr (std::is_same_v<T, std::string>) {
            if (!v.is_string()) throw std::invalid_argument("");
        }
        return v.get<T>();
    } catch (const std::exception&) {
        fail(key, "expected " + expected + ", got " + v.dump());
    }
}

template <typename T>
T JsonReader::required(const std::string& key, const std::string& expected) {
    if (!has(key)) fail(key, "missing; expected " + expected);
    return convert<T>(key, raw(key), expected);
}

template <typename T>
T JsonReader::optional(const std::string& key, const T& fallback, const std::string& expected) {
    if (!has(key)) return fallback;
    return convert<T>(key, raw(key), expected);
}

}  // namespace sdf
