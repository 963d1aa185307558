// The warp's winding traversal (cuda/sampling/winding_sign_kernel.cuh, warp_fast_winding_value) against
// each thread's own (fast_winding_number), bit for bit, on the device: lattice rows,
// Morton-sorted points near the surface, scattered points, and lanes without a point in
// between (which must neither stall the warp nor change their neighbours' sums). Also the
// CPU's fast value of the same tree beside it (libm's atan2 and CUDA's may differ in the last
// bits, so only the side is compared there, away from 1/2).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <vector>

#include "core/sampling/sampler_sign.h"
#include "core/winding/winding_sign.h"
#include "cuda/util/cuda_check.h"
#include "cuda/util/device_buffer.h"
#include "cuda/util/device_mesh.h"
#include "cuda/sampling/device_winding.h"
#include "kernels/core/morton.h"
#include "tests/cpu_reference/bvh/bvh_test_meshes.h"

namespace sdf {
namespace {

/// Lane i of the launch evaluates point i both ways; a point with skip[i] != 0 takes no part.
__global__ void both_traversals(cuda::WindingSignView w, const Vec3d* points, const int* skip, int64_t n, double* warp,
                                double* thread) {
    const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
    const bool wants = i < n && skip[i] == 0;
    const Vec3d p = i < n ? points[i] : Vec3d(0.0);
    const double by_warp = cuda::warp_fast_winding_value(w.view, p, wants, w.accuracy);
    if (i >= n) return;
    warp[i] = by_warp;
    thread[i] = wants ? fast_winding_number(w.view, p, w.accuracy).value : 0.0;
}

std::vector<Vec3d> test_points(const PreparedMesh& mesh) {
    const Bounds3& b = mesh.bounds();
    const Vec3d lo = b.min - 0.1 * b.extent(), size = 1.2 * b.extent();
    std::vector<Vec3d> pts;
    for (int z = 0; z < 24; ++z)  // lattice rows, as the lattice samplers finalize them
        for (int y = 0; y < 24; ++y)
            for (int x = 0; x < 40; ++x)
                pts.push_back(lo + Vec3d{size.x * x / 39.0, size.y * y / 23.0, size.z * z / 23.0});
    std::mt19937_64 rng(7);
    std::normal_distribution<double> g(0.0, 0.01 * b.diagonal());
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<Vec3d> near;
    for (int i = 0; i < 20000; ++i) {  // near the surface, Morton-sorted as query() sorts them
        const Vec3d& v = mesh.vertices()[size_t(rng() % mesh.vertices().size())];
        near.push_back(v + Vec3d{g(rng), g(rng), g(rng)});
    }
    const double side = std::max({size.x, size.y, size.z});
    std::sort(near.begin(), near.end(), [&](const Vec3d& a, const Vec3d& c) {
        return morton_key_of_point(a.x, a.y, a.z, lo.x, lo.y, lo.z, 1.0 / side) <
               morton_key_of_point(c.x, c.y, c.z, lo.x, lo.y, lo.z, 1.0 / side);
    });
    pts.insert(pts.end(), near.begin(), near.end());
    for (int i = 0; i < 5000; ++i) pts.push_back(lo + Vec3d{size.x * u(rng), size.y * u(rng), size.z * u(rng)});
    return pts;
}

TEST(CudaWindingTraversal, TheWarpsTraversalGivesEachLanesOwnValueBitForBit) {
    std::vector<test::NamedMesh> cases = test::bvh_test_meshes();
    cases.push_back({"open bowl", test::open_bowl()});
    for (const test::NamedMesh& c : cases) {
        SamplerSign sign(SignMode::Winding);
        sign.prepare(c.mesh);
        ASSERT_TRUE(sign.winding()) << c.name;
        cuda::DeviceMesh<double> dmesh(c.mesh.buffers<double>());
        cuda::DeviceWinding winding;
        winding.upload(sign, dmesh.view());
        ASSERT_TRUE(winding.view().enabled()) << c.name;

        const std::vector<Vec3d> pts = test_points(c.mesh);
        const int64_t n = int64_t(pts.size());
        std::vector<int> skip(pts.size());
        for (size_t i = 0; i < skip.size(); ++i) skip[i] = (i % 7 == 3) || (i / 32) % 11 == 5;  // single lanes, whole warps
        cuda::DeviceBuffer<Vec3d> dpts;
        cuda::DeviceBuffer<int> dskip;
        cuda::DeviceBuffer<double> dwarp, dthread;
        dpts.upload(pts);
        dskip.upload(skip);
        dwarp.allocate(pts.size());
        dthread.allocate(pts.size());
        both_traversals<<<int((n + 127) / 128), 128>>>(winding.view(), dpts.get(), dskip.get(), n, dwarp.get(), dthread.get());
        CUDA_CHECK_LAUNCH("both_traversals");
        std::vector<double> warp(pts.size()), thread(pts.size());
        dwarp.download(warp.data(), pts.size());
        dthread.download(thread.data(), pts.size());
        CUDA_CHECK(cudaDeviceSynchronize());

        const WindingSign reference(c.mesh, SamplerSign::winding_options());
        int64_t compared = 0, cpu_bits_differ = 0;
        for (size_t i = 0; i < pts.size(); ++i) {
            if (skip[i]) {
                ASSERT_EQ(warp[i], 0.0) << c.name << " point " << i << " (no part in the traversal)";
                continue;
            }
            ASSERT_EQ(std::memcmp(&warp[i], &thread[i], sizeof(double)), 0)
                << c.name << " point " << i << ": warp " << warp[i] << ", thread " << thread[i];
            const double cpu = reference.estimate(pts[i]).value;
            cpu_bits_differ += std::memcmp(&cpu, &warp[i], sizeof(double)) != 0;
            if (std::abs(cpu - 0.5) > 1e-9) ASSERT_EQ(warp[i] > 0.5, cpu > 0.5) << c.name << " point " << i;
            ++compared;
        }
        std::printf("%-16s %lld points bit for bit (warp = thread); CPU value's bits differ at %lld\n", c.name.c_str(),
                    (long long)compared, (long long)cpu_bits_differ);
    }
}

}  // namespace
}  // namespace sdf
