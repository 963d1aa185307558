#include "harness/provenance/provenance.h"

#include <unistd.h>

#include <array>
#include <chrono>
#include <cstdlib>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <memory>

#include "core/parallel/parallel_for.h"
#include "cpu_reference/dispatch/cpu_kernels.h"
#include "harness/build_config.h"
#include "harness/sampling/sampler_table.h"
#if SDF_HAVE_CUDA
#include "cuda/util/cuda_device.h"
#endif

namespace sdf {
namespace {

std::string run_command(const std::string& cmd, bool* ok) {
    std::array<char, 256> buf{};
    std::string out;
    std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(cmd.c_str(), "r"), pclose);
    if (!pipe) { *ok = false; return ""; }
    while (fgets(buf.data(), int(buf.size()), pipe.get())) out += buf.data();
    const int status = pclose(pipe.release());
    *ok = status == 0;
    while (!out.empty() && (out.back() == '\n' || out.back() == ' ')) out.pop_back();
    return out;
}

/// The commit passed in (for a tree without .git, or with a stale one): SDF_SOURCE_COMMIT from the environment, else
/// from the build (cmake -DSDF_SOURCE_COMMIT=...). "<commit>-dirty" marks uncommitted changes,
/// as `git describe --dirty` does; a commit without it is taken as clean.
GitState passed_in_commit() {
    GitState g;
    const char* env = std::getenv("SDF_SOURCE_COMMIT");
    std::string commit = env && *env ? env : SDF_SOURCE_COMMIT_AT_BUILD;
    if (commit.empty()) return g;
    const std::string dirty_suffix = "-dirty";
    g.dirty = commit.size() > dirty_suffix.size() &&
              commit.compare(commit.size() - dirty_suffix.size(), dirty_suffix.size(), dirty_suffix) == 0;
    if (g.dirty) commit.resize(commit.size() - dirty_suffix.size());
    g.commit = commit;
    g.source = "SDF_SOURCE_COMMIT";
    return g;
}

}  // namespace

GitState git_state() { return git_state_of(SDF_SOURCE_DIR); }

GitState git_state_of(const std::string& source_dir) {
    // A commit passed in wins: a copy of the tree (the GPU machines') may hold a stale .git
    // whose HEAD is not what was built (seen: runs recorded an older commit as "git").
    if (const GitState passed = passed_in_commit(); passed.source == "SDF_SOURCE_COMMIT") return passed;
    GitState g;
    bool ok = false;
    const std::string dir = "git -C '" + source_dir + "' ";
    const std::string commit = run_command(dir + "rev-parse HEAD 2>/dev/null", &ok);
    if (!ok || commit.empty()) return passed_in_commit();
    g.commit = commit;
    g.source = "git";
    const std::string status = run_command(dir + "status --porcelain --untracked-files=no 2>/dev/null", &ok);
    g.dirty = !ok || !status.empty();
    return g;
}

std::string cpu_model() {
    std::ifstream in("/proc/cpuinfo");
    for (std::string line; std::getline(in, line);)
        if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
    return "unknown";
}

nlohmann::json build_info() {
    // The hot search loops run at the widest level the CPU supports (cpu_kernels.h), which can
    // be wider than the build's target: both are recorded.
    const CpuKernelChoice kernels = cpu_kernel_choice();
    return {{"build_type", SDF_BUILD_TYPE},
            {"cxx_compiler", SDF_CXX_COMPILER},
            {"cxx_flags", SDF_CXX_FLAGS},
            {"cpu_target", {{"option", SDF_CPU_TARGET}, {"march", SDF_CPU_MARCH}, {"isa", SDF_CPU_ISA}}},
            {"cpu_kernels", {{"isa", kernels.isa}, {"chosen_by", kernels.chosen_by}, {"built", kernels.built}}},
            {"fp_contract", "off"},
            {"cuda_flags", SDF_HAVE_CUDA ? SDF_CUDA_FLAGS : ""},
            {"cuda", SDF_HAVE_CUDA ? true : false},
            {"fast_math", false}};
}

nlohmann::json gpu_info() {
#if SDF_HAVE_CUDA
    if (cuda::device_count() > 0) return cuda::describe_device(0);
#endif
    return nullptr;
}

std::string utc_timestamp() {
    const std::time_t t = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
    char buf[32];
    std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
    return buf;
}

std::string compact_utc_timestamp() {
    const auto now = std::chrono::system_clock::now();
    const std::time_t t = std::chrono::system_clock::to_time_t(now);
    const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() % 1000;
    char buf[32], out[48];
    std::strftime(buf, sizeof buf, "%Y%m%dT%H%M%S", std::gmtime(&t));
    std::snprintf(out, sizeof out, "%s.%03dZ", buf, int(ms));
    return out;
}

nlohmann::json machine_kind(const nlohmann::json& provenance) {
    nlohmann::json kind = {{"cpu", "unknown"}, {"gpu", nullptr}, {"cpu_target", "unrecorded"}};
    if (provenance.contains("cpu") && provenance["cpu"].contains("model")) kind["cpu"] = provenance["cpu"]["model"];
    // The build target is part of the machine: the same CPU runs an x86-64-v2 build and a
    // native AVX-512 build at different speeds.
    const nlohmann::json build = provenance.value("build", nlohmann::json());
    if (build.is_object() && build.contains("cpu_target") && build["cpu_target"].is_object())
        kind["cpu_target"] = build["cpu_target"].value("march", std::string("unrecorded"));
    // ... and so does the ISA its dispatched kernels ran at (recorded since run-time dispatch).
    if (build.is_object() && build.contains("cpu_kernels") && build["cpu_kernels"].is_object())
        kind["cpu_kernels"] = build["cpu_kernels"].value("isa", std::string("unrecorded"));
    const nlohmann::json gpu = provenance.value("gpu", nlohmann::json());
    if (gpu.is_object() && gpu.contains("name")) kind["gpu"] = gpu["name"];
    return kind;
}

nlohmann::json load_average() {
    std::ifstream in("/proc/loadavg");
    double a = 0, b = 0, c = 0;
    if (!(in >> a >> b >> c)) return nullptr;
    return {a, b, c};
}

nlohmann::json machine_and_build() {
    char host[256] = "unknown";
    gethostname(host, sizeof host - 1);
    const GitState g = git_state();
    return {{"host", host},
            {"cpu", {{"model", cpu_model()}, {"hardware_threads", hardware_threads()}}},
            {"gpu", gpu_info()},
            {"build", build_info()},
            {"git", {{"commit", g.commit}, {"dirty", g.dirty}, {"source", g.source}}}};
}

}  // namespace sdf
