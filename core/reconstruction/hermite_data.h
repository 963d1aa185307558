/// @file hermite_data.h
/// @brief Builds, once per field, the per-point arrays an interpolator reads (values, first
/// derivatives, higher derivatives, BCC face table) for the chosen derivative source, and
/// hands them to the kernels as a LatticeFieldView.
///
/// The arrays are computed in double (threaded over points) and can be converted to float
/// for a GPU or a float kernel afterwards.
#pragma once

#include <vector>

#include "core/reconstruction/reconstruction_spec.h"
#include "core/sampling/sampled_field.h"

namespace sdf {

template <typename T>
struct HermiteData {
    Lattice lattice{};
    std::vector<T> values;
    std::vector<Vec3<T>> first;   ///< per lattice unit; empty when unused
    std::vector<T> higher;        ///< higher_stride per point; empty when unused
    int higher_stride = 0;
    BccFaceTable<T> faces{};

    /// A view of these arrays; valid while this object lives and is not resized.
    LatticeFieldView<T> view() const;
};

/// Validates the spec against the field (validate_reconstruction) and builds the arrays.
/// field.distance is the value channel; field.gradient (world units) the true gradients.
HermiteData<double> build_hermite_data(const SampledField& field, const ReconstructionSpec& spec);

template <typename T>
HermiteData<T> convert_hermite_data(const HermiteData<double>& d);

}  // namespace sdf
