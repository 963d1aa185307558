#include "harness/runner/runner.h"

#include <filesystem>
#include <iostream>
#include <regex>

#include "cpu_reference/mesh/sha256.h"
#include "experiments/experiment.h"
#include "harness/io/atomic_file.h"
#include "harness/provenance/provenance.h"

namespace sdf {
namespace fs = std::filesystem;

int run_experiment(const RunnerOptions& options) {
    const nlohmann::json config = read_json_file(options.config_path);
    JsonReader root(config, options.config_path);
    const std::string name = root.required<std::string>("name", "a run name of letters, digits, '-', '_' or '.'");
    if (!std::regex_match(name, std::regex("[A-Za-z0-9_.-]+")))
        root.fail("name", "expected letters, digits, '-', '_' or '.', got \"" + name + "\"");
    const std::string kind = root.choice("kind", experiment_kinds(), "sampling");
    root.optional<std::string>("description", "", "a string");

    RunContext ctx;
    ctx.config_path = options.config_path;
    ctx.config_dir = fs::path(options.config_path).parent_path().string();
    ctx.log = &std::cout;
    std::unique_ptr<Experiment> experiment = make_experiment(kind);
    experiment->configure(root, ctx);
    root.finish();

    const std::string config_text = config.dump();
    const std::string config_hash = sha256_hex(config_text.data(), config_text.size());
    if (options.dry_run) {
        std::cout << "plan for " << options.config_path << " (kind " << kind << ", config " << config_hash.substr(0, 12)
                  << "):\n";
        for (const std::string& line : experiment->plan()) std::cout << "  - " << line << "\n";
        return 0;
    }

    const std::string started = utc_timestamp();
    const std::string run_id = compact_utc_timestamp() + "-" + config_hash.substr(0, 8);
    StagedDirectory out((fs::path(options.output_root) / name / run_id).string());
    ctx.output_dir = out.path();
    std::cout << "run " << name << "/" << run_id << " (kind " << kind << ")\n";
    experiment->run(ctx);

    nlohmann::json manifest = {{"run_id", run_id},
                               {"name", name},
                               {"kind", kind},
                               {"config", {{"path", options.config_path}, {"sha256", config_hash}, {"resolved", config}}},
                               {"started", started},
                               {"finished", utc_timestamp()},
                               {"provenance", machine_and_build()}};
    if (ctx.metrics.contains("mesh")) manifest["inputs"]["mesh"] = ctx.metrics["mesh"];
    write_text_atomically(out.path() + "/metrics.json", ctx.metrics.dump(2) + "\n");
    write_text_atomically(out.path() + "/manifest.json", manifest.dump(2) + "\n");
    out.commit();
    std::cout << "results in " << out.final_path() << "\n";
    return 0;
}

}  // namespace sdf
