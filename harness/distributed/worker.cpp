// A worker's life (rank > 0 of run-experiment): serve_distributed_requests
// (harness/distributed/distributed.h). The root's Sample request carries the sampler options,
// the lattice, every rank's slab and, when new, the mesh as loaded; the worker samples its
// slab and answers with its status and its points (slab_exchange.h). It keeps the slab until
// the root's Write request, when it writes the slab into the field files (parallel_write.h).
#include <chrono>
#include <cstring>
#include <memory>

#include "core/mesh/prepared_mesh.h"
#include "harness/config/sampler_spec.h"
#include "harness/distributed/distributed.h"
#include "harness/distributed/fault_injection.h"
#include "harness/distributed/mpi_session.h"
#include "harness/distributed/mpi_transport.h"
#include "harness/distributed/parallel_write.h"
#include "harness/distributed/slab_exchange.h"
#include "harness/distributed/wire_codec.h"
#include "harness/sampling/sampler_table.h"

namespace sdf {
namespace mpi {
namespace {

class Worker {
public:
    /// Handles one Sample request; the answer goes to the root whatever happens.
    void sample(const std::string& request) {
        const Session& s = session();
        nlohmann::json status = {{"ok", true}, {"rank", s.rank}, {"host", s.self["host"]}};
        release();  // a new field: the last one's slab is no longer wanted
        SampledField& part = part_;
        LatticeSlab& slab = slab_;
        Lattice& lattice = lattice_;
        try {
            ByteReader in(request);
            in.get<int32_t>();  // the command
            const SamplerOptions options = options_for_this_rank(get_options(in));
            lattice = in.get<Lattice>();
            const std::vector<LatticeSlab> slabs = in.get_vector<LatticeSlab>();
            const std::string sha = in.get_string();
            if (in.get<uint8_t>() != 0) prepare(in);
            if (!mesh_ || mesh_->content_sha256() != sha)
                throw std::runtime_error(!mesh_error_.empty() ? mesh_error_
                                                              : "has no prepared mesh " + sha.substr(0, 12) + " (protocol error)");
            if (slabs.size() != size_t(s.size)) throw std::runtime_error("the request holds no slab for this rank");
            slab = slabs[size_t(s.rank)];
            // Bound once per mesh and options: a study's lattices of one mesh reuse its tree and uploads.
            const std::string key = sampler_options_to_json(options).dump();
            const auto bind_start = std::chrono::steady_clock::now();
            if (!bound_ || key != sampler_key_) {
                bound_.reset();
                bound_ = make_sampler(options)->bind(mesh_);
                sampler_key_ = key;
            }
            const auto start = std::chrono::steady_clock::now();
            maybe_inject_failure(s.rank);
            part = sample_part(*bound_, lattice, slab);
            const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            status["part"] = describe_part(part, s.rank, s.self["host"].get<std::string>(), slab, seconds);
            // What this request waited for besides its slab: the binding (tree, uploads) of a
            // new mesh or options, and a mesh prepared on arrival.
            status["part"]["bind_seconds"] = std::chrono::duration<double>(start - bind_start).count();
            status["part"]["prepare_seconds"] = prepared_in_request_;
            prepared_in_request_ = 0;
            status["sampler"] = part.sampler;
        } catch (const std::exception& e) {
            status["ok"] = false;
            status["error"] = e.what();
        }
        send_string(status.dump(), 0, kTagStatus);
        if (!status["ok"].get<bool>()) return release();
        holds_part_ = true;  // for the parallel write of its files
        send_part(part, lattice, slab);
    }

    /// Handles one Write request: writes the slab it holds into the root's channel files.
    void write(const std::string& request) {
        const Session& s = session();
        nlohmann::json status = {{"ok", true}, {"rank", s.rank}, {"host", s.self["host"]}};
        try {
            if (!holds_part_) throw std::runtime_error("holds no sampled slab to write (protocol error)");
            ByteReader in(request);
            in.get<int32_t>();  // the command
            const std::vector<FieldChannelFile> files = files_from_json(nlohmann::json::parse(in.get_string()));
            const auto start = std::chrono::steady_clock::now();
            ChannelFiles out;
            std::string why;
            if (failure_asked(s.rank, "open")) {
                status["written"] = false;
                status["why"] = "injected: cannot open the files (SDF_MPI_FAIL_STAGE=open)";
            } else if (!out.open(files, lattice_.num_points(), why)) {
                status["written"] = false;  // the root writes this slab
                status["why"] = why;
            } else {
                maybe_inject_failure(s.rank, "write");
                status["write_bytes"] = write_slab(out, part_, false, lattice_, slab_);
                out.close();
                status["written"] = true;
                status["write_seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            }
        } catch (const std::exception& e) {
            status["ok"] = false;
            status["error"] = e.what();
        }
        release();
        send_string(status.dump(), 0, kTagStatus);
    }

    /// Handles a Mesh request (sent when the root loads it): prepares it now; a failure is
    /// this rank's answer to the next Sample request.
    void mesh(const std::string& request) {
        try {
            ByteReader in(request);
            in.get<int32_t>();  // the command
            prepare(in);
        } catch (const std::exception& e) {
            mesh_error_ = e.what();
        }
        prepared_in_request_ = 0;
    }

private:
    /// The mesh read from `in`, prepared as the root's load_prepared_mesh() prepares it.
    void prepare(ByteReader& in) {
        bound_.reset();  // the last mesh's sampler and device memory first
        mesh_.reset();
        mesh_error_.clear();
        const auto start = std::chrono::steady_clock::now();
        try {
            mesh_ = std::make_shared<const PreparedMesh>(prepare_mesh(get_mesh(in)));
        } catch (const std::exception& e) {
            mesh_error_ = e.what();
            throw;
        }
        prepared_in_request_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }

    void release() {
        holds_part_ = false;
        part_ = SampledField();
    }

    SampledField part_;  ///< the last slab sampled, kept until its field is written
    LatticeSlab slab_;
    Lattice lattice_;
    bool holds_part_ = false;
    std::shared_ptr<const PreparedMesh> mesh_;
    std::string mesh_error_;            ///< why the last mesh sent could not be prepared
    double prepared_in_request_ = 0;    ///< seconds the current Sample request spent preparing its mesh
    std::unique_ptr<BoundSampler> bound_;  ///< bound to mesh_ with the options of sampler_key_
    std::string sampler_key_;
};

}  // namespace
}  // namespace mpi

using namespace mpi;

int serve_distributed_requests() {
    Worker worker;
    for (;;) {
        const std::string request = receive_string(0, kTagCommand);
        if (request.size() < sizeof(int32_t)) return 1;
        int32_t command = 0;
        std::memcpy(&command, request.data(), sizeof command);
        if (Command(command) == Command::Quit) return 0;
        if (Command(command) == Command::Write) worker.write(request);
        else if (Command(command) == Command::Mesh) worker.mesh(request);
        else worker.sample(request);
    }
}

}  // namespace sdf
