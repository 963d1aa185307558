/// @file pixel_record.h
/// @brief What the ray caster (and the mesh reference renderer) stores per pixel: whether
/// and how the ray hit, the depth along the ray, the shading normal and the shaded value.
///
/// Every renderer of this project fills the same record, so image metrics, image files and
/// the CPU/GPU comparison read one layout. Values are float whatever the scalar type of the
/// kernel that produced them (images are stored in float: EXR, PFM).
#pragma once

#include <cstdint>

#include "kernels/core/vec3.h"

namespace sdf {

enum class HitKind : uint8_t {
    Miss = 0,     ///< the ray left the domain (or the scene) without a hit
    Surface = 1,  ///< a sign change of the field (or a triangle) was found and refined
    Clipped = 2,  ///< the ray entered the domain box already inside (f <= 0): the hit is
                  ///< the entry point on the box, shaded with the box face's normal
};

struct PixelRecord {
    float depth = 0;            ///< distance from the eye along the ray; 0 for a miss
    Vec3f normal{0, 0, 0};      ///< unit, world space, turned toward the viewer; 0 for a miss
    float shade = 0;            ///< Blinn-Phong value (shading.h); the background for a miss
    HitKind hit = HitKind::Miss;
    uint8_t refine_iterations = 0;  ///< root refinement iterations (diagnostics)
    uint16_t steps = 0;         ///< march steps, saturating at 65535 (diagnostics)

    SDF_CPU_GPU bool is_hit() const { return hit != HitKind::Miss; }
};

}  // namespace sdf
