// main() of every GPU test: exits with 77 (CTest SKIP_RETURN_CODE) when no CUDA device is
// present, so GPU tests report "skipped" on machines without a GPU instead of passing.
#include <gtest/gtest.h>

#include <cstdio>

#include "cuda/util/cuda_device.h"

int main(int argc, char** argv) {
    if (sdf::cuda::device_count() == 0) {
        std::printf("no CUDA device on this machine: GPU test skipped\n");
        return 77;
    }
    std::printf("GPU: %s\n", sdf::cuda::describe_device(0).dump().c_str());
    ::testing::InitGoogleTest(&argc, argv);
    return RUN_ALL_TESTS();
}
