// One exit-code table for every tool (README, "Exit codes"): 0 success (and --help,
// --version), 1 an error in the inputs or the run, 2 a command-line error. CLI11's own codes (105 for
// a failed validator, 106 for a missing required option, ...) differ per kind of mistake
// and were undocumented; scripts only need to know "the command line was wrong".
#pragma once

#include <CLI/CLI.hpp>

#include "harness/provenance/version.h"

namespace sdf {

constexpr int kExitCommandLineError = 2;
/// run-experiment: a mesh the config names is on no directory of the data search path.
constexpr int kExitMeshNotFound = 4;

/// Prints CLI11's message (or the help) as CLI11 does; returns the tool's exit code.
inline int command_line_exit(const CLI::App& app, const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : kExitCommandLineError;
}

/// `--version`: prints "TOOL VERSION (commit HASH)" (harness/provenance/version.h) and exits 0.
inline void add_version_flag(CLI::App& app, const std::string& tool) {
    app.set_version_flag("--version", version_line(tool), "print the version and the git commit of this build, then exit");
}

}  // namespace sdf

/// CLI11_PARSE with the exit codes of the table above.
#define SDF_CLI_PARSE(app, argc, argv)                           \
    try {                                                        \
        (app).parse((argc), (argv));                             \
    } catch (const CLI::ParseError& e) {                         \
        return sdf::command_line_exit((app), e);                 \
    }
