// Shared helpers of the harness tests: the scratch-directory fixture and the shell runner
// (tests/test_util), a substring assertion with a readable failure, the message of what a
// call throws, JSON files read back, and directory listings.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <exception>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "tests/test_util/scratch_dir.h"
#include "tests/test_util/shell.h"

namespace sdf::test {

/// EXPECT_TRUE(Contains(text, part)) prints both strings when `part` is missing.
inline ::testing::AssertionResult Contains(const std::string& text, const std::string& part) {
    if (text.find(part) != std::string::npos) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << "\"" << text << "\"\n  does not contain \"" << part << "\"";
}

/// Runs `f` and returns what it throws (any std::exception); fails the test when nothing is.
template <typename F>
std::string error_of(F&& f) {
    try {
        f();
    } catch (const std::exception& e) {
        return e.what();
    }
    ADD_FAILURE() << "nothing was thrown";
    return {};
}

/// A JSON file the code under test wrote (manifests, metrics, field headers).
inline nlohmann::json read_json(const std::filesystem::path& p) { return nlohmann::json::parse(read_text(p)); }

/// The names in `dir` (not recursive), sorted; none when `dir` does not exist.
inline std::vector<std::string> sorted_entries(const std::filesystem::path& dir) {
    std::vector<std::string> names;
    if (!std::filesystem::exists(dir)) return names;
    for (const auto& e : std::filesystem::directory_iterator(dir)) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
}

}  // namespace sdf::test
