// Running a command-line tool as a user would, through `sh`, with its exit code, stdout and
// stderr captured: for the tests of the executables (tests/harness, tests/reconstruction).
#pragma once

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "tests/test_util/scratch_dir.h"

namespace sdf::test {

/// `s` in single quotes for sh, embedded quotes escaped.
inline std::string quote(const std::string& s) {
    std::string q = "'";
    for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
}

struct ShellResult {
    int code = -1;  ///< the exit status; -1 when the command did not exit normally
    std::string out, err;
};

/// Runs `command` in `dir` (which must exist); stdout and stderr pass through files there,
/// removed afterwards. `command` is one simple command, optionally with environment
/// assignments before it: the redirections bind to it.
inline ShellResult run_in(const std::filesystem::path& dir, const std::string& command) {
    const std::filesystem::path out = dir / ".stdout", err = dir / ".stderr";
    const std::string cmd = "cd " + quote(dir.string()) + " && " + command + " > " + quote(out.string()) + " 2> " +
                            quote(err.string());
    const int status = std::system(cmd.c_str());
    ShellResult r;
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = read_text(out);
    r.err = read_text(err);
    std::filesystem::remove(out);
    std::filesystem::remove(err);
    return r;
}

}  // namespace sdf::test
