#include "harness/experiment/experiment.h"

#include <stdexcept>

namespace sdf {

std::vector<std::string> experiment_kind_names(const ExperimentRegistry& registry) {
    std::vector<std::string> names;
    for (const ExperimentKind& k : registry) names.emplace_back(k.name);
    return names;
}

std::unique_ptr<Experiment> make_experiment(const ExperimentRegistry& registry, const std::string& kind) {
    for (const ExperimentKind& k : registry)
        if (kind == k.name) return k.make();
    std::string known;
    for (const ExperimentKind& k : registry) known += (known.empty() ? "" : ", ") + std::string(k.name);
    throw std::invalid_argument("unknown experiment kind '" + kind + "'; known kinds: " + known);
}

}  // namespace sdf
