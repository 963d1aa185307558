// Fixture for scripts/check-layers: the CUDA backend including the CPU backend must fail.
#include "cpu_reference/sampling/brute_force_cpu.h"
