// The single-process side of harness/distributed/distributed.h, for builds without MPI.
#include "harness/distributed/distributed.h"

#include <unistd.h>

#include "harness/sampling/sampler_table.h"

namespace sdf {

DistributedScope::DistributedScope(int&, char**&) {}
DistributedScope::~DistributedScope() = default;
bool distributed_active() { return false; }
int distributed_rank() { return 0; }
int distributed_size() { return 1; }
int serve_distributed_requests() { return 0; }
void require_same_settings_on_every_rank(const nlohmann::json&) {}
std::unique_ptr<Sampler> make_field_sampler(const SamplerOptions& options) { return make_sampler(options); }
void share_mesh_with_workers(const TriangleMesh&) {}
nlohmann::json distributed_description() { return nullptr; }
bool distributed_build() { return false; }
void set_distribution(Distribution) {}
Distribution distribution() { return Distribution::LatticeSlabs; }
std::string broadcast_from_root(const std::string& text) { return text; }
nlohmann::json gather_to_root(const nlohmann::json& mine) { return nlohmann::json::array({mine}); }
nlohmann::json this_process() { return {{"rank", 0}}; }
void fail_here_if_asked() {}
std::string start_collective_distribution() { return ""; }
void finish_collective_distribution() {}
void abort_distributed(int) {}
SampledField sample_collectively(const std::shared_ptr<const PreparedMesh>& mesh, const std::function<SamplingRequest()>& setup) {
    const SamplingRequest request = setup();
    return sample_once(*make_sampler(request.options), mesh, request.lattice);
}
nlohmann::json distributed_info() {
    char host[256] = {};
    if (::gethostname(host, sizeof host - 1) != 0) host[0] = '\0';
    return {{"mpi", false}, {"started_by", nullptr}, {"rank", 0}, {"size", 1}, {"host", std::string(host)}};
}
std::string write_sampled_field(const std::string& header_path, const SampledField& field,
                                const FieldWriteOptions& options) {
    write_field(header_path, field, options);
    return "root";
}

}  // namespace sdf
