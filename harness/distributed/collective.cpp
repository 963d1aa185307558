// Collective sampling: the Python module under mpirun, where every rank runs the same script
// and calls sample_collectively (harness/distributed/distributed.h). No workers' loop: the
// root plans the slabs and every rank samples its own (slab_exchange.h); every rank returns
// the whole field. Messages (mpi_transport.h, wire_codec.h):
//
//   root -> worker  kTagCommand  Sample: the root's setup error (empty when it is ready), then
//                                its sampler options, lattice, slabs and mesh fingerprint
//   worker -> root  kTagStatus   as a worker's answer (worker.cpp; plus "setup": its own arguments
//                                failed), then kTagData with its slab when it sampled one
//   root -> worker  kTagOutcome  JSON: ok and the field's provenance, or the error every rank
//                                raises; when ok, the field's points follow by MPI_Bcast
// The Sample request and the outcome are waited for politely; the broadcast comes when every
// rank has answered, so no rank spins in it while others compute.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <mutex>
#include <stdexcept>

#include "core/lattice/lattice_fitting.h"
#include "core/sampling/sampler_results.h"
#include "harness/config/sampler_spec.h"
#include "harness/distributed/distributed.h"
#include "harness/distributed/fault_injection.h"
#include "harness/distributed/mpi_session.h"
#include "harness/distributed/mpi_transport.h"
#include "harness/distributed/slab_exchange.h"
#include "harness/distributed/wire_codec.h"
#include "harness/io/field_file.h"
#include "harness/sampling/sampler_table.h"

namespace sdf {
namespace mpi {
namespace {

/// What every rank's mesh must share with the root's.
std::string mesh_fingerprint(const PreparedMesh& mesh) {
    return "sha256 " + mesh.content_sha256() + ", " + std::to_string(mesh.vertices().size()) + " vertices and " +
           std::to_string(mesh.triangles().size()) + " triangles prepared";
}

void require_same(const std::string& what, const std::string& mine, const std::string& roots) {
    if (mine != roots)
        throw std::runtime_error("called with another " + what + " than rank 0 (every rank must pass the same arguments): " +
                                 mine + " here, " + roots + " on rank 0");
}

/// The same for a JSON object (a lattice, sampler options), naming the keys that differ.
void require_same_keys(const std::string& what, const nlohmann::json& mine, const std::string& roots_text) {
    const nlohmann::json roots = nlohmann::json::parse(roots_text);
    if (mine == roots) return;
    std::string mine_keys, roots_keys;
    for (const auto& [key, value] : mine.items()) {
        const nlohmann::json theirs = roots.contains(key) ? roots[key] : nlohmann::json(nullptr);
        if (value == theirs) continue;
        mine_keys += (mine_keys.empty() ? "" : ", ") + key + " " + value.dump();
        roots_keys += (roots_keys.empty() ? "" : ", ") + key + " " + theirs.dump();
    }
    require_same(what, mine_keys, roots_keys);
}

/// Every rank: the root's points of `field` (sized alike on every rank), in chunks of at
/// most 1 GiB.
void broadcast_field(SampledField& field) {
    broadcast_bytes(field.distance.data(), field.distance.size() * sizeof(double));
    broadcast_bytes(field.gradient.data(), field.gradient.size() * sizeof(Vec3d));
    broadcast_bytes(field.closest_triangle.data(), field.closest_triangle.size() * sizeof(int32_t));
}

/// After a failed exchange, on every rank: where every rank failed in its setup with the same
/// message (the same bad argument everywhere), its own exception, as one process would raise
/// it; otherwise the message naming every failed rank.
[[noreturn]] void raise_outcome(const nlohmann::json& outcome, const std::exception_ptr& setup_error) {
    if (outcome.value("same", false) && setup_error) std::rethrow_exception(setup_error);
    throw std::runtime_error(outcome.at("error").get<std::string>());
}

SampledField collective_root(const std::shared_ptr<const PreparedMesh>& shared_mesh,
                             const std::function<SamplingRequest()>& setup) {
    const PreparedMesh& mesh = *shared_mesh;
    Session& s = session();
    s.held.valid = false;
    const std::string host = s.self["host"].get<std::string>();
    const auto start = std::chrono::steady_clock::now();
    SamplingRequest mine;
    SampledField field;
    SlabPlan plan;
    std::exception_ptr setup_error;
    std::string setup_message;
    try {
        mine = setup();
        // The lattice's range check runs on every rank, so a bad one fails everywhere alike.
        field = unfilled_field(mesh, mine.lattice, whole_lattice_slab(mine.lattice), mine.options.precision);
        plan = plan_slabs(mesh, mine.lattice, mine.options, s.size);
    } catch (const std::exception& e) {
        setup_error = std::current_exception();
        setup_message = e.what();
    }
    ByteWriter request;
    request.put(int32_t(Command::Sample));
    request.put_string(setup_message);
    if (!setup_error) {
        put_options(request, mine.options);
        request.put_string(lattice_to_json(mine.lattice).dump());
        request.put_vector(plan.slabs);
        request.put_string(mesh_fingerprint(mesh));
    }
    for (int r = 1; r < s.size; ++r) send_bytes(request.bytes().data(), request.bytes().size(), r, kTagCommand);

    const auto sampling_start = std::chrono::steady_clock::now();
    Gathered gathered;
    if (setup_error) {
        gathered.failures.push_back({0, host, setup_message, true});
        receive_answers(gathered, nullptr, mine.lattice, {});
    } else {
        gathered = sample_and_gather(
            [&](const LatticeSlab& slab) {
                const std::unique_ptr<BoundSampler> sampler = make_sampler(options_for_this_rank(mine.options))->bind(shared_mesh);
                return sample_part(*sampler, mine.lattice, slab);
            },
            mine.lattice, plan, field);
    }

    nlohmann::json outcome = {{"ok", gathered.failures.empty()}};
    if (!gathered.failures.empty()) {
        bool same = int(gathered.failures.size()) == s.size;
        for (const RankFailure& f : gathered.failures) same = same && f.setup && f.error == gathered.failures[0].error;
        std::sort(gathered.failures.begin(), gathered.failures.end(),
                  [](const RankFailure& a, const RankFailure& b) { return a.rank < b.rank; });
        outcome["same"] = same;
        outcome["error"] = same ? gathered.failures[0].error
                                : failure_message(setup_error ? "" : lattice_notation(mine.lattice), gathered.failures);
    } else {
        const auto end = std::chrono::steady_clock::now();
        finish_provenance(field, mine.options, plan, gathered, std::chrono::duration<double>(end - start).count(),
                          std::chrono::duration<double>(end - sampling_start).count());
        field.sampler.details["distributed"]["collective"] = true;  // every rank called sample and holds the field
        outcome["sampler"] = field.sampler;
        outcome["timings"] = timings_to_json(field.timings);
    }
    for (int r = 1; r < s.size; ++r) send_string(outcome.dump(), r, kTagOutcome);
    if (!outcome["ok"].get<bool>()) raise_outcome(outcome, setup_error);
    broadcast_field(field);
    return field;
}

SampledField collective_worker(const std::shared_ptr<const PreparedMesh>& shared_mesh,
                               const std::function<SamplingRequest()>& setup) {
    const PreparedMesh& mesh = *shared_mesh;
    const Session& s = session();
    const std::string host = s.self["host"].get<std::string>();
    nlohmann::json status = {{"ok", true}, {"rank", s.rank}, {"host", host}};
    SamplingRequest mine;
    std::exception_ptr setup_error;
    try {
        mine = setup();
        require_search_range(mesh, mine.lattice, mine.options.precision);  // as the root's unfilled_field
    } catch (const std::exception& e) {
        setup_error = std::current_exception();
        status = {{"ok", false}, {"rank", s.rank}, {"host", host}, {"error", e.what()}, {"setup", true}};
    }
    const std::string request = receive_string(0, kTagCommand);
    SampledField part;
    LatticeSlab slab;
    if (!setup_error) {
        try {
            ByteReader in(request);
            in.get<int32_t>();  // the command
            if (in.get_string().empty()) {  // the root is ready: sample this rank's slab
                const std::string options = in.get_string(), lattice = in.get_string();
                const std::vector<LatticeSlab> slabs = in.get_vector<LatticeSlab>();
                require_same("mesh", mesh_fingerprint(mesh), in.get_string());
                require_same_keys("lattice", lattice_to_json(mine.lattice), lattice);
                require_same_keys("sampler", sampler_options_to_json(mine.options), options);
                if (slabs.size() != size_t(s.size)) throw std::runtime_error("the request holds no slab for this rank");
                slab = slabs[size_t(s.rank)];
                const std::unique_ptr<BoundSampler> sampler = make_sampler(options_for_this_rank(mine.options))->bind(shared_mesh);
                const auto t0 = std::chrono::steady_clock::now();
                maybe_inject_failure(s.rank);
                part = sample_part(*sampler, mine.lattice, slab);
                const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
                status["part"] = describe_part(part, s.rank, host, slab, seconds);
                status["sampler"] = part.sampler;
            }
        } catch (const std::exception& e) {
            status = {{"ok", false}, {"rank", s.rank}, {"host", host}, {"error", e.what()}};
        }
    }
    send_string(status.dump(), 0, kTagStatus);
    if (status.contains("part")) send_part(part, mine.lattice, slab);
    part = SampledField();

    // The whole field's memory, while the root still gathers (its first touch is not free).
    SampledField field;
    if (status.contains("part")) {
        field.lattice = mine.lattice;
        field.precision = mine.options.precision;
        field.resize(mine.lattice.num_points());
    }
    const nlohmann::json outcome = nlohmann::json::parse(receive_string(0, kTagOutcome));
    if (!outcome.at("ok").get<bool>()) raise_outcome(outcome, setup_error);
    broadcast_field(field);
    field.sampler = outcome.at("sampler").get<SamplerReport>();
    field.timings = timings_from_json(outcome.at("timings"));
    return field;
}

}  // namespace
}  // namespace mpi

using namespace mpi;

std::string start_collective_distribution() {
    Session& s = session();
    if (s.joined) return s.started_by;
    int initialized = 0, finalized = 0;
    check_mpi(MPI_Initialized(&initialized), "MPI_Initialized");
    check_mpi(MPI_Finalized(&finalized), "MPI_Finalized");
    if (finalized) return "";
    if (initialized) {
        s.started_by = "another library";  // mpi4py, say: it ends MPI too
    } else if (launched_by_mpi()) {
        // Serialized: sample() releases the GIL, so any Python thread may call it (one at a time).
        int provided = 0;
        check_mpi(MPI_Init_thread(nullptr, nullptr, MPI_THREAD_SERIALIZED, &provided), "MPI_Init_thread");
        s.started = true;
        s.started_by = "sdf_lattices";
    } else {
        return "";
    }
    s.collective = true;
    join_ranks();
    return s.started_by;
}

void finish_collective_distribution() {
    Session& s = session();
    if (!s.started || !s.collective) return;
    s.started = false;
    s.joined = false;
    int finalized = 0;
    MPI_Finalized(&finalized);
    if (!finalized) MPI_Finalize();
}

SampledField sample_collectively(const std::shared_ptr<const PreparedMesh>& mesh, const std::function<SamplingRequest()>& setup) {
    if (!distributed_active() || !session().collective) {
        const SamplingRequest request = setup();
        return sample_once(*make_sampler(request.options), mesh, request.lattice);
    }
    // One exchange at a time (MPI_THREAD_SERIALIZED; the messages of two would interleave).
    static std::mutex one_at_a_time;
    const std::lock_guard<std::mutex> lock(one_at_a_time);
    return session().rank == 0 ? collective_root(mesh, setup) : collective_worker(mesh, setup);
}

nlohmann::json distributed_info() {
    const Session& s = session();
    nlohmann::json info = {{"mpi", true},
                           {"started_by", s.started_by.empty() ? nlohmann::json(nullptr) : nlohmann::json(s.started_by)},
                           {"rank", s.rank},
                           {"size", s.size}};
    if (s.joined) {
        for (const auto& [key, value] : s.self.items()) info[key] = value;
        if (s.rank == 0 && s.size > 1) info["processes"] = s.processes;
    } else {
        char host[256] = {};
        if (::gethostname(host, sizeof host - 1) != 0) host[0] = '\0';
        info["host"] = std::string(host);
    }
    return info;
}

}  // namespace sdf
