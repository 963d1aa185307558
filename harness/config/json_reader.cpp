#include "harness/config/json_reader.h"

#include <algorithm>
#include <fstream>
#include <sstream>

#include "core/io/text_file.h"
#include "core/quoted_alternatives.h"

namespace sdf {
namespace {
/// Configs and field headers are small; a larger "JSON" file is a wrong path.
constexpr uint64_t kMaxJsonFileBytes = uint64_t(64) << 20;
}  // namespace

nlohmann::json read_json_file(const std::string& path, const std::string& what) {
    std::string s;
    try {
        s = read_text_file(path, what, kMaxJsonFileBytes);
    } catch (const std::runtime_error& e) {
        throw ConfigError(e.what());
    }
    // JSON says names within an object SHOULD be unique and leaves duplicates to the reader;
    // nlohmann keeps the last silently. A repeated key is almost always an edit gone wrong,
    // so it is an error. One set of keys per object being parsed (the callback sees the
    // objects nested, in order).
    std::vector<std::vector<std::string>> keys_of_open_objects;
    const auto refuse_duplicates = [&](int, nlohmann::json::parse_event_t event, nlohmann::json& parsed) {
        using Event = nlohmann::json::parse_event_t;
        if (event == Event::object_start) keys_of_open_objects.emplace_back();
        else if (event == Event::object_end) keys_of_open_objects.pop_back();
        else if (event == Event::key && !keys_of_open_objects.empty()) {
            std::vector<std::string>& keys = keys_of_open_objects.back();
            const std::string& key = parsed.get_ref<const std::string&>();
            if (std::find(keys.begin(), keys.end(), key) != keys.end())
                throw ConfigError(path + ": key '" + key + "' appears twice in one object; expected each key once");
            keys.push_back(key);
        }
        return true;
    };
    try {
        return nlohmann::json::parse(s, refuse_duplicates, true, /*ignore_comments=*/true);
    } catch (const nlohmann::json::out_of_range& e) {
        // Numbers beyond double's range (1e400) are the one out_of_range the parser raises.
        std::string what = e.what();
        const size_t bracket = what.find("] ");
        throw ConfigError(path + ": " + (bracket == std::string::npos ? what : what.substr(bracket + 2)) +
                          "; expected numbers within double precision's range (about 1.8e308)");
    } catch (const nlohmann::json::parse_error& e) {
        // Translate the byte offset into line:column.
        const size_t at = std::min<size_t>(e.byte > 0 ? e.byte - 1 : 0, s.size());
        const size_t line = size_t(std::count(s.begin(), s.begin() + long(at), '\n')) + 1;
        const size_t last_nl = s.rfind('\n', at == 0 ? 0 : at - 1);
        const size_t column = last_nl == std::string::npos ? at + 1 : at - last_nl;
        std::string what = e.what();
        const size_t colon = what.find(": ", what.find("parse error"));
        throw ConfigError(path + ":" + std::to_string(line) + ":" + std::to_string(column) +
                          ": malformed JSON: " + (colon == std::string::npos ? what : what.substr(colon + 2)));
    }
}

JsonReader::JsonReader(const nlohmann::json& value, std::string file, std::string path)
    : JsonReader(value, std::move(file), std::move(path), nullptr, nlohmann::json::json_pointer()) {}

JsonReader::JsonReader(const nlohmann::json& value, std::string file, std::string path,
                       std::shared_ptr<nlohmann::json> resolved, nlohmann::json::json_pointer where)
    : value_(value), file_(std::move(file)), path_(std::move(path)), resolved_(std::move(resolved)), where_(std::move(where)) {
    if (!value_.is_object())
        throw ConfigError(file_ + ": " + (path_.empty() ? std::string("the top level") : "key '" + path_ + "'") +
                          ": expected a JSON object, got " + (value_.is_array() ? "an array " : "") +
                          value_.dump().substr(0, 200));
}

bool JsonReader::has(const std::string& key) const {
    // Every key asked about is a valid key here, present or not (for "did you mean").
    accept(key);
    return value_.contains(key);
}

void JsonReader::accept(const std::string& key) const {
    if (std::find(known_.begin(), known_.end(), key) == known_.end()) known_.push_back(key);
}

const nlohmann::json& JsonReader::raw(const std::string& key) {
    if (!has(key)) fail_missing(key, "");
    return value_.at(key);
}

std::string JsonReader::key_path(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }

void JsonReader::fail(const std::string& key, const std::string& message) const {
    throw ConfigError(file_ + ": key '" + key_path(key) + "': " + message);
}

void JsonReader::fail_missing(const std::string& key, const std::string& expected) const {
    // A present key nobody has asked about that is close to `key` is most likely a typo of it.
    std::vector<std::string> unknown;
    for (const auto& [k, v] : value_.items())
        if (std::find(known_.begin(), known_.end(), k) == known_.end()) unknown.push_back(k);
    std::string hint;
    for (const auto& k : unknown)
        if (nearest_match(k, {key}) == key) {
            hint = "; the config has an unknown key '" + key_path(k) + "': did you mean '" + key + "'?";
            break;
        }
    fail(key, "missing" + (expected.empty() ? std::string() : "; expected " + expected) + hint);
}

void JsonReader::record(const std::string& key, const nlohmann::json& value) const {
    if (resolved_) (*resolved_)[where_ / key] = value;
}

JsonReader JsonReader::child(const nlohmann::json& v, const std::string& path,
                             const nlohmann::json::json_pointer& where) const {
    return JsonReader(v, file_, path, resolved_, where);
}

std::string JsonReader::choice(const std::string& key, const std::vector<std::string>& choices,
                               const std::string& fallback) {
    const std::string list = quoted_alternatives(choices);
    const std::string value = optional<std::string>(key, fallback, "one of " + list);
    if (std::find(choices.begin(), choices.end(), value) == choices.end()) {
        const std::string near = nearest_match(value, choices);
        fail(key, "unknown value \"" + value + "\"; expected one of " + list +
                      (near.empty() ? "" : " (did you mean \"" + near + "\"?)"));
    }
    return value;
}

JsonReader JsonReader::object(const std::string& key) {
    if (!has(key)) fail_missing(key, "a JSON object");
    const nlohmann::json& v = raw(key);
    if (!v.is_object()) fail(key, "expected a JSON object, got " + v.dump());
    if (resolved_ && !resolved_->contains(where_ / key)) (*resolved_)[where_ / key] = v;
    return child(v, key_path(key), where_ / key);
}

JsonReader JsonReader::optional_object(const std::string& key) {
    static const nlohmann::json empty = nlohmann::json::object();
    if (has(key)) return object(key);
    if (resolved_ && !resolved_->contains(where_ / key)) (*resolved_)[where_ / key] = nlohmann::json::object();
    return child(empty, key_path(key), where_ / key);
}

std::vector<JsonReader> JsonReader::objects(const std::string& key) {
    if (!has(key)) fail_missing(key, "an array of objects");
    const nlohmann::json& v = raw(key);
    if (!v.is_array()) fail(key, "expected an array of objects, got " + v.dump());
    if (resolved_ && !resolved_->contains(where_ / key)) (*resolved_)[where_ / key] = v;
    std::vector<JsonReader> out;
    for (size_t i = 0; i < v.size(); ++i) {
        const std::string p = key_path(key) + "[" + std::to_string(i) + "]";
        if (!v[i].is_object()) throw ConfigError(file_ + ": key '" + p + "': expected an object, got " + v[i].dump());
        out.push_back(child(v[i], p, where_ / key / i));
    }
    return out;
}

void JsonReader::finish(const std::vector<std::string>& also_allowed) const {
    std::vector<std::string> known = known_;
    known.insert(known.end(), also_allowed.begin(), also_allowed.end());
    for (const auto& [key, v] : value_.items()) {
        if (std::find(known.begin(), known.end(), key) != known.end()) continue;
        const std::string near = nearest_match(key, known);
        std::string list;
        for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
        throw ConfigError(file_ + ": unknown key '" + key_path(key) + "'" +
                          (near.empty() ? "" : "; did you mean '" + near + "'?") +
                          (list.empty() ? "" : " (valid here: " + list + ")"));
    }
}

int edit_distance(const std::string& a, const std::string& b) {
    std::vector<int> row(b.size() + 1);
    for (size_t j = 0; j <= b.size(); ++j) row[j] = int(j);
    for (size_t i = 1; i <= a.size(); ++i) {
        int diag = row[0];
        row[0] = int(i);
        for (size_t j = 1; j <= b.size(); ++j) {
            const int up = row[j];
            row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
            diag = up;
        }
    }
    return row[b.size()];
}

std::string nearest_match(const std::string& word, const std::vector<std::string>& candidates) {
    std::string best;
    int best_d = 1 << 30;
    for (const auto& c : candidates) {
        const int d = edit_distance(word, c);
        if (d < best_d) { best_d = d; best = c; }
    }
    // A typo changes a few characters; beyond that a suggestion would only confuse.
    return best_d <= std::max<int>(2, int(word.size()) / 3) ? best : "";
}

}  // namespace sdf
