/// @file stored_slab.h
/// @brief A slab's samples as a field file stores them (harness/io/field_file.h): distance
/// and gradient in the file's float type, the closest triangle as int32 in the mesh file's
/// face order, every point at its place in the slab's compact order (its primary z-planes,
/// then its secondary ones). Samplers that can produce these bytes where they compute (the
/// CUDA BVH sampler, on the device) let the streamed writer (harness/sampling/
/// streamed_sampling.h) copy them to the files as they are, with no scatter or conversion on
/// the host. The bytes equal what field_channel_bytes() makes of the same samples: a double
/// rounded to float is the same IEEE round-to-nearest on the host and the device.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>

#include "core/sampling/narrow_band.h"
#include "core/sampling/sampled_field.h"

namespace sdf {

/// Which channels, in which float type.
struct StoredLayout {
    bool float32 = true;           ///< distance and gradient as float32, else float64
    bool gradient = true;          ///< the gradient channel (3 values a point)
    bool closest_triangle = true;  ///< the closest-triangle channel (int32)

    size_t value_bytes() const { return float32 ? 4 : 8; }
    /// Bytes of one point over every channel.
    size_t bytes_per_point() const { return value_bytes() * (gradient ? 4 : 1) + (closest_triangle ? 4 : 0); }
};

/// One slab's stored bytes; valid while `storage` is held (the writer holds it until its
/// writes are done, so a sampler may reuse the memory for a later slab only after that).
struct StoredSlab {
    SampledField info;   ///< lattice, precision, timings and provenance; its arrays are empty
    int64_t points = 0;  ///< the slab's points, in its compact order
    const char* distance = nullptr;          ///< points values
    const char* gradient = nullptr;          ///< 3 x points values; null without the channel
    const char* closest_triangle = nullptr;  ///< points int32; null without the channel
    NarrowBandCounts band;                   ///< with SamplerOptions::band_width > 0
    std::shared_ptr<const void> storage;     ///< owns the bytes
};

}  // namespace sdf
