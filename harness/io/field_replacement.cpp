#include "harness/io/field_replacement.h"

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

namespace sdf {
namespace fs = std::filesystem;

namespace {

/// The channels a field file of the project may have (field_channel_files' names, then the
/// sparse band's own: sparse_field_file.h).
constexpr const char* kChannelNames[] = {"distance",     "gradient",   "closest_triangle", "active_blocks",
                                         "mixed_blocks", "tile_signs", "mixed_signs"};

/// NAME of NAME.json (the file name, without the folder).
std::string field_name(const std::string& header_path) {
    std::string name = fs::path(header_path).filename().string();
    if (name.size() > 5 && name.compare(name.size() - 5, 5, ".json") == 0) name.resize(name.size() - 5);
    return name;
}

/// A tag "w<pid>-<n>": the writing process (so that a later run can tell an interrupted
/// writer's leftovers from a live writer's files) and a number unique within it.
std::string write_tag(unsigned long n) { return "w" + std::to_string(::getpid()) + "-" + std::to_string(n); }

/// The pid of a tag "w<pid>-<n>"; 0 when `tag` is not one.
long tag_pid(const std::string& tag) {
    const size_t dash = tag.find('-');
    if (tag.size() < 4 || tag[0] != 'w' || dash == std::string::npos || dash < 2 || dash + 1 == tag.size()) return 0;
    for (size_t i = 1; i < tag.size(); ++i)
        if (i != dash && !std::isdigit(static_cast<unsigned char>(tag[i]))) return 0;
    return std::stol(tag.substr(1, dash - 1));
}

/// The tag of a channel file name of the field: "" for NAME.<channel>.raw, the tag of
/// NAME.<channel>.<tag>.raw; nullopt-like "?" for any other name.
std::string channel_name_tag(const std::string& name, const std::string& file) {
    const std::string suffix = ".raw";
    if (file.size() <= name.size() + 1 + suffix.size() || file.compare(0, name.size() + 1, name + ".") != 0 ||
        file.compare(file.size() - suffix.size(), suffix.size(), suffix) != 0)
        return "?";
    const std::string middle = file.substr(name.size() + 1, file.size() - name.size() - 1 - suffix.size());
    for (const char* channel : kChannelNames) {
        const std::string c = channel;
        if (middle == c) return "";
        if (middle.size() > c.size() + 1 && middle.compare(0, c.size() + 1, c + ".") == 0) {
            const std::string tag = middle.substr(c.size() + 1);
            return tag_pid(tag) > 0 ? tag : "?";
        }
    }
    return "?";
}

/// The channel files (folder-relative names) the header at `path` names; empty when it is
/// missing or unreadable (its files are then left alone).
std::vector<std::string> files_named_by(const std::string& path) {
    std::vector<std::string> files;
    std::ifstream in(path);
    if (!in) return files;
    const nlohmann::json header = nlohmann::json::parse(in, nullptr, false);
    if (!header.is_object() || !header.contains("channels") || !header["channels"].is_object()) return files;
    for (const auto& [name, channel] : header["channels"].items())
        if (channel.is_object() && channel.contains("file") && channel["file"].is_string())
            files.push_back(channel["file"].get<std::string>());
    return files;
}

/// fsync of a folder, so that renames and removals in it survive a crash (best effort).
void sync_folder(const fs::path& dir) {
    const int fd = ::open(dir.empty() ? "." : dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd < 0) return;
    ::fsync(fd);
    ::close(fd);
}

}  // namespace

bool is_field_channel_name(const std::string& header_path, const std::string& file) {
    return channel_name_tag(field_name(header_path), file) != "?";
}

FieldReplacement::FieldReplacement(std::string header_path, std::vector<FieldChannelFile> channels, Overwrite overwrite)
    : header_(std::move(header_path)), channels_(std::move(channels)), overwrite_(overwrite), placed_(channels_.size()) {
    if (header_.size() < 5 || header_.compare(header_.size() - 5, 5, ".json") != 0) header_ += ".json";  // as write_field
    require_writable_target(header_, overwrite_);
    const std::vector<std::string> old = files_named_by(header_);
    static std::atomic<unsigned long> counter{0};
    for (FieldChannelFile& c : channels_) {
        const std::string plain = fs::path(c.path).filename().string();
        const bool taken = fs::exists(c.path) || std::find(old.begin(), old.end(), plain) != old.end();
        if (!taken) continue;
        if (overwrite_ == Overwrite::Forbid)
            throw std::runtime_error(c.path + ": already exists; refusing to overwrite a field");
        // The old field keeps its files until the new header replaces it: a name of our own.
        const std::string base = c.path.substr(0, c.path.size() - 4);  // without ".raw"
        do c.path = base + "." + write_tag(counter.fetch_add(1)) + ".raw";
        while (fs::exists(c.path));
    }
}

FieldReplacement::~FieldReplacement() {
    if (committed_) return;
    for (size_t i = 0; i < channels_.size(); ++i)
        if (placed_[i]) ::unlink(channels_[i].path.c_str());  // ours, named by no header
}

void FieldReplacement::place(size_t i, const std::string& staged) {
    fault_point("rename " + staged + " to " + channels_.at(i).path);
    if (!rename_no_replace(staged, channels_[i].path))
        throw std::runtime_error(channels_[i].path + ": appeared while this field was written; refusing to overwrite it");
    placed_[i] = true;
}

void FieldReplacement::placed(size_t i) { placed_.at(i) = true; }

void FieldReplacement::commit(const SampledField& field) {
    commit_with([&](const std::vector<FieldChannelFile>& channels) { write_field_header(header_, field, channels, overwrite_); });
}

void FieldReplacement::commit_with(const std::function<void(const std::vector<FieldChannelFile>&)>& write_header) {
    if (committed_) throw std::logic_error(header_ + ": FieldReplacement committed twice");
    for (size_t i = 0; i < channels_.size(); ++i)
        if (!placed_[i]) throw std::logic_error(channels_[i].path + ": committed before it was written");
    const fs::path dir = fs::absolute(header_).parent_path();
    sync_folder(dir);  // the channels' names are durable before the header names them
    const std::vector<std::string> old = files_named_by(header_);  // the field being replaced
    write_header(channels_);  // the commit point
    committed_ = true;
    if (overwrite_ == Overwrite::Forbid) return;  // nothing was there to replace
    // The old field's channel files, and those of interrupted writers of this name (their
    // process gone); never another live writer's, nor a file this header names.
    const std::string name = field_name(header_);
    std::vector<std::string> keep;
    for (const FieldChannelFile& c : channels_) keep.push_back(fs::path(c.path).filename().string());
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(dir, ec)) {
        const std::string file = entry.path().filename().string();
        const std::string tag = channel_name_tag(name, file);
        if (tag == "?" || std::find(keep.begin(), keep.end(), file) != keep.end()) continue;
        const bool was_old = std::find(old.begin(), old.end(), file) != old.end();
        if (!was_old && !tag.empty() && tag_pid(tag) != long(::getpid()) && process_is_running(tag_pid(tag))) continue;
        fault_point("remove " + entry.path().string());
        std::error_code rm;
        fs::remove(entry.path(), rm);
    }
    sync_folder(dir);
}

}  // namespace sdf
