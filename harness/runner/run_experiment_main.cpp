// run-experiment CONFIG.json [--output-root DIR] [--dry-run] [--quiet]
#include <CLI/CLI.hpp>

#include <iostream>

#include "cpu_reference/parallel/progress.h"
#include "harness/runner/runner.h"

int main(int argc, char** argv) {
    CLI::App app{"Runs an experiment described by a JSON config (see configs/ and README.md)."};
    sdf::RunnerOptions options;
    bool quiet = false;
    app.add_option("config", options.config_path, "experiment config (JSON)")->required();
    app.add_option("--output-root", options.output_root, "where results/<name>/<run-id>/ go")->capture_default_str();
    app.add_flag("--dry-run", options.dry_run, "validate the config and print the plan; compute nothing");
    app.add_flag("--quiet", quiet, "no progress lines");
    CLI11_PARSE(app, argc, argv);
    sdf::ProgressReporter::set_globally_enabled(!quiet);
    try {
        return sdf::run_experiment(options);
    } catch (const std::exception& e) {
        std::cerr << "run-experiment: error: " << e.what() << "\n";
        return 1;
    }
}
