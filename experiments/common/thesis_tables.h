/// @file thesis_tables.h
/// @brief The thesis's published numbers, printed beside ours.
#pragma once

#include <cstdint>
#include <string>

namespace sdf {

/// Thesis Table 3-2: execution times on a GeForce GTX 465 (GPU) and one CPU core.
struct ThesisTiming {
    const char* mesh;       ///< "soccer ball", "bunny", "dragon"
    int64_t samples;        ///< 32,768 / 262,144 / 2,097,152 ("32k", "262k", "2,097k")
    double gpu_seconds;
    double cpu_seconds;
    double speedup;
};

inline constexpr ThesisTiming kThesisTable32[] = {
    {"soccer ball", 262144, 0.44125, 63.9975, 145}, {"soccer ball", 2097152, 2.6365, 511.02, 194},
    {"bunny", 32768, 0.90175, 181.3325, 201},       {"bunny", 262144, 5.76275, 1451.54, 252},
    {"dragon", 32768, 1.2325, 383.6, 311},          {"dragon", 262144, 8.16425, 3063.5725, 375},
};

/// Thesis Table 3-1: triangle and vertex counts of its meshes.
struct ThesisMeshCounts {
    const char* mesh;
    int triangles;
    int vertices;
};

inline constexpr ThesisMeshCounts kThesisTable31[] = {
    {"soccer ball", 3516, 1760}, {"bunny", 69666, 34835}, {"dragon", 100000, 50000}};

inline const ThesisTiming* thesis_timing(const std::string& mesh, int64_t samples) {
    for (const ThesisTiming& t : kThesisTable32)
        if (mesh == t.mesh && samples == t.samples) return &t;
    return nullptr;
}

}  // namespace sdf

namespace sdf {

/// Thesis Table 4-1, ML row: "L2 norm error" of the Marschner-Lobb function sampled on a
/// 111 x 111 x 222 BCC lattice and reconstructed with the cubic BCC scheme, derivatives from
/// plain and from Gaussian-weighted (sigma^2 = .5) least squares. The norm is not defined in
/// the thesis; the ratio weighted / plain (0.976) is the normalisation-free comparison.
struct ThesisTable41Row {
    const char* dataset;
    double plain;
    double weighted;
};

inline constexpr ThesisTable41Row kThesisTable41[] = {
    {"ML", 8.939, 8.725}, {"Carp", 0.74, 0.731}, {"Bonsai", 5.741, 5.721}, {"Lobster", 8.538, 8.467}};

}  // namespace sdf
