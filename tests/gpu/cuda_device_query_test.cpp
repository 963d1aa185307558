// Point queries whose points and results stay on the device (core/sampling/device_query.h):
// float64 and float32 points, contiguous and strided (an N x 4 array's first three columns,
// a column-major N x 3 view), equal Sampler::query() on the same points bit for bit; a
// point that is not finite is refused by its index; a null output is skipped. Host arrays
// in and out (query_host) equal query() too.
#include <gtest/gtest.h>
#include <cuda_runtime.h>

#include <cmath>
#include <cstring>
#include <random>

#include "harness/sampling/sampler_table.h"
#include "tests/cpu_reference/bvh/bvh_test_meshes.h"
#include "tests/test_util/shared_mesh.h"

namespace sdf {
namespace {

template <typename T>
T* to_device(const std::vector<T>& host) {
    T* p = nullptr;
    EXPECT_EQ(cudaMalloc(&p, host.size() * sizeof(T)), cudaSuccess);
    EXPECT_EQ(cudaMemcpy(p, host.data(), host.size() * sizeof(T), cudaMemcpyHostToDevice), cudaSuccess);
    return p;
}

template <typename T>
std::vector<T> to_host(const T* device, size_t n) {
    std::vector<T> host(n);
    EXPECT_EQ(cudaMemcpy(host.data(), device, n * sizeof(T), cudaMemcpyDeviceToHost), cudaSuccess);
    return host;
}

struct DeviceOutputs {
    double* distance = nullptr;
    double* gradient = nullptr;
    int32_t* triangle = nullptr;
    explicit DeviceOutputs(size_t n) {
        EXPECT_EQ(cudaMalloc(&distance, n * sizeof(double)), cudaSuccess);
        EXPECT_EQ(cudaMalloc(&gradient, 3 * n * sizeof(double)), cudaSuccess);
        EXPECT_EQ(cudaMalloc(&triangle, n * sizeof(int32_t)), cudaSuccess);
    }
    ~DeviceOutputs() {
        cudaFree(distance);
        cudaFree(gradient);
        cudaFree(triangle);
    }
    DeviceQueryResults results() const { return {distance, gradient, triangle}; }
};

SamplerOptions cuda_options(Precision precision) {
    SamplerOptions o;
    o.backend = "cuda";
    o.method = "bvh";
    o.precision = precision;
    o.progress = false;
    return o;
}

TEST(CudaDeviceQuery, EqualsTheHostQueryBitForBit) {
    const PreparedMesh& mesh = test::bvh_test_meshes()[4].mesh;  // soccer ball
    const size_t n = 5003;
    std::mt19937_64 rng(11);
    const Bounds3& box = mesh.bounds();
    std::uniform_real_distribution<double> u(-0.2, 1.2);
    std::vector<Vec3d> points(n);
    for (Vec3d& p : points) p = box.min + component_mul(box.extent(), Vec3d{u(rng), u(rng), u(rng)});
    std::vector<Vec3d> as_float(n);  // the float32 inputs, as the host query sees them
    for (size_t i = 0; i < n; ++i)
        as_float[i] = Vec3d{double(float(points[i].x)), double(float(points[i].y)), double(float(points[i].z))};
    std::vector<double> rows(3 * n), column_major(3 * n);
    std::vector<float> padded(4 * n);
    for (size_t i = 0; i < n; ++i)
        for (int k = 0; k < 3; ++k) {
            rows[3 * i + k] = points[i][k];
            column_major[k * n + i] = points[i][k];
            padded[4 * i + k] = float(points[i][k]);
        }
    for (Precision precision : {Precision::Float, Precision::Double}) {
        auto sampler = make_sampler(cuda_options(precision));
        const std::vector<PointSample> truth = sampler->bind(share(mesh))->query(points), truth_float = sampler->bind(share(mesh))->query(as_float);
        struct Case { const char* what; const void* xyz; bool float32; int64_t row, col; const std::vector<PointSample>* truth; };
        double* d_rows = to_device(rows);
        double* d_columns = to_device(column_major);
        float* d_padded = to_device(padded);
        const Case cases[] = {{"float64 rows", d_rows, false, 3, 1, &truth},
                              {"float64 column-major", d_columns, false, 1, int64_t(n), &truth},
                              {"float32 N x 4", d_padded, true, 4, 1, &truth_float}};
        for (const Case& c : cases) {
            DeviceOutputs out(n);
            DevicePoints dp{c.xyz, c.float32, int64_t(n), c.row, c.col, 0, nullptr};
            ASSERT_TRUE(sampler->bind(share(mesh))->query_device(dp, out.results())) << c.what;
            const std::vector<double> d = to_host(out.distance, n), g = to_host(out.gradient, 3 * n);
            const std::vector<int32_t> t = to_host(out.triangle, n);
            for (size_t i = 0; i < n; ++i) {
                const PointSample& e = (*c.truth)[i];
                ASSERT_EQ(std::memcmp(&d[i], &e.distance, sizeof(double)), 0) << c.what << " point " << i;
                ASSERT_EQ(g[3 * i], e.gradient.x) << c.what << " point " << i;
                ASSERT_EQ(g[3 * i + 1], e.gradient.y) << c.what << " point " << i;
                ASSERT_EQ(g[3 * i + 2], e.gradient.z) << c.what << " point " << i;
                ASSERT_EQ(t[i], e.triangle) << c.what << " point " << i;
            }
        }
        // Only the distance: the other outputs are skipped.
        DeviceOutputs out(n);
        DeviceQueryResults only_distance{out.distance, nullptr, nullptr};
        ASSERT_TRUE(sampler->bind(share(mesh))->query_device(DevicePoints{d_rows, false, int64_t(n), 3, 1, 0, nullptr}, only_distance));
        EXPECT_EQ(to_host(out.distance, n)[17], truth[17].distance);
        cudaFree(d_rows);
        cudaFree(d_columns);
        cudaFree(d_padded);
    }
}

// Host arrays in and out (core/sampling/host_query.h), as a NumPy caller passes them:
// float32 rows go to the device as they are, strided float64 rows are gathered first, and
// the columns come back through the pinned buffers. More points than one staging chunk
// (cuda/util/staged_copy.h: 32 MiB), so both buffers alternate.
TEST(CudaDeviceQuery, HostArraysEqualTheHostQueryBitForBit) {
    const PreparedMesh& mesh = test::bvh_test_meshes()[4].mesh;  // soccer ball
    const size_t n = (size_t(3) << 20) + 17;  // 3M points: 72 MiB of gradients, three chunks
    std::mt19937_64 rng(23);
    const Bounds3& box = mesh.bounds();
    std::uniform_real_distribution<double> u(-0.2, 1.2);
    std::vector<float> rows32(3 * n);
    std::vector<double> padded64(4 * n, -7.0);
    std::vector<Vec3d> points(n), as_float(n);
    for (size_t i = 0; i < n; ++i) {
        points[i] = box.min + component_mul(box.extent(), Vec3d{u(rng), u(rng), u(rng)});
        for (int k = 0; k < 3; ++k) {
            rows32[3 * i + k] = float(points[i][k]);
            padded64[4 * i + k] = points[i][k];
            as_float[i][k] = double(rows32[3 * i + k]);
        }
    }
    auto sampler = make_sampler(cuda_options(Precision::Float));
    const std::vector<PointSample> truth = sampler->bind(share(mesh))->query(points), truth_float = sampler->bind(share(mesh))->query(as_float);
    struct Case { const char* what; HostPoints points; const std::vector<PointSample>* truth; };
    const Case cases[] = {{"float32 rows", HostPoints{rows32.data(), true, int64_t(n), 3, 1}, &truth_float},
                          {"float64 N x 4", HostPoints{padded64.data(), false, int64_t(n), 4, 1}, &truth}};
    for (const Case& c : cases) {
        std::vector<double> d(n), g(3 * n);
        std::vector<int32_t> t(n);
        sampler->bind(share(mesh))->query_host(c.points, HostQueryResults{d.data(), g.data(), t.data()});
        for (size_t i = 0; i < n; ++i) {
            const PointSample& e = (*c.truth)[i];
            ASSERT_EQ(std::memcmp(&d[i], &e.distance, sizeof(double)), 0) << c.what << " point " << i;
            ASSERT_EQ(std::memcmp(&g[3 * i], &e.gradient, sizeof(Vec3d)), 0) << c.what << " point " << i;
            ASSERT_EQ(t[i], e.triangle) << c.what << " point " << i;
        }
    }
    // A point that is not finite is refused by its row, before anything reaches the device.
    rows32[3 * 1234 + 2] = std::nanf("");
    std::vector<double> d(n);
    try {
        sampler->bind(share(mesh))->query_host(HostPoints{rows32.data(), true, int64_t(n), 3, 1}, HostQueryResults{d.data(), nullptr, nullptr});
        ADD_FAILURE() << "a NaN point was accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("row 1234 is not three finite numbers"), std::string::npos) << e.what();
    }
}

TEST(CudaDeviceQuery, RefusesAPointThatIsNotFiniteByItsIndex) {
    const PreparedMesh& mesh = test::bvh_test_meshes()[4].mesh;
    std::vector<double> xyz(3 * 100, 0.25);
    xyz[3 * 41 + 1] = std::nan("");
    xyz[3 * 77] = 1e300;
    double* d = to_device(xyz);
    DeviceOutputs out(100);
    auto sampler = make_sampler(cuda_options(Precision::Float));
    try {
        sampler->bind(share(mesh))->query_device(DevicePoints{d, false, 100, 3, 1, 0, nullptr}, out.results());
        ADD_FAILURE() << "a NaN point was accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("query points: row 41 "), std::string::npos) << e.what();
    }
    cudaFree(d);
}

}  // namespace
}  // namespace sdf
