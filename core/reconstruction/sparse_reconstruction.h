/// @file sparse_reconstruction.h
/// @brief The reconstruction of a sparse narrow band (core/sampling/sparse_band.h) straight
/// from its blocks: at every point, bit for bit what Reconstruction gives on the densified
/// band (SparseBandField::densify(), the dense `--band W` field), with memory that grows with
/// the band, not the lattice.
///
///   SparseReconstruction r(band, "tricubic_lm", "fd", !band.gradient.empty());
///   std::vector<ReconstructedSample<double>> s = r.evaluate(points);
///
/// How. An interpolator's value at a point, with its derivative data, reads the lattice
/// points within a few spacings of the point's cell (its radius, plus the derivative source's
/// stencil, plus the lattice edge's one-sided rules). So the points are grouped by the block
/// of 8^3 primary cells that holds them, and each group is reconstructed on a window of the
/// lattice (core/sampling/sparse_band_window.h): the block's cells grown by a margin on every
/// side, cut at the lattice's edge, densified from the band. The window's derivative data are
/// built by the dense code (build_hermite_data) and the same interpolator evaluates there in
/// lattice units: the point's lattice coordinates u are computed as the dense view computes
/// them, and u minus the window's first point (an integer, so the subtraction is exact) is
/// what the interpolator sees in a view whose origin is 0 and whose unit is 1; its gradient
/// is scaled by 1/unit last, as the dense view scales it. Where the window stops short of the
/// lattice's edge, the margin keeps its own edge rules out of everything the point reads;
/// where it reaches the edge, its edge is the lattice's, clamping included.
///
/// Filters whose prefilter is global (cc_bspline3, bcc_box_quintic: interpolation couples
/// every point of the lattice) have no such window: reconstructs_locally() is false and the
/// constructor refuses them; their callers densify.
#pragma once

#include <string>
#include <vector>

#include "core/reconstruction/hermite_data.h"
#include "core/sampling/sparse_band.h"

namespace sdf {

/// Whether `kind`'s value at a point depends only on the lattice points near it (all filters
/// but the interpolating splines, whose prefilter solves over the whole lattice).
bool reconstructs_locally(InterpolatorKind kind);

class SparseReconstruction {
public:
    /// `band` must outlive this object. `gradient`: whether the band has a gradient channel
    /// (a file read without one: false), as the densified field would. Throws
    /// std::invalid_argument for a spec that does not fit the lattice or the channels, and
    /// for a filter that does not reconstruct locally.
    SparseReconstruction(const SparseBandField& band, const ReconstructionSpec& spec, bool gradient);
    /// By config names; an empty `derivatives` picks default_derivative_source().
    SparseReconstruction(const SparseBandField& band, const std::string& interpolator, const std::string& derivatives,
                         bool gradient);

    const ReconstructionSpec& spec() const { return spec_; }
    std::string description() const { return describe(spec_); }
    const SparseBandField& band() const { return band_; }
    /// The interpolator's domain on the band's lattice (Reconstruction::domain()'s).
    DomainBox<double> domain() const;

    ReconstructedSample<double> evaluate(const Vec3d& p) const;
    /// out[i] = evaluate(points[i]), one window per block of cells holding points; threads =
    /// 0 uses every hardware thread.
    void evaluate(const Vec3d* points, ReconstructedSample<double>* out, int64_t n, int threads = 0) const;
    std::vector<ReconstructedSample<double>> evaluate(const std::vector<Vec3d>& points, int threads = 0) const;

private:
    /// The primary cell (lower corner) whose window serves lattice coordinates u.
    Int3 cell_of(const Vec3d& u) const;
    /// Reconstructs points[order[begin, end)] (all of one block of cells, [lo, hi] its cells)
    /// on one window.
    void evaluate_group(const Int3& lo, const Int3& hi, const Vec3d* points, const int64_t* order, int64_t count,
                        ReconstructedSample<double>* out) const;

    const SparseBandField& band_;
    ReconstructionSpec spec_;
    bool gradient_;
    int margin_;                      ///< primary points beyond the cells, per side
    LatticeFieldView<double> frame_;  ///< the dense view's geometry (no arrays): its to_lattice and domain
};

}  // namespace sdf
