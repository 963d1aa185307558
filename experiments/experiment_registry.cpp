#include <stdexcept>

#include "experiments/experiment.h"

namespace sdf {

// One line per kind. Each factory is defined in the kind's own file.
std::unique_ptr<Experiment> make_sampling_experiment();
std::unique_ptr<Experiment> make_speedup_experiment();
std::unique_ptr<Experiment> make_reconstruction_experiment();
std::unique_ptr<Experiment> make_analytic_experiment();
std::unique_ptr<Experiment> make_peers_experiment();

namespace {
struct Registration {
    const char* kind;
    std::unique_ptr<Experiment> (*make)();
};
const Registration kRegistry[] = {
    {"sampling", make_sampling_experiment},
    {"speedup", make_speedup_experiment},
    {"reconstruction", make_reconstruction_experiment},
    {"analytic", make_analytic_experiment},
    {"peers", make_peers_experiment},
};
}  // namespace

std::vector<std::string> experiment_kinds() {
    std::vector<std::string> kinds;
    for (const Registration& r : kRegistry) kinds.push_back(r.kind);
    return kinds;
}

std::unique_ptr<Experiment> make_experiment(const std::string& kind) {
    for (const Registration& r : kRegistry)
        if (kind == r.kind) return r.make();
    throw std::invalid_argument("unknown experiment kind '" + kind + "'");
}

}  // namespace sdf
