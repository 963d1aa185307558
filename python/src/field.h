/// @file field.h
/// @brief sdf_lattices.Field: a sampled (or read) field with the reconstruction last asked
/// for, kept for repeated calls (reconstruct, render).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/lattice/lattice_fitting.h"
#include "core/reconstruction/reconstruction.h"
#include "core/reconstruction/reconstruction_spec.h"
#include "harness/io/field_output.h"
#include "harness/io/volume_grids.h"
#include "core/sampling/sampled_field.h"
#include "harness/sampling/mesh_sdf.h"
#include "python/src/common.h"
#include "python/src/reconstruct.h"

namespace sdf {

class Field {
public:
    explicit Field(SampledField field) : field_(std::make_shared<const SampledField>(std::move(field))) {}

    const SampledField& field() const { return *field_; }
    const Lattice& lattice() const { return field_->lattice; }

    /// The CC sub-grids, each {shape (nz, ny, nx), first storage index}: one for CC, the
    /// primary and the secondary grid for BCC.
    struct Grid {
        Int3 resolution;
        int64_t first;
    };
    std::vector<Grid> grids() const {
        std::vector<Grid> g;
        for (const VolumeGrid& v : volume_grids(lattice())) g.push_back({v.resolution, v.first});
        return g;
    }

    /// One array per grid (a tuple for BCC), each [nz, ny, nx] + `inner`.
    template <typename Make>
    py::object per_grid(Make make) const {
        std::vector<py::object> arrays;
        for (const Grid& g : grids()) arrays.push_back(make(g, std::vector<py::ssize_t>{g.resolution.z, g.resolution.y, g.resolution.x}));
        if (arrays.size() == 1) return arrays[0];
        py::tuple all(arrays.size());
        for (size_t i = 0; i < arrays.size(); ++i) all[i] = arrays[i];
        return all;
    }

    // The arrays are read-only NumPy views of the field's own memory, each holding the field
    // alive: no copy (16.8M points of distance, gradient and triangle are 604 MB, which a
    // copy would also have to page-fault) and no way to change a field that its cached
    // reconstruction and write() read.
    py::object values() const {
        return per_grid([&](const Grid& g, const std::vector<py::ssize_t>& shape) -> py::object {
            return view(field_->distance.data() + g.first, shape);
        });
    }
    py::object gradient() const {
        if (field_->gradient.empty()) return py::none();
        static_assert(sizeof(Vec3d) == 3 * sizeof(double), "a gradient array views Vec3d as 3 packed doubles");
        return per_grid([&](const Grid& g, std::vector<py::ssize_t> shape) -> py::object {
            shape.push_back(3);
            return view(reinterpret_cast<const double*>(field_->gradient.data() + g.first), shape);  // no element taken: a grid may be empty
        });
    }
    py::object triangle() const {
        if (field_->closest_triangle.empty()) return py::none();
        return per_grid([&](const Grid& g, const std::vector<py::ssize_t>& shape) -> py::object {
            return view(field_->closest_triangle.data() + g.first, shape);
        });
    }
    py::object grid_origins() const {
        std::vector<py::object> origins;
        for (const Grid& g : grids()) {
            const Vec3d o = lattice().position(g.first);
            origins.push_back(py::make_tuple(o.x, o.y, o.z));
        }
        return origins.size() == 1 ? origins[0] : py::make_tuple(origins[0], origins[1]);
    }

    void write(const std::string& path, const std::string& dtype, bool overwrite, bool closest_triangle) const {
        FieldWriteOptions o;
        o.dtype = choose("dtype", dtype, {"float32", "float64"}) == "float32" ? FieldDtype::Float32 : FieldDtype::Float64;
        o.overwrite = overwrite ? Overwrite::Allow : Overwrite::Forbid;
        o.closest_triangle = closest_triangle;
        py::gil_scoped_release release;
        write_field_file(path, *field_, o);
    }

    /// The reconstruction of these names (sdf-eval's defaults for an empty `derivatives`).
    std::shared_ptr<const Reconstruction> reconstruction(const std::string& interpolator, const std::string& derivatives,
                                                         double sigma2, const std::string& sigma_units, int threads) {
        const ReconstructionSpec spec = reconstruction_spec(lattice().type, !field_->gradient.empty(), interpolator, derivatives,
                                                            sigma2, sigma_units, threads);
        const std::string key = describe(spec);
        if (!recon_ || recon_key_ != key) {
            std::shared_ptr<const SampledField> f = field_;
            std::shared_ptr<const Reconstruction> r;
            {
                py::gil_scoped_release release;
                r = std::make_shared<const Reconstruction>(*f, spec);
            }
            recon_ = r;
            recon_key_ = key;
        }
        return recon_;
    }

    /// Values and gradients at points; outside the domain: "nan", "clamp" or "error".
    py::tuple reconstruct(const py::object& points, const std::string& interpolator, const std::string& derivatives,
                          double sigma2, const std::string& sigma_units, int threads, const std::string& outside);

    /// World positions of the lattice points, per grid, shape [nz, ny, nx, 3].
    py::object points() const;

private:
    /// A read-only C-order array of `shape` over `data` (inside field_), whose base owns a
    /// reference to field_.
    template <typename T>
    py::array view(const T* data, const std::vector<py::ssize_t>& shape) const {
        auto* owner = new std::shared_ptr<const SampledField>(field_);
        const py::capsule base(owner, [](void* p) { delete static_cast<std::shared_ptr<const SampledField>*>(p); });
        py::array_t<T> a(shape, data, base);
        a.attr("setflags")(py::arg("write") = false);
        return std::move(a);
    }

    std::shared_ptr<const SampledField> field_;
    std::shared_ptr<const Reconstruction> recon_;
    std::string recon_key_;
};

/// A lattice as sample()'s arguments frame it (Python objects; None where not given).
struct LatticeArguments {
    std::string type;  ///< a lattice type's name (kernels/lattice/lattice_kinds.h)
    py::object resolution, samples, margin, bounds, spacing, origin;
    LatticeStorage storage = LatticeStorage::Dense;  ///< bounds its size: a sparse band's may be larger
};

/// The lattice of `arguments`: fitted around `mesh_bounds` (resolution or samples, and
/// margin, as run-experiment fits it), or framed by the caller (bounds with spacing or
/// resolution; spacing alone around the mesh's box; origin, spacing and resolution).
Lattice frame_lattice(const LatticeArguments& arguments, const Bounds3& mesh_bounds);

/// `field` with its mesh's description, as a Field.
Field field_for_mesh(SampledField field, const PreparedMesh& mesh);

/// SDF.sample(): the lattice of the arguments, sampled by the bound sampler.
Field sample_bound(const MeshSdf& sdf, const std::string& lattice, const py::object& resolution, const py::object& samples,
                   const py::object& margin, const py::object& bounds, const py::object& spacing, const py::object& origin,
                   const py::object& progress);

}  // namespace sdf
