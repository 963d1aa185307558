#include "harness/cache/content_cache.h"

#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <unistd.h>

#include "core/mesh/sha256.h"
#include "harness/build_config.h"
#include "harness/config/json_reader.h"
#include "harness/io/atomic_file.h"
#include "harness/provenance/provenance.h"

namespace sdf {
namespace fs = std::filesystem;

ContentCache::ContentCache(std::string root) : root_(std::move(root)) {}

std::string ContentCache::default_root() {
    if (const char* env = std::getenv("SDF_CACHE_DIR"); env && *env) return env;
    return (fs::path(SDF_SOURCE_DIR) / "cache").string();
}

void ContentCache::require_usable_root(const std::string& root, const std::string& option) {
    std::error_code ec;
    // The root, or else the nearest of its ancestors that exists, must be a directory.
    for (fs::path p = fs::absolute(root, ec); !p.empty(); p = p.parent_path()) {
        const fs::file_status status = fs::status(p, ec);
        if (status.type() == fs::file_type::not_found) {
            if (p == p.parent_path()) break;
            continue;
        }
        // A directory, or a path that cannot be examined (the write will say why, if it fails).
        if (status.type() == fs::file_type::directory || status.type() == fs::file_type::none ||
            status.type() == fs::file_type::unknown)
            return;
        const bool is_root = p == fs::absolute(root, ec);
        throw std::runtime_error(option + " " + root + ": " + (is_root ? "" : p.string() + " ") +
                                 (status.type() == fs::file_type::regular ? "is a regular file" : "is not a directory") +
                                 "; expected a directory for the field cache (or a path where one can be made)");
    }
}

std::string ContentCache::key_hash(const nlohmann::json& key) {
    const std::string text = key.dump();
    return sha256_hex(text.data(), text.size());
}

std::string ContentCache::entry_path(const std::string& kind, const nlohmann::json& key) const {
    const std::string h = key_hash(key);
    return (fs::path(root_) / kind / h.substr(0, 2) / h).string();
}

namespace {

/// Size and SHA-256 of every regular file under `dir` except entry.json, by relative path.
nlohmann::json file_checksums(const std::string& dir) {
    nlohmann::json files = nlohmann::json::object();
    for (const fs::directory_entry& e : fs::recursive_directory_iterator(dir)) {
        if (!e.is_regular_file()) continue;
        const std::string name = fs::relative(e.path(), dir).generic_string();
        if (name == "entry.json") continue;
        files[name] = {{"bytes", e.file_size()}, {"sha256", sha256_of_file(e.path().string())}};
    }
    return files;
}

}  // namespace

bool ContentCache::has_entry(const std::string& kind, const nlohmann::json& key) const {
    return fs::is_regular_file(fs::path(entry_path(kind, key)) / "entry.json");
}

std::string ContentCache::verification_failure(const std::string& dir, const nlohmann::json& key) {
    const fs::path record_path = fs::path(dir) / "entry.json";
    if (!fs::is_regular_file(record_path)) return "entry.json is missing";
    nlohmann::json record;
    try {
        record = read_json_file(record_path.string(), "cache entry record");
    } catch (const std::exception& e) {
        return std::string("entry.json is unreadable: ") + e.what();
    }
    if (!record.is_object() || !record.contains("key") || record["key"] != key)
        return "entry.json does not hold the key of this entry";
    if (!record.contains("files") || !record["files"].is_object())
        return "entry.json lists no file checksums (written by an older version)";
    nlohmann::json actual;
    try {
        actual = file_checksums(dir);
    } catch (const std::exception& e) {
        return std::string("its files cannot be read: ") + e.what();
    }
    for (const auto& [name, expected] : record["files"].items()) {
        if (!actual.contains(name)) return name + " is missing";
        if (actual[name]["bytes"] != expected.value("bytes", nlohmann::json()))
            return name + " has " + actual[name]["bytes"].dump() + " bytes, expected " + expected.value("bytes", nlohmann::json()).dump();
        if (actual[name]["sha256"] != expected.value("sha256", nlohmann::json()))
            return name + " has SHA-256 " + actual[name]["sha256"].get<std::string>() + ", recorded " +
                   expected.value("sha256", std::string("none"));
    }
    for (const auto& [name, _] : actual.items())
        if (!record["files"].contains(name)) return name + " is not part of the entry";
    return "";
}

std::optional<std::string> ContentCache::find(const std::string& kind, const nlohmann::json& key) const {
    const std::string dir = entry_path(kind, key);
    if (!fs::exists(dir)) return std::nullopt;
    const std::string why = verification_failure(dir, key);
    if (why.empty()) return dir;
    // Moved aside, not deleted: the bytes stay for inspection, and a reader in another
    // process keeps its open files. If another process moved it first, the rename fails
    // harmlessly.
    const std::string aside = dir + ".damaged-" + compact_utc_timestamp() + "-" + std::to_string(::getpid());
    std::error_code ec;
    fs::rename(dir, aside, ec);
    std::cerr << "warning: cache entry " << dir << " failed verification (" << why << "); "
              << (ec ? "it could not be moved aside (" + ec.message() + ")" : "moved to " + aside)
              << "; computing it again\n";
    if (ec && fs::exists(dir)) throw std::runtime_error("cache entry " + dir + " is damaged (" + why +
                                                        ") and cannot be moved aside; remove it or run with --no-cache");
    return std::nullopt;
}

nlohmann::json ContentCache::entry_record(const std::string& kind, const nlohmann::json& key) const {
    return read_json_file((fs::path(entry_path(kind, key)) / "entry.json").string());
}

bool ContentCache::store(const std::string& kind, const nlohmann::json& key, const nlohmann::json& info,
                         const std::function<void(const std::string& dir)>& write) const {
    const std::string dir = entry_path(kind, key);
    if (fs::exists(dir)) return false;
    remove_stale_staging(fs::path(dir).parent_path().string());
    std::optional<StagedDirectory> staged;
    try {
        staged.emplace(dir);
    } catch (const std::exception&) {
        if (fs::exists(dir)) return false;  // filled meanwhile by another process
        throw;
    }
    write(staged->path());
    const nlohmann::json record = {{"key", key}, {"info", info}, {"created", utc_timestamp()},
                                   {"files", file_checksums(staged->path())}};
    write_text_atomically(staged->path() + "/entry.json", record.dump(2) + "\n");
    return staged->try_commit_as(dir);
}

}  // namespace sdf
