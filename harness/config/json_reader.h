/// @file json_reader.h
/// @brief Strict, self-describing reading of JSON configs: every key is typed, every error
/// names the file, the key path, the value seen and what was expected, and unknown keys are
/// rejected with the nearest valid key suggested.
///
///   JsonReader r(json, file);            // root object
///   int n = r.required<int>("threads", "a thread count");
///   JsonReader s = r.object("sampler");  // nested, path "sampler"
///   r.finish();                          // throws on keys nobody asked for
///
/// A reader can also record what it reads into a "resolved" tree (the config as the run
/// used it: every value read, defaults included), for the run's manifest.
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include <nlohmann/json.hpp>

namespace sdf {

/// A config error: the message already holds file, key and expectation.
class ConfigError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// Parses a JSON file; syntax errors name the file, line and column.
nlohmann::json read_json_file(const std::string& path, const std::string& what = "JSON file");

class JsonReader {
public:
    /// The reader keeps a reference to `value`: it must outlive the reader (a temporary
    /// cannot be passed).
    JsonReader(const nlohmann::json& value, std::string file, std::string path = "");
    JsonReader(nlohmann::json&& value, std::string file, std::string path = "") = delete;
    /// A reader that also writes every value it reads (defaults included) into `*resolved`
    /// at `where` (a JSON pointer into that tree).
    JsonReader(const nlohmann::json& value, std::string file, std::string path,
               std::shared_ptr<nlohmann::json> resolved, nlohmann::json::json_pointer where);

    bool has(const std::string& key) const;
    const nlohmann::json& raw(const std::string& key);  ///< marks the key as used

    /// Typed access; `expected` describes the value for error messages ("a positive integer").
    /// Integers must fit the target type; arrays are checked element by element.
    template <typename T>
    T required(const std::string& key, const std::string& expected);
    template <typename T>
    T optional(const std::string& key, const T& fallback, const std::string& expected);
    /// A string that must be one of `choices`.
    std::string choice(const std::string& key, const std::vector<std::string>& choices, const std::string& fallback);

    JsonReader object(const std::string& key);            ///< required nested object
    /// A nested object that may be absent (then read as {}: its keys take their defaults).
    JsonReader optional_object(const std::string& key);
    std::vector<JsonReader> objects(const std::string& key);  ///< required array of objects

    /// Marks `key` as understood without reading it (its value is checked elsewhere).
    void accept(const std::string& key) const;

    /// Throws ConfigError for a key nobody asked about, suggesting the nearest known key.
    void finish(const std::vector<std::string>& also_allowed = {}) const;

    [[noreturn]] void fail(const std::string& key, const std::string& message) const;
    std::string key_path(const std::string& key) const;
    const std::string& file() const { return file_; }
    const std::string& path() const { return path_; }
    const nlohmann::json& json() const { return value_; }

    /// Writes `value` at `key` of the resolved tree (no-op without one).
    void record(const std::string& key, const nlohmann::json& value) const;

private:
    template <typename T>
    T convert(const std::string& key, const nlohmann::json& v, const std::string& expected) const;
    [[noreturn]] void fail_missing(const std::string& key, const std::string& expected) const;
    JsonReader child(const nlohmann::json& v, const std::string& path, const nlohmann::json::json_pointer& where) const;

    const nlohmann::json& value_;
    std::string file_, path_;
    std::shared_ptr<nlohmann::json> resolved_;
    nlohmann::json::json_pointer where_;
    mutable std::vector<std::string> known_;  ///< every key asked about
};

/// Levenshtein distance (for "did you mean").
int edit_distance(const std::string& a, const std::string& b);
/// The candidate nearest to `word`, or "" when none is close enough to be a likely typo.
std::string nearest_match(const std::string& word, const std::vector<std::string>& candidates);

// ---- template definitions ---------------------------------------------------------------

namespace json_detail {

template <typename T>
struct is_vector : std::false_type {};
template <typename T, typename A>
struct is_vector<std::vector<T, A>> : std::true_type {};

/// Why `v` is not a T: "" when it is one, " (why)" when an explanation helps, or "!" for a
/// plain type mismatch.
template <typename T>
std::string type_problem(const nlohmann::json& v) {
    if constexpr (std::is_same_v<T, bool>) {
        return v.is_boolean() ? "" : "!";
    } else if constexpr (std::is_integral_v<T>) {
        if (!v.is_number_integer()) return "!";
        const bool fits = v.is_number_unsigned()
                              ? v.get<uint64_t>() <= uint64_t(std::numeric_limits<T>::max())
                              : (v.get<int64_t>() >= int64_t(std::numeric_limits<T>::min()) &&
                                 (std::is_unsigned_v<T> || v.get<int64_t>() <= int64_t(std::numeric_limits<T>::max())));
        if (fits) return "";
        return " (out of range: the largest accepted value is " + std::to_string(std::numeric_limits<T>::max()) +
               (std::is_signed_v<T> ? ", the smallest " + std::to_string(std::numeric_limits<T>::min()) : std::string()) +
               ")";
    } else if constexpr (std::is_floating_point_v<T>) {
        return v.is_number() ? "" : "!";
    } else if constexpr (std::is_same_v<T, std::string>) {
        return v.is_string() ? "" : "!";
    } else if constexpr (is_vector<T>::value) {
        if (!v.is_array()) return "!";
        for (size_t i = 0; i < v.size(); ++i) {
            const std::string p = type_problem<typename T::value_type>(v[i]);
            if (!p.empty())
                return " (entry " + std::to_string(i) + ", " + v[i].dump() + ", is not of that type" +
                       (p == "!" ? std::string() : p) + ")";
        }
        return "";
    } else {
        return "";  // other types: nlohmann's own conversion decides
    }
}

}  // namespace json_detail

template <typename T>
T JsonReader::convert(const std::string& key, const nlohmann::json& v, const std::string& expected) const {
    const std::string problem = json_detail::type_problem<T>(v);
    if (!problem.empty()) fail(key, "expected " + expected + ", got " + v.dump() + (problem == "!" ? "" : problem));
    try {
        return v.get<T>();
    } catch (const std::exception&) {
        fail(key, "expected " + expected + ", got " + v.dump());
    }
}

template <typename T>
T JsonReader::required(const std::string& key, const std::string& expected) {
    if (!has(key)) fail_missing(key, expected);
    T value = convert<T>(key, raw(key), expected);
    record(key, value);
    return value;
}

template <typename T>
T JsonReader::optional(const std::string& key, const T& fallback, const std::string& expected) {
    T value = has(key) ? convert<T>(key, raw(key), expected) : fallback;
    record(key, value);
    return value;
}

}  // namespace sdf
