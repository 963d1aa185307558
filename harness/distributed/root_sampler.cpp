// The root's sampler of run-experiment under mpirun: make_field_sampler
// (harness/distributed/distributed.h). Each whole lattice it is asked for is planned into one
// slab per rank (slab_plan.h); it sends the workers their Sample request (worker.cpp), samples
// slab 0 itself and gathers the rest (slab_exchange.h). The workers keep their slabs for the
// parallel write of the field's files (parallel_write.cpp).
#include <chrono>
#include <stdexcept>

#include "core/lattice/lattice_fitting.h"
#include "core/sampling/sampler_results.h"
#include "harness/distributed/distributed.h"
#include "harness/distributed/mpi_session.h"
#include "harness/distributed/mpi_transport.h"
#include "harness/distributed/slab_exchange.h"
#include "harness/distributed/wire_codec.h"
#include "harness/sampling/sampler_table.h"

namespace sdf {
namespace mpi {
namespace {

/// The root's sampler bound to a mesh: whole lattices are cut into slabs over the ranks,
/// anything else (a slab, points) is sampled by this rank's own bound sampler.
class BoundDistributedSampler final : public BoundSampler {
public:
    BoundDistributedSampler(std::shared_ptr<const PreparedMesh> mesh, const SamplerOptions& options, const Sampler& local)
        : BoundSampler(mesh), options_(options), local_(local.bind(std::move(mesh))) {}

    std::string name() const override { return local_->name() + " on " + std::to_string(session().size) + " MPI ranks"; }
    const SignModeChoice& sign() const override { return local_->sign(); }

    std::vector<PointSample> query(const std::vector<Vec3d>& points, SamplingTimings* timings) const override {
        return local_->query(points, timings);
    }

    SampledField sample_slab(const Lattice& lattice, const LatticeSlab& slab) const override {
        if (!is_whole_lattice(lattice, slab)) return local_->sample_slab(lattice, slab);
        const PreparedMesh& mesh = this->mesh();
        Session& s = session();
        s.held.valid = false;  // the workers drop the last field's slabs on this request
        const auto start = std::chrono::steady_clock::now();
        // Before any worker is asked: a mesh or lattice out of the search's range is refused here.
        SampledField field = unfilled_field(mesh, lattice, whole_lattice_slab(lattice), options_.precision);
        const SlabPlan plan = plan_slabs(mesh, lattice, options_, s.size);
        send_requests(mesh, lattice, plan);
        const auto sampling_start = std::chrono::steady_clock::now();
        const Gathered gathered =
            sample_and_gather([&](const LatticeSlab& mine) { return sample_part(*local_, lattice, mine); }, lattice, plan, field);
        if (!gathered.failures.empty()) throw std::runtime_error(failure_message(lattice_notation(lattice), gathered.failures));
        const auto end = std::chrono::steady_clock::now();
        s.fields.push_back(finish_provenance(field, options_, plan, gathered, std::chrono::duration<double>(end - start).count(),
                                             std::chrono::duration<double>(end - sampling_start).count()));
        s.held = {true, lattice, plan.slabs, field.sampler.details["distributed"], field.distance.data(), s.fields.size() - 1};
        return field;
    }

private:
    void send_requests(const PreparedMesh& mesh, const Lattice& lattice, const SlabPlan& plan) const {
        Session& s = session();
        ByteWriter out;
        out.put(int32_t(Command::Sample));
        put_options(out, options_);
        out.put(lattice);
        out.put_vector(plan.slabs);
        out.put_string(mesh.content_sha256());
        const bool new_mesh = s.mesh_sent != mesh.content_sha256();
        out.put(uint8_t(new_mesh));
        if (new_mesh) {
            const auto it = s.meshes.find(mesh.content_sha256());
            if (it == s.meshes.end())
                throw std::logic_error("distributed sampling: mesh " + mesh.name() +
                                       " was not shared with the workers (share_mesh_with_workers)");
            put_mesh(out, it->second);
        }
        for (int r = 1; r < s.size; ++r) send_bytes(out.bytes().data(), out.bytes().size(), r, kTagCommand);
        s.mesh_sent = mesh.content_sha256();
    }

    SamplerOptions options_;
    std::unique_ptr<BoundSampler> local_;
};

class DistributedSampler final : public Sampler {
public:
    explicit DistributedSampler(const SamplerOptions& options)
        : options_(options), local_(make_sampler(options_for_this_rank(options))) {}

    std::string name() const override {
        return local_->name() + " on " + std::to_string(session().size) + " MPI ranks";
    }

    std::unique_ptr<BoundSampler> bind(std::shared_ptr<const PreparedMesh> mesh) const override {
        return std::make_unique<BoundDistributedSampler>(std::move(mesh), options_, *local_);
    }

private:
    SamplerOptions options_;
    std::unique_ptr<Sampler> local_;
};

}  // namespace
}  // namespace mpi

using namespace mpi;

std::unique_ptr<Sampler> make_field_sampler(const SamplerOptions& options) {
    if (!distributed_active()) return make_sampler(options);
    if (session().distribution == Distribution::Runs) return make_sampler(options_for_this_rank(options));
    return std::make_unique<DistributedSampler>(options);
}

void share_mesh_with_workers(const TriangleMesh& mesh) {
    if (!distributed_active()) return;
    Session& s = session();
    s.meshes.emplace(mesh.content_sha256, mesh);
    // Only where the workers serve requests (run-experiment's slabs, not the Python module's
    // collective calls or runs mode): the mesh goes now, so each worker prepares it (welding,
    // checks, its BVH) while the root prepares its own, not after the first Sample request.
    if (s.rank != 0 || s.released || s.collective || s.distribution != Distribution::LatticeSlabs) return;
    if (s.mesh_sent == mesh.content_sha256) return;
    ByteWriter out;
    out.put(int32_t(Command::Mesh));
    put_mesh(out, mesh);
    for (int r = 1; r < s.size; ++r) send_bytes(out.bytes().data(), out.bytes().size(), r, kTagCommand);
    s.mesh_sent = mesh.content_sha256;
}
}  // namespace sdf
