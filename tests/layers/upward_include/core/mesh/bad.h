// Fixture for scripts/check-layers: core/ (layer 1) including harness/ (layer 3) must fail.
#pragma once
#include "kernels/core/vec3.h"
#include "harness/config/json_reader.h"
