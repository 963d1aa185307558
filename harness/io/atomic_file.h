/// @file atomic_file.h
/// @brief Files and directories that appear whole or not at all, and never silently
/// replace an existing result.
#pragma once

#include <string>

namespace sdf {

enum class Overwrite { Forbid, Allow };

/// Writes `size` bytes to `path` through a temporary file in the same directory and a
/// rename. Throws if `path` exists and overwriting is forbidden, naming the file.
void write_file_atomically(const std::string& path, const void* data, size_t size,
                           Overwrite overwrite = Overwrite::Forbid);
void write_text_atomically(const std::string& path, const std::string& text,
                           Overwrite overwrite = Overwrite::Forbid);

/// A directory filled under a hidden temporary name and renamed into place by commit().
/// If it is destroyed without commit() (an error, an interrupt), the partial directory is
/// removed, so nothing half-written is ever left under the final name.
class StagedDirectory {
public:
    explicit StagedDirectory(std::string final_path);
    ~StagedDirectory();
    StagedDirectory(const StagedDirectory&) = delete;
    StagedDirectory& operator=(const StagedDirectory&) = delete;

    /// Where to write while staging.
    const std::string& path() const { return staging_; }
    const std::string& final_path() const { return final_; }
    /// Atomically moves the staged directory to its final name (which must not exist).
    void commit();

private:
    std::string final_, staging_;
    bool committed_ = false;
};

}  // namespace sdf
