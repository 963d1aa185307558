/// @file content_cache.h
/// @brief A content-addressed store of computed results on disk: an entry is a directory
/// named by the SHA-256 of a JSON key that describes exactly what was computed (inputs,
/// parameters, code version), so equal keys mean interchangeable results.
///
///   <root>/<kind>/<hh>/<sha256>/entry.json     {"key", "info", "created", "files"}
///   <root>/<kind>/<hh>/<sha256>/...            the entry's own files
///
/// Entries appear whole or not at all (StagedDirectory) and are never replaced: when two
/// processes fill the same entry, the first one wins and the second is discarded. The root
/// is $SDF_CACHE_DIR, else <repo>/cache (git-ignored).
///
/// Integrity: entry.json lists every file of the entry with its size and SHA-256, and find()
/// checks them (and that the stored key is the key asked for) before an entry is used. An
/// entry that fails - flipped bytes, a truncated or missing file, a missing or unreadable
/// entry.json, no checksums (an older cache) - is moved aside to "<dir>.damaged-<time>-<pid>"
/// with a warning naming it and why, and counts as absent: the caller computes the result
/// again and store() fills the entry anew, so a damaged entry is repaired once, not
/// recomputed forever.
#pragma once

#include <functional>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

namespace sdf {

class ContentCache {
public:
    explicit ContentCache(std::string root);
    /// $SDF_CACHE_DIR when set and not empty, else <repo>/cache.
    static std::string default_root();

    const std::string& root() const { return root_; }
    /// Refuses (std::runtime_error naming `root` and `option`) a cache root that cannot hold
    /// entries: a path that is not a directory, or under something that is not one. Checked
    /// when a run is planned, before anything is sampled (a cache is written after sampling).
    static void require_usable_root(const std::string& root, const std::string& option);
    static std::string key_hash(const nlohmann::json& key);
    std::string entry_path(const std::string& kind, const nlohmann::json& key) const;

    /// Whether the entry's entry.json exists (cheap: for plans and dry runs; find() verifies).
    bool has_entry(const std::string& kind, const nlohmann::json& key) const;
    /// The entry's directory when it exists and passes verification, else nullopt (a damaged
    /// entry is moved aside with a warning on stderr, as described above).
    std::optional<std::string> find(const std::string& kind, const nlohmann::json& key) const;
    /// Why the entry at `dir` cannot be used for `key` ("" when it can): its entry.json, key
    /// and files' sizes and SHA-256.
    static std::string verification_failure(const std::string& dir, const nlohmann::json& key);
    /// The entry's entry.json ("key", "info", "created").
    nlohmann::json entry_record(const std::string& kind, const nlohmann::json& key) const;

    /// Creates the entry: `write` fills a staging directory, then entry.json is added and
    /// the directory is moved into place. Returns false (discarding what was written) when
    /// the entry already exists.
    bool store(const std::string& kind, const nlohmann::json& key, const nlohmann::json& info,
               const std::function<void(const std::string& dir)>& write) const;

private:
    std::string root_;
};

}  // namespace sdf
