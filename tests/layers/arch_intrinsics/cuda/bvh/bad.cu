// Fixture of scripts/check-arch-intrinsics: redux.sync outside cuda/util/warp_reduce.cuh,
// which sm_75 (the first default architecture) does not have.
__global__ void count(int* total, int flag) {
    const int n = __reduce_add_sync(0xffffffffu, flag);
    if (threadIdx.x == 0) atomicAdd(total, n);
}
