// Scratch directories for tests that write files: a fresh directory under the system's
// temporary directory, named after the process and the running test so that tests run in
// parallel (ctest -j) never share one, and removed afterwards. Used by the tests of several
// folders; tests/harness/harness_test_util.h builds on it.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <utility>

namespace sdf::test {

/// The whole file, bytes as they are ("" when it cannot be read).
inline std::string read_text(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

/// Writes `text` to `p` (binary), creating its parent directories; returns `p` as a string.
inline std::string write_file(const std::filesystem::path& p, const std::string& text) {
    std::filesystem::create_directories(p.parent_path());
    std::ofstream(p, std::ios::binary) << text;
    return p.string();
}

/// <temp>/<prefix>_<pid>_<test name>; the '/' of parameterized test names becomes '_'.
inline std::filesystem::path test_scratch_path(const std::string& prefix) {
    std::string test = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    std::replace(test.begin(), test.end(), '/', '_');
    return std::filesystem::temp_directory_path() / (prefix + "_" + std::to_string(::getpid()) + "_" + test);
}

/// A fixture with a scratch directory `dir_` per test. `create` = false leaves it absent
/// (for code that must create it itself).
class ScratchDirTest : public ::testing::Test {
protected:
    explicit ScratchDirTest(std::string prefix, bool create = true) : prefix_(std::move(prefix)), create_(create) {}

    void SetUp() override {
        dir_ = test_scratch_path(prefix_);
        std::filesystem::remove_all(dir_);
        if (create_) std::filesystem::create_directories(dir_);
    }
    void TearDown() override { std::filesystem::remove_all(dir_); }

    std::string at(const std::string& rel) const { return (dir_ / rel).string(); }
    std::string write(const std::string& rel, const std::string& text) const { return write_file(dir_ / rel, text); }

    std::filesystem::path dir_;

private:
    std::string prefix_;
    bool create_;
};

/// The same directory for one test body (TEST rather than TEST_F), removed by the destructor.
class ScratchDir {
public:
    explicit ScratchDir(const std::string& prefix) : path_(test_scratch_path(prefix)) {
        std::filesystem::remove_all(path_);
        std::filesystem::create_directories(path_);
    }
    ~ScratchDir() { std::filesystem::remove_all(path_); }
    ScratchDir(const ScratchDir&) = delete;
    ScratchDir& operator=(const ScratchDir&) = delete;

    const std::filesystem::path& path() const { return path_; }
    std::string at(const std::string& rel) const { return (path_ / rel).string(); }
    std::string write(const std::string& rel, const std::string& text) const { return write_file(path_ / rel, text); }

private:
    std::filesystem::path path_;
};

}  // namespace sdf::test
