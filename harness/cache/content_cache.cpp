#include "harness/cache/content_cache.h"

#include <cstdlib>
#include <filesystem>

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

std::string ContentCache::key_hash(const nlohmann::json& key) {
    const std::string text = key.dump();
    return sha256_hex(text.data(), text.size());
}

std::string ContentCache::entry_path(const std::string& kind, const nlohmann::json& key) const {
    const std::string h = key_hash(key);
    return (fs::path(root_) / kind / h.substr(0, 2) / h).string();
}

std::optional<std::string> ContentCache::find(const std::string& kind, const nlohmann::json& key) const {
    const std::string dir = entry_path(kind, key);
    if (fs::is_regular_file(fs::path(dir) / "entry.json")) return dir;
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
    const nlohmann::json record = {{"key", key}, {"info", info}, {"created", utc_timestamp()}};
    write_text_atomically(staged->path() + "/entry.json", record.dump(2) + "\n");
    return staged->try_commit_as(dir);
}

}  // namespace sdf
