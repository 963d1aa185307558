// This process's part in a distributed run (mpi_session.h), and the parts of
// harness/distributed/distributed.h that only describe or connect the ranks: the scope of
// MPI, the settings check, runs mode's broadcast and gather.
#include "harness/distributed/mpi_session.h"

#include <sched.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>

#include "core/parallel/parallel_for.h"
#include "harness/build_config.h"
#include "harness/distributed/mpi_transport.h"
#include "harness/distributed/wire_codec.h"
#include "harness/sampling/device_selection.h"
#if SDF_HAVE_CUDA
#include "cuda/util/cuda_device.h"
#endif

namespace sdf {
namespace mpi {
namespace {

int cuda_devices() {
#if SDF_HAVE_CUDA
    return cuda::device_count();
#else
    return 0;
#endif
}

nlohmann::json describe_this_process(int rank) {
    nlohmann::json self = {{"rank", rank}, {"host", host_name()}};
    MPI_Comm local;
    check_mpi(MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, rank, MPI_INFO_NULL, &local), "MPI_Comm_split_type");
    int local_rank = 0, local_size = 1;
    MPI_Comm_rank(local, &local_rank);
    MPI_Comm_size(local, &local_size);
    MPI_Comm_free(&local);
    self["local_rank"] = local_rank;
    self["local_size"] = local_size;
    self["threads"] = std::max(1, resolve_thread_count(0) / std::max(1, local_size));
    // The cores this rank may run on: Open MPI binds each rank to one core by default when
    // -np <= 2 (to a socket above), so a rank's host threads (the field's pages, the pinned
    // copies, the CPU sampler) would all share that core (issue 36).
    cpu_set_t allowed;
    CPU_ZERO(&allowed);
    if (sched_getaffinity(0, sizeof allowed, &allowed) == 0) self["cores_allowed"] = CPU_COUNT(&allowed);
    const int devices = cuda_devices();
    self["gpus_on_host"] = devices;
    self["gpu"] = nullptr;
#if SDF_HAVE_CUDA
    if (devices > 0) {
        const int device = local_rank % devices;  // the default selection's (device_selection.h)
        const nlohmann::json d = cuda::describe_device(device);
        self["gpu"] = {{"device", device}, {"name", d.value("name", std::string("?"))},
                       {"pci_bus_id", d.value("pci_bus_id", std::string("?"))}};
    }
#endif
    return self;
}

}  // namespace

Session& session() {
    static Session s;
    return s;
}

bool launched_by_mpi() {
    for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK", "MPI_LOCALNRANKS"})
        if (std::getenv(v) != nullptr) return true;
    return false;
}

SamplerOptions options_for_this_rank(SamplerOptions o) {
    const Session& s = session();
    const int devices = cuda_devices();
    // Local rank r of the host's ranks takes its share of the visible GPUs
    // (device_selection.h): GPU (device + r) % count by default, a share of "devices".
    o = place_rank_on_devices(o, s.self.value("local_rank", 0), s.self.value("local_size", 1), devices);
    if (o.threads == 0) o.threads = std::max(1, resolve_thread_count(0) / std::max(1, s.self.value("local_size", 1)));
    if (s.rank != 0) o.progress = false;  // one progress line per run: the root's
    return o;
}

void join_ranks() {
    Session& s = session();
    MPI_Comm_rank(MPI_COMM_WORLD, &s.rank);
    MPI_Comm_size(MPI_COMM_WORLD, &s.size);
    s.self = describe_this_process(s.rank);
    s.joined = true;
    if (s.rank != 0) {
        send_string(s.self.dump(), 0, kTagHello);
        return;
    }
    s.processes.push_back(s.self);
    for (int r = 1; r < s.size; ++r) s.processes.push_back(nlohmann::json::parse(receive_string(r, kTagHello)));
    for (const nlohmann::json& p : s.processes) {
        const int allowed = p.value("cores_allowed", 0), threads = p.value("threads", 1);
        if (allowed > 0 && allowed < threads) {
            std::fprintf(stderr,
                         "warning: rank %d may run on %d core%s of its host's %d for its %d threads (mpirun binds each rank "
                         "to one core by default for -np <= 2): its host work runs on %s; start it with "
                         "mpirun --bind-to none, or --map-by slot:PE=%d\n",
                         p.value("rank", 0), allowed, allowed == 1 ? "" : "s", resolve_thread_count(0), threads,
                         allowed == 1 ? "that core" : "those cores", threads);
            break;  // one line: every rank was started alike
        }
    }
}

namespace {

/// Rank 0: what differs between every rank's settings (in rank order) and its own, one
/// clause per key: "--distribute: rank 0 has \"slabs\", rank 1 has \"runs\"". Empty when
/// every rank agrees.
std::string settings_differences(const std::vector<nlohmann::json>& settings) {
    const nlohmann::json& root = settings[0];
    std::vector<std::string> keys;
    for (const nlohmann::json& s : settings)
        for (const auto& [key, value] : s.items())
            if (std::find(keys.begin(), keys.end(), key) == keys.end()) keys.push_back(key);
    std::string text;
    for (const std::string& key : keys) {
        const auto value_of = [&](const nlohmann::json& s) { return s.contains(key) ? s[key].dump() : std::string("nothing"); };
        std::map<std::string, std::vector<int>> others;  // value -> ranks
        for (size_t r = 1; r < settings.size(); ++r)
            if (value_of(settings[r]) != value_of(root)) others[value_of(settings[r])].push_back(int(r));
        if (others.empty()) continue;
        std::string clause = key + ": rank 0 has " + value_of(root);
        for (const auto& [value, ranks] : others) {
            std::string list;
            for (int r : ranks) list += (list.empty() ? "" : ", ") + std::to_string(r);
            clause += ", rank" + std::string(ranks.size() > 1 ? "s " : " ") + list + " ha" + (ranks.size() > 1 ? "ve " : "s ") + value;
        }
        text += (text.empty() ? "" : "; ") + clause;
    }
    return text;
}


}  // namespace
}  // namespace mpi

using namespace mpi;

DistributedScope::DistributedScope(int& argc, char**& argv) {
    if (!launched_by_mpi()) return;
    Session& s = session();
    int provided = 0;
    check_mpi(MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided), "MPI_Init_thread");
    s.started = true;
    join_ranks();
}

DistributedScope::~DistributedScope() {
    Session& s = session();
    if (!s.started) return;
    if (s.rank == 0 && !s.released && !s.collective && s.distribution == Distribution::LatticeSlabs) {
        const int32_t quit = int32_t(Command::Quit);
        for (int r = 1; r < s.size; ++r) send_bytes(&quit, sizeof quit, r, kTagCommand);
        s.released = true;
    }
    MPI_Finalize();
}

bool distributed_active() { return session().joined && session().size > 1; }
int distributed_rank() { return session().rank; }
int distributed_size() { return session().size; }
bool distributed_build() { return true; }

void require_same_settings_on_every_rank(const nlohmann::json& settings) {
    Session& s = session();
    if (!distributed_active()) return;
    std::string verdict;
    if (s.rank != 0) {
        send_string(settings.dump(), 0, kTagSettings);
        verdict = receive_string(0, kTagSettings);
    } else {
        std::vector<nlohmann::json> all = {settings};
        for (int r = 1; r < s.size; ++r) all.push_back(nlohmann::json::parse(receive_string(r, kTagSettings), nullptr, false));
        const std::string differences = settings_differences(all);
        if (!differences.empty())
            verdict = "the ranks were started with different options (every rank must get the same command line and "
                      "environment); nothing was run: " + differences;
        for (int r = 1; r < s.size; ++r) send_string(verdict, r, kTagSettings);
    }
    if (verdict.empty()) return;
    s.released = true;  // no worker waits for a command: each stops here
    throw std::runtime_error(verdict);
}

nlohmann::json distributed_description() {
    if (!distributed_active()) return nullptr;
    const Session& s = session();
    return {{"ranks", s.size},
            {"mode", s.distribution == Distribution::Runs ? "runs" : "lattice_slabs"},
            {"processes", s.processes},
            {"fields", s.fields}};
}

void set_distribution(Distribution d) { session().distribution = d; }
Distribution distribution() { return session().distribution; }

std::string broadcast_from_root(const std::string& text) {
    const Session& s = session();
    if (!distributed_active()) return text;
    if (s.rank != 0) return receive_string(0, kTagRuns);
    for (int r = 1; r < s.size; ++r) send_string(text, r, kTagRuns);
    return text;
}

nlohmann::json gather_to_root(const nlohmann::json& mine) {
    const Session& s = session();
    if (!distributed_active()) return nlohmann::json::array({mine});
    if (s.rank != 0) {
        send_string(mine.dump(), 0, kTagRuns);
        return nlohmann::json::array();
    }
    nlohmann::json all = nlohmann::json::array({mine});
    for (int r = 1; r < s.size; ++r) all.push_back(nlohmann::json::parse(receive_string(r, kTagRuns)));
    return all;
}

nlohmann::json this_process() { return session().self; }

void abort_distributed(int code) {
    if (distributed_active()) MPI_Abort(MPI_COMM_WORLD, code);
}

}  // namespace sdf
