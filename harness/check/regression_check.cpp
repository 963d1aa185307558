#include "harness/check/regression_check.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "harness/provenance/provenance.h"

namespace sdf {
namespace {

std::string num(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return buf;
}

std::string machine_text(const nlohmann::json& kind) {
    const std::string kernels = kind.contains("cpu_kernels") ? ", kernels " + kind.value("cpu_kernels", std::string()) : "";
    return "CPU \"" + kind.value("cpu", std::string("unknown")) + "\" (build target \"" +
           kind.value("cpu_target", std::string("unrecorded")) + "\"" + kernels + "), GPU " +
           (kind["gpu"].is_string() ? "\"" + kind["gpu"].get<std::string>() + "\"" : std::string("none"));
}

const nlohmann::json& regression_of(const nlohmann::json& metrics) {
    static const nlohmann::json none = nlohmann::json::object();
    return metrics.contains("regression") && metrics["regression"].is_object() ? metrics["regression"] : none;
}

/// One metric against its baseline entry; appends a line and counts it.
void check_metric(const std::string& key, const nlohmann::json& base, const nlohmann::json& got, bool same_machine,
                  const nlohmann::json& run_machine, const nlohmann::json& base_machine, CheckResult& r) {
    const std::string kind = base.value("kind", std::string("error"));
    const double b = base.at("value").get<double>();
    const double v = got.at("value").get<double>();
    if (kind == "speedup") {
        const double floor = base.value("floor", b * 0.8);
        if (!same_machine) {
            ++r.not_comparable;
            r.lines.push_back("  not comparable  " + key + " = " + num(v) + " (baseline " + num(b) + "): measured on " +
                              machine_text(run_machine) + ", the baseline on " + machine_text(base_machine) +
                              "; speedups are compared on the same machine kind only");
        } else if (v < floor) {
            ++r.failed;
            r.lines.push_back("  FAIL  " + key + " = " + num(v) + ", below the floor " + num(floor) + " (baseline " +
                              num(b) + ")");
        } else {
            ++r.ok;
        }
        return;
    }
    if (kind == "exact") {
        if (v != b) {
            ++r.failed;
            r.lines.push_back("  FAIL  " + key + " = " + num(v) + ", expected exactly " + num(b));
        } else {
            ++r.ok;
        }
        return;
    }
    const double rel = base.value("relative", 0.01), abs_tol = base.value("absolute", 0.0);
    const double allowed = abs_tol + rel * std::abs(b);
    if (!std::isfinite(v) || std::abs(v - b) > allowed) {
        ++r.failed;
        const std::string change = b != 0 ? " (" + std::string(v > b ? "+" : "") + num(100.0 * (v - b) / std::abs(b)) + "%)" : "";
        r.lines.push_back("  FAIL  " + key + " = " + num(v) + ", baseline " + num(b) + change + ", allowed +/-" +
                          num(allowed) + " (" + num(100 * rel) + "% + " + num(abs_tol) + ")" +
                          (v < b ? "; lower than the baseline: if the change is intended, make a new baseline" : ""));
    } else {
        ++r.ok;
    }
}

}  // namespace

nlohmann::json make_baseline(const nlohmann::json& manifest, const nlohmann::json& metrics, const BaselineDefaults& d) {
    const nlohmann::json git = manifest.at("provenance").at("git");
    const std::string commit = git.value("commit", std::string("unknown"));
    if (git.value("dirty", true) || commit == "unknown" || commit.empty())
        throw std::runtime_error("run " + manifest.value("run_id", std::string("?")) + " was made from " +
                                 (commit == "unknown" || commit.empty() ? std::string("an unknown git state")
                                                                        : "a dirty work tree (commit " + commit + ")") +
                                 "; a baseline must come from a clean checkout: commit, rebuild, run again");
    const nlohmann::json& reg = regression_of(metrics);
    if (reg.empty()) throw std::runtime_error("run " + manifest.value("run_id", std::string("?")) + " has no metrics to check");
    nlohmann::json entries = nlohmann::json::object();
    for (const auto& [key, m] : reg.items()) {
        const std::string kind = m.value("kind", std::string("error"));
        const double v = m.at("value").get<double>();
        if (kind == "speedup") entries[key] = {{"kind", kind}, {"value", v}, {"floor", d.speedup_floor_fraction * v}};
        else if (kind == "exact") entries[key] = {{"kind", kind}, {"value", v}};
        else entries[key] = {{"kind", "error"}, {"value", v}, {"relative", d.error_relative}, {"absolute", d.error_absolute}};
    }
    return {{"format", "sdf-baseline"},
            {"version", 1},
            {"name", manifest.at("name")},
            {"kind", manifest.at("kind")},
            {"made_from", {{"run_id", manifest.at("run_id")},
                           {"git_commit", commit},
                           {"config_sha256", manifest.at("config").at("sha256")},
                           {"finished", manifest.value("finished", std::string())}}},
            {"machine", machine_kind(manifest.at("provenance"))},
            {"metrics", entries}};
}

CheckResult check_run(const nlohmann::json& manifest, const nlohmann::json& metrics, const nlohmann::json& baseline,
                      const std::string& label) {
    if (baseline.value("format", std::string()) != "sdf-baseline")
        throw std::runtime_error(label + ": not a baseline file (\"format\" is not \"sdf-baseline\")");
    CheckResult r;
    const nlohmann::json run_machine = machine_kind(manifest.at("provenance"));
    const nlohmann::json base_machine = baseline.value("machine", nlohmann::json::object());
    const bool same_machine = run_machine == base_machine;
    const nlohmann::json made = baseline.value("made_from", nlohmann::json::object());
    r.lines.push_back("check of " + manifest.value("name", std::string("?")) + "/" + manifest.value("run_id", std::string("?")) +
                      " against " + label + " (made from run " + made.value("run_id", std::string("?")) + " at commit " +
                      made.value("git_commit", std::string("?")).substr(0, 12) + ")");
    if (made.contains("config_sha256") && manifest.contains("config") &&
        made["config_sha256"] != manifest["config"].value("sha256", std::string()))
        r.lines.push_back("  note: this run's resolved config differs from the baseline's (sha256 " +
                          manifest["config"].value("sha256", std::string()).substr(0, 12) + " vs " +
                          made["config_sha256"].get<std::string>().substr(0, 12) + ")");
    // A baseline that checks nothing would pass every run: refuse it, and every entry the
    // checks below could not read as written (an unknown kind would fall back to "error").
    if (!baseline.contains("metrics") || !baseline["metrics"].is_object() || baseline["metrics"].empty())
        throw std::runtime_error(label + ": key 'metrics': expected an object with at least one metric to check, got " +
                                 (baseline.contains("metrics") ? baseline["metrics"].dump().substr(0, 100) : "nothing") +
                                 "; make a baseline from a clean run with: run-experiment --write-baseline RUN_DIR");
    for (const auto& [key, base] : baseline["metrics"].items()) {
        const std::string where = label + ": key 'metrics." + key + "'";
        if (!base.is_object() || !base.contains("value") || !base["value"].is_number())
            throw std::runtime_error(where + ": expected an object with a numeric \"value\", got " + base.dump().substr(0, 100));
        const nlohmann::json kind = base.value("kind", nlohmann::json("error"));
        if (kind != "error" && kind != "exact" && kind != "speedup")
            throw std::runtime_error(where + ": unknown kind " + kind.dump() + "; expected \"error\", \"exact\" or \"speedup\"");
        for (const char* number : {"relative", "absolute", "floor"})
            if (base.contains(number) && !base[number].is_number())
                throw std::runtime_error(where + ": key '" + number + "': expected a number, got " + base[number].dump());
    }
    const nlohmann::json& reg = regression_of(metrics);
    for (const auto& [key, base] : baseline.at("metrics").items()) {
        if (!reg.contains(key)) {
            ++r.missing;
            r.lines.push_back("  FAIL  " + key + ": in the baseline but missing from this run");
            continue;
        }
        check_metric(key, base, reg[key], same_machine, run_machine, base_machine, r);
    }
    for (const auto& [key, m] : reg.items())
        if (!baseline.at("metrics").contains(key)) {
            ++r.added;
            r.lines.push_back("  new   " + key + " = " + num(m.at("value").get<double>()) + " (not in the baseline)");
        }
    const int total = r.ok + r.failed + r.not_comparable + r.missing;
    r.lines.push_back(std::string(r.passed() ? "PASSED" : "FAILED") + ": " + std::to_string(r.ok) + " of " +
                      std::to_string(total) + " metrics within tolerance" +
                      (r.failed ? ", " + std::to_string(r.failed) + " outside" : "") +
                      (r.missing ? ", " + std::to_string(r.missing) + " missing" : "") +
                      (r.not_comparable ? ", " + std::to_string(r.not_comparable) + " not comparable (other machine)" : "") +
                      (r.added ? ", " + std::to_string(r.added) + " new" : ""));
    return r;
}

std::string CheckResult::text() const {
    std::string s;
    for (const std::string& l : lines) s += l + "\n";
    return s;
}

}  // namespace sdf
