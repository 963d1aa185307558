// Fixture for scripts/check-layers: the brute-force sampler including the BVH sampler's kernel
// must fail: the two samplers are siblings (rank 2), what they share lives in cuda/sampling.
#include "cuda/sampling/point_pieces.h"
#include "cuda/bvh/bvh_kernel.cuh"
