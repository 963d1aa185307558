#include "harness/io/atomic_file.h"

#include <fcntl.h>
#include <stdio.h>
#include <sys/stat.h>
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <stdexcept>

namespace sdf {
namespace fs = std::filesystem;

namespace {

std::string errno_text(int e) { return std::strerror(e); }

/// Writes everything to `fd`, retrying short writes; returns errno or 0.
int write_all(int fd, const char* data, size_t size) {
    while (size > 0) {
        const ssize_t n = ::write(fd, data, size);
        if (n < 0) {
            if (errno == EINTR) continue;
            return errno;
        }
        data += n;
        size -= size_t(n);
    }
    return 0;
}

/// fsync of the directory holding `path`, so a rename into it survives a crash (best effort).
void sync_parent_directory(const std::string& path) {
    const fs::path parent = fs::path(path).parent_path();
    const int fd = ::open(parent.empty() ? "." : parent.c_str(), O_RDONLY | O_DIRECTORY);
    if (fd < 0) return;
    ::fsync(fd);
    ::close(fd);
}

/// Normalised, without a trailing separator: "runs/r5/" and "runs/./r5" are "runs/r5".
std::string normalised(const std::string& path) {
    fs::path p = fs::path(path).lexically_normal();
    if (p.filename().empty() && p.has_parent_path()) p = p.parent_path();
    return p.string();
}

}  // namespace

void fault_point(const std::string& step) {
    static const long at = [] {
        const char* v = std::getenv("SDF_FAULT_AT");
        return v && *v ? std::strtol(v, nullptr, 10) : 0L;
    }();
    if (at <= 0) return;
    static std::atomic<long> calls{0};
    if (calls.fetch_add(1) + 1 != at) return;
    const char* mode = std::getenv("SDF_FAULT_MODE");
    if (mode && std::string(mode) == "kill") ::raise(SIGKILL);
    throw std::runtime_error("injected failure at step " + std::to_string(at) + ": " + step);
}

void sync_file(const std::string& path) {
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) throw std::runtime_error(path + ": cannot open to sync (" + errno_text(errno) + ")");
    const int e = ::fsync(fd) == 0 ? 0 : errno;
    ::close(fd);
    if (e != 0) throw std::runtime_error(path + ": fsync failed (" + errno_text(e) + ")");
}

void require_writable_target(const std::string& path, Overwrite overwrite) {
    const fs::path target = fs::absolute(path);
    const fs::path dir = target.parent_path();
    std::error_code ec;
    if (!fs::is_directory(dir, ec))
        throw std::runtime_error(path + ": the folder " + dir.string() + " does not exist (or is not a folder)");
    if (::access(dir.c_str(), W_OK | X_OK) != 0)
        throw std::runtime_error(path + ": the folder " + dir.string() + " is not writable (" + errno_text(errno) + ")");
    if (fs::is_directory(target, ec)) throw std::runtime_error(path + ": is a folder; expected a file name");
    if (overwrite == Overwrite::Forbid && fs::exists(target, ec))
        throw std::runtime_error(path + ": already exists; refusing to overwrite it");
}

std::string unique_sibling_name(const std::string& path, const std::string& tag) {
    static std::atomic<unsigned long> counter{0};
    const fs::path p(path);
    const std::string name = "." + p.filename().string() + "." + tag + "." + std::to_string(::getpid()) + "." +
                             std::to_string(counter.fetch_add(1));
    return (p.parent_path() / name).string();
}

bool process_is_running(long pid) {
    if (pid <= 0) return false;
    if (::kill(pid_t(pid), 0) != 0 && errno != EPERM) return false;
    // "pid (comm) S ...": the state follows the last ')' (comm may hold spaces and parentheses).
    std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
    std::string text((std::istreambuf_iterator<char>(stat)), std::istreambuf_iterator<char>());
    const size_t close = text.rfind(')');
    return close == std::string::npos || close + 2 >= text.size() || text[close + 2] != 'Z';
}

int remove_stale_staging(const std::string& dir) {
    static const std::regex pattern(R"(\..+\.(tmp|partial)\.([0-9]+)\.[0-9]+)");
    int removed = 0;
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) return 0;
    for (const auto& e : fs::directory_iterator(dir, ec)) {
        std::smatch m;
        const std::string name = e.path().filename().string();
        if (!std::regex_match(name, m, pattern)) continue;
        const pid_t pid = pid_t(std::stol(m[2].str()));
        if (process_is_running(pid)) continue;
        std::error_code rm;
        fs::remove_all(e.path(), rm);
        if (!rm) ++removed;
    }
    return removed;
}

bool rename_no_replace(const std::string& from, const std::string& to) {
    if (::renameat2(AT_FDCWD, from.c_str(), AT_FDCWD, to.c_str(), RENAME_NOREPLACE) == 0) return true;
    int e = errno;
    if (e == EEXIST) return false;
    if (e == EINVAL || e == ENOSYS || e == ENOTSUP) {
        // No RENAME_NOREPLACE on this file system: link() refuses an existing target too
        // (files only; a directory falls back to a checked rename).
        struct stat st {};
        if (::stat(from.c_str(), &st) == 0 && S_ISDIR(st.st_mode)) {
            if (fs::exists(to)) return false;
            if (::rename(from.c_str(), to.c_str()) == 0) return true;
            e = errno;
        } else if (::link(from.c_str(), to.c_str()) == 0) {
            ::unlink(from.c_str());
            return true;
        } else {
            e = errno;
            if (e == EEXIST) return false;
        }
    }
    throw std::runtime_error("cannot rename " + from + " to " + to + ": " + errno_text(e));
}

namespace {

std::runtime_error refusal(const std::string& path) {
    return std::runtime_error(path + ": already exists; refusing to overwrite it (choose another output or "
                                     "remove the file)");
}

/// Renames the complete, synced temporary `tmp` to `path` (never over an existing file unless
/// overwriting is allowed) and syncs the folder; removes `tmp` when it cannot be placed.
void place(const std::string& tmp, const std::string& path, Overwrite overwrite) {
    try {
        fault_point("rename " + path + " into place");
        if (overwrite == Overwrite::Forbid) {
            if (!rename_no_replace(tmp, path)) throw refusal(path);
        } else if (::rename(tmp.c_str(), path.c_str()) != 0) {
            throw std::runtime_error(path + ": cannot move the written file into place: " + errno_text(errno));
        }
    } catch (...) {
        ::unlink(tmp.c_str());
        throw;
    }
    sync_parent_directory(path);
}

/// The checks before writing `path`: not there unless it may be replaced; its folder made.
void prepare_target(const std::string& path, Overwrite overwrite) {
    if (overwrite == Overwrite::Forbid && fs::exists(path)) throw refusal(path);
    const fs::path target(path);
    if (target.has_parent_path()) fs::create_directories(target.parent_path());
}

}  // namespace

void write_file_atomically(const std::string& path, const void* data, size_t size, Overwrite overwrite) {
    prepare_target(path, overwrite);
    const std::string tmp = unique_sibling_name(path, "tmp");
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    if (fd < 0) throw std::runtime_error(tmp + ": cannot open for writing: " + errno_text(errno));
    int e = write_all(fd, static_cast<const char*>(data), size);
    if (e == 0 && ::fsync(fd) != 0) e = errno;
    if (::close(fd) != 0 && e == 0) e = errno;
    if (e != 0) {
        ::unlink(tmp.c_str());
        throw std::runtime_error(path + ": write failed: " + errno_text(e));
    }
    place(tmp, path, overwrite);
}

void write_through_temporary(const std::string& path, Overwrite overwrite,
                             const std::function<void(const std::string& temporary)>& write) {
    prepare_target(path, overwrite);
    const std::string tmp = unique_sibling_name(path, "tmp");
    try {
        write(tmp);
        sync_file(tmp);
    } catch (...) {
        ::unlink(tmp.c_str());
        throw;
    }
    place(tmp, path, overwrite);
}

void write_text_atomically(const std::string& path, const std::string& text, Overwrite overwrite) {
    write_file_atomically(path, text.data(), text.size(), overwrite);
}

StagedDirectory::StagedDirectory(std::string final_path) : final_(normalised(final_path)) {
    if (fs::exists(final_))
        throw std::runtime_error(final_ + ": already exists; refusing to overwrite a result directory");
    staging_ = unique_sibling_name(final_, "partial");
    fs::create_directories(staging_);
}

StagedDirectory::~StagedDirectory() {
    if (!committed_) {
        std::error_code ec;
        fs::remove_all(staging_, ec);
    }
}

void StagedDirectory::commit() {
    if (!try_commit_as(final_))
        throw std::runtime_error(final_ + ": appeared while this run was writing; refusing to overwrite it");
}

bool StagedDirectory::try_commit_as(const std::string& final_path) {
    if (committed_) throw std::logic_error(final_ + ": StagedDirectory committed twice");
    const std::string target = normalised(final_path);
    if (fs::path(target).parent_path() != fs::path(final_).parent_path())
        throw std::logic_error(target + ": not in the same directory as " + final_);
    if (!rename_no_replace(staging_, target)) return false;
    final_ = target;
    committed_ = true;
    sync_parent_directory(final_);
    return true;
}

}  // namespace sdf
