// DeviceBuffer's memory (cuda/util/device_memory.cu): allocations come from a pool of our own, not
// the device's default pool, whose settings belong to the whole process (PyTorch, CuPy and
// cuBQL use and set it); memory our pool keeps after a free still counts as free to
// free_device_memory(), which sizes the samplers' slabs; a sampler still answers exactly
// after another library set the default pool to keep everything.
#include <gtest/gtest.h>
#include <cuda_runtime.h>

#include <cstdint>

#include "cuda/util/device_buffer.h"
#include "harness/sampling/sampler_table.h"
#include "tests/cpu_reference/bvh/bvh_test_meshes.h"
#include "tests/test_util/shared_mesh.h"

namespace sdf {
namespace {

uint64_t default_pool_threshold() {
    int device = 0;
    cudaMemPool_t pool{};
    uint64_t threshold = 0;
    EXPECT_EQ(cudaGetDevice(&device), cudaSuccess);
    EXPECT_EQ(cudaDeviceGetDefaultMemPool(&pool, device), cudaSuccess);
    EXPECT_EQ(cudaMemPoolGetAttribute(pool, cudaMemPoolAttrReleaseThreshold, &threshold), cudaSuccess);
    return threshold;
}

TEST(CudaDeviceMemory, KeptMemoryCountsAsFreeAndTheDefaultPoolIsLeftAlone) {
    const uint64_t before = default_pool_threshold();
    constexpr size_t kBytes = size_t(256) << 20;  // below the pool's kept share (1/16) on any current GPU
    {
        cuda::DeviceBuffer<char> buffer(kBytes);
        ASSERT_NE(buffer.get(), nullptr);
        ASSERT_EQ(cudaMemset(buffer.get(), 1, kBytes), cudaSuccess);
    }
    ASSERT_EQ(cudaDeviceSynchronize(), cudaSuccess);
    size_t driver_free = 0, total = 0;
    ASSERT_EQ(cudaMemGetInfo(&driver_free, &total), cudaSuccess);
    if (total / 16 < kBytes) GTEST_SKIP() << "a device of " << (total >> 20) << " MiB keeps less than the test's buffer";
    // The freed 256 MiB stay in our pool: taken for the driver, free for us.
    EXPECT_GE(cuda::free_device_memory(), driver_free + kBytes);
    EXPECT_EQ(default_pool_threshold(), before);
}

TEST(CudaDeviceMemory, AnswersAreUnchangedWhenTheDefaultPoolKeepsEverything) {
    const PreparedMesh mesh = prepare_mesh(make_torus());
    SamplerOptions o;
    o.backend = "cuda";
    o.method = "bvh";
    o.progress = false;
    const std::vector<Vec3d> points = {{0.1, 0.2, 0.3}, {1.5, -0.2, 0.4}, {0.0, 0.0, 0.0}};
    const std::vector<PointSample> first = make_sampler(o)->bind(share(mesh))->query(points);
    int device = 0;
    cudaMemPool_t pool{};
    ASSERT_EQ(cudaGetDevice(&device), cudaSuccess);
    ASSERT_EQ(cudaDeviceGetDefaultMemPool(&pool, device), cudaSuccess);
    uint64_t keep_all = UINT64_MAX;  // what cuBQL's peer sets
    ASSERT_EQ(cudaMemPoolSetAttribute(pool, cudaMemPoolAttrReleaseThreshold, &keep_all), cudaSuccess);
    const std::vector<PointSample> second = make_sampler(o)->bind(share(mesh))->query(points);
    ASSERT_EQ(first.size(), second.size());
    for (size_t i = 0; i < first.size(); ++i) {
        EXPECT_EQ(first[i].distance, second[i].distance) << i;
        EXPECT_EQ(first[i].triangle, second[i].triangle) << i;
    }
    uint64_t zero = 0;
    cudaMemPoolSetAttribute(pool, cudaMemPoolAttrReleaseThreshold, &zero);
}

}  // namespace
}  // namespace sdf
