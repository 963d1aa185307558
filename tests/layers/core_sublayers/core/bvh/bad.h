// Fixture for scripts/check-layers: core/bvh (rank 1) including core/mesh (rank 2) must fail:
// the folder cycle core/mesh <-> core/bvh that ranking only top-level folders did not see.
#pragma once
#include "core/bounds3.h"
#include "core/mesh/prepared_mesh.h"
