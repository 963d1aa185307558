#include "experiments/experiment_registry.h"

namespace sdf {

// Each factory is defined in the kind's own file.
std::unique_ptr<Experiment> make_sampling_experiment();
std::unique_ptr<Experiment> make_speedup_experiment();
std::unique_ptr<Experiment> make_reconstruction_experiment();
std::unique_ptr<Experiment> make_analytic_experiment();
std::unique_ptr<Experiment> make_peers_experiment();

const ExperimentRegistry& experiment_registry() {
    static const ExperimentRegistry registry = {
        {"sampling", make_sampling_experiment},
        {"speedup", make_speedup_experiment},
        {"reconstruction", make_reconstruction_experiment},
        {"analytic", make_analytic_experiment},
        {"peers", make_peers_experiment},
    };
    return registry;
}

}  // namespace sdf
