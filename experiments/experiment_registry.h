/// @file experiment_registry.h
/// @brief Every experiment kind of this project, one line each in experiment_registry.cpp;
/// apps/run_experiment_main.cpp hands this table to the runner.
#pragma once

#include "harness/experiment/experiment.h"

namespace sdf {

const ExperimentRegistry& experiment_registry();

}  // namespace sdf
