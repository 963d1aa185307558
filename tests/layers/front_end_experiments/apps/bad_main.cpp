// A tool that reaches into an experiment's helpers: refused (only the registry is allowed).
#include "experiments/experiment_registry.h"

#include "experiments/common/probes.h"
