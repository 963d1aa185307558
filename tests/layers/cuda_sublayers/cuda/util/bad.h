// Fixture for scripts/check-layers: cuda/util (rank 0) including cuda/sampling (rank 1) must
// fail: the device-memory helpers every launcher includes may not depend on a sampling step.
#pragma once
#include "cuda/util/cuda_check.h"
#include "cuda/sampling/finalize_kernel.cuh"
