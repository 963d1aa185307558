// Fixture for scripts/check-layers: an include within the same layer is fine.
#pragma once
#include "kernels/core/host_device.h"
