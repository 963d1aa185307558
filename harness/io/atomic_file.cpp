#include "harness/io/atomic_file.h"

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace sdf {
namespace fs = std::filesystem;

void write_file_atomically(const std::string& path, const void* data, size_t size, Overwrite overwrite) {
    if (overwrite == Overwrite::Forbid && fs::exists(path))
        throw std::runtime_error(path + ": already exists; refusing to overwrite it (choose another output or "
                                        "remove the file)");
    const fs::path target(path);
    if (target.has_parent_path()) fs::create_directories(target.parent_path());
    const std::string tmp = path + ".tmp." + std::to_string(::getpid());
    {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        if (!out) throw std::runtime_error(tmp + ": cannot open for writing");
        out.write(static_cast<const char*>(data), std::streamsize(size));
        out.flush();
        if (!out) {
            std::remove(tmp.c_str());
            throw std::runtime_error(path + ": write failed (disk full?)");
        }
    }
    fs::rename(tmp, path);
}

void write_text_atomically(const std::string& path, const std::string& text, Overwrite overwrite) {
    write_file_atomically(path, text.data(), text.size(), overwrite);
}

StagedDirectory::StagedDirectory(std::string final_path) : final_(std::move(final_path)) {
    if (fs::exists(final_))
        throw std::runtime_error(final_ + ": already exists; refusing to overwrite a result directory");
    const fs::path p(final_);
    staging_ = (p.parent_path() / ("." + p.filename().string() + ".partial." + std::to_string(::getpid()))).string();
    fs::create_directories(staging_);
}

StagedDirectory::~StagedDirectory() {
    if (!committed_) {
        std::error_code ec;
        fs::remove_all(staging_, ec);
    }
}

void StagedDirectory::commit() {
    if (fs::exists(final_))
        throw std::runtime_error(final_ + ": appeared while this run was writing; refusing to overwrite it");
    fs::rename(staging_, final_);
    committed_ = true;
}

}  // namespace sdf
