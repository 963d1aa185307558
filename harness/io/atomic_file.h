/// @file atomic_file.h
/// @brief Files and directories that appear whole or not at all, and never silently
/// replace an existing result.
///
/// A file is written to a temporary name in the target's directory (unique per process,
/// thread and call), flushed to disk (fsync), then renamed into place. Without permission to
/// overwrite, the rename is renameat2(RENAME_NOREPLACE) (or link + unlink where the file
/// system lacks it), so an existing file is never replaced, even by a concurrent writer. The
/// temporary is removed on every failure.
#pragma once

#include <functional>
#include <string>

namespace sdf {

enum class Overwrite { Forbid, Allow };

/// Writes `size` bytes to `path` atomically. Throws if `path` exists and overwriting is
/// forbidden, naming the file.
void write_file_atomically(const std::string& path, const void* data, size_t size,
                           Overwrite overwrite = Overwrite::Forbid);
void write_text_atomically(const std::string& path, const std::string& text,
                           Overwrite overwrite = Overwrite::Forbid);

/// Writes `path` atomically through `write`, a writer that takes a file name (a library's:
/// OpenVDB's io::File), which is given a temporary name beside `path`; the temporary is then
/// flushed to disk (fsync) and placed as write_file_atomically() places its own. Refuses an
/// existing `path` before calling `write` unless overwriting is allowed. The temporary is
/// removed on every failure, `write`'s own included.
void write_through_temporary(const std::string& path, Overwrite overwrite,
                             const std::function<void(const std::string& temporary)>& write);

/// Renames `from` to `to` unless `to` exists (file or directory, empty or not): returns false
/// then and leaves both alone. Other failures throw, naming both paths.
bool rename_no_replace(const std::string& from, const std::string& to);

/// A directory filled under a hidden temporary name beside its final path and renamed into
/// place by commit(). If it is destroyed without commit() (an error, an interrupt), the
/// partial directory is removed, so nothing half-written is ever left under the final name.
/// The final path is normalised ("runs/r5/" is "runs/r5").
class StagedDirectory {
public:
    explicit StagedDirectory(std::string final_path);
    ~StagedDirectory();
    StagedDirectory(const StagedDirectory&) = delete;
    StagedDirectory& operator=(const StagedDirectory&) = delete;

    /// Where to write while staging.
    const std::string& path() const { return staging_; }
    const std::string& final_path() const { return final_; }
    /// Atomically moves the staged directory to its final name, which must not exist (an
    /// existing directory, even an empty one, is never replaced): throws if it does.
    void commit();
    /// As commit(), but to `final_path` (a sibling of the staging directory's parent is not
    /// allowed: it must be in the same directory as the original final path); returns false,
    /// without committing, when that name is taken.
    bool try_commit_as(const std::string& final_path);

private:
    std::string final_, staging_;
    bool committed_ = false;
};

/// Whether process `pid` still runs: it exists and is not a zombie (a killed process whose
/// parent has not reaped it yet has written its last byte).
bool process_is_running(long pid);

/// Removes what interrupted writers left in `dir`: temporaries and staging directories
/// (unique_sibling_name) whose process is no longer running. Returns how many were removed.
int remove_stale_staging(const std::string& dir);

/// A name for a temporary file or directory beside `path`: ".<name>.<tag>.<pid>.<n>" with n
/// unique within this process (so threads never collide).
std::string unique_sibling_name(const std::string& path, const std::string& tag);

/// fsync of a complete file written by another writer (a library's), before it is renamed
/// into place. Throws naming `path` when it fails.
void sync_file(const std::string& path);

/// Checks, before any work, that `path` can be written: its folder exists and is writable,
/// `path` is not a folder, and it does not exist unless overwriting is allowed. Throws
/// std::runtime_error naming `path` and what is wrong.
void require_writable_target(const std::string& path, Overwrite overwrite);

/// The crash-safety tests' hook (tests/harness/atomic_replacement_test.cpp): every step of a
/// commit that another step must not be separated from calls it. With SDF_FAULT_AT=k in the
/// environment, the k-th call of the process (1-based) throws std::runtime_error("injected
/// failure at step k: `step`"), or with SDF_FAULT_MODE=kill ends the process with SIGKILL, as
/// a crash or the OOM killer would. Without SDF_FAULT_AT it does nothing.
void fault_point(const std::string& step);

}  // namespace sdf
